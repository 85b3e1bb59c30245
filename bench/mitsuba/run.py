"""The bench's run: per scene, the XML, both references (cached), the
validation, then the interleaved measurements; the report at the end."""
import hashlib
import json
import os
import platform
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

from . import images, measure, report, translate, validate, writers
from .mcrt_run import Mcrt, parse_flags
from .mitsuba_run import Mitsuba

T0 = time.time()


def log(msg):
    print(f"[{time.time() - T0:7.1f} s] {msg}", file=sys.stderr, flush=True)


def machine():
    cpu = next((l.split(":", 1)[1].strip() for l in Path("/proc/cpuinfo").read_text().splitlines()
                if l.startswith("model name")), platform.processor())
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).resolve().parents[2]).stdout.strip()
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(), "git_commit": commit,
            "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
            "load_before": [round(x, 2) for x in os.getloadavg()]}


def prepare_scene(a, path, mcrt, mi, ref_flags, commands):
    """XML, the two references and the validation of one scene."""
    scene, name = translate.load_scene(path), Path(path).stem
    cam = scene["camera"]
    w, h = a.size, max(1, round(a.size * cam["height"] / cam["width"]))
    xml_dir = a.out / "xml"
    xml_dir.mkdir(parents=True, exist_ok=True)
    full = translate.describe(scene, max_depth=a.max_depth, spp=scene.get("render", {}).get("spp", 16))
    (xml_dir / f"{name}.xml").write_text(writers.to_xml(full, f"translated from {path} by bench.mitsuba"))
    if a.xml:
        return None
    tmp = a.out / "tmp"
    tmp.mkdir(exist_ok=True)
    depth = a.max_depth if a.max_depth is not None else scene.get("render", {}).get("max_depth", 50)

    def mcrt_half(seed, spp):
        out = tmp / f"{name}-mcrt-ref-{seed}.exr"
        s = mcrt.render(path, out, spp, seed, w, h, ref_flags, a.max_depth, purpose="reference half")
        img = images.read_exr(out)
        out.unlink()
        return img, s["render_seconds"]

    mc_fields = {"renderer": "mcrt", "scene": scene, "size": [w, h], "spp": a.ref_spp, "max_depth": depth,
                 "binary_sha256": mcrt.sha256, "flags": ref_flags, "seeds": images.REF_SEEDS}
    mc_ref, mc_path, mc_meta, mc_noise = images.reference(a.out, f"{name}-mcrt", mc_fields, a.ref_spp, mcrt_half, log)
    ref_desc = translate.describe(scene, w, h, spp=a.ref_spp // 2, sampler=a.mitsuba_ref_sampler,
                                  max_depth=a.max_depth)
    mi_fields = {"renderer": "mitsuba", "version": mi.version, "variant": mi.variant, "scene": scene,
                 "xml": writers.to_xml(ref_desc), "spp": a.ref_spp, "seeds": images.REF_SEEDS}
    ref_scene = mi.load(ref_desc, (name, "ref"))
    mi_ref, mi_path, mi_meta, mi_noise = images.reference(
        a.out, f"{name}-mitsuba", mi_fields, a.ref_spp, lambda seed, spp: mi.render(ref_scene, spp, seed)[:2], log)
    log(f"{name}: validation")
    mask = validate.silhouette(validate.lights_only(path, mcrt, tmp, (w, h)), scene)
    diff = mcrt.diff(mi_path, mc_path, "validation: Mitsuba reference vs mcrt reference")
    v = {"references": validate.compare_references(mc_ref, mc_meta, mi_ref, mi_meta, diff,
                                                   (mc_noise, mi_noise), mask),
         "reference_files": {"mcrt": str(mc_path), "mitsuba": str(mi_path)},
         "reference_meta": {"mcrt": mc_meta, "mitsuba": {k: x for k, x in mi_meta.items() if k != "fields"}},
         "front_normals": translate.front_normals(full),
         "depth_check": validate.depth_check(path, scene, mcrt, mi, tmp, (16, 16) if a.quick else (48, 48),
                                             1024),
         "xml_check": validate.xml_check(translate.describe(scene, 32, 32, spp=4, max_depth=a.max_depth), mi)}
    v["reference_meta"]["mcrt"].pop("fields", None)
    c = v["references"]
    log(f"{name}: Mitsuba - mcrt mean {c['mean_diff_percent']:+.3f} % (SE {c['mean_diff_se_percent']:.3f} %), "
        f"RMSE/mean {c['rmse_over_mean']:.4f} vs noise {c['expected_rmse_over_mean']:.4f}, "
        f"RMSE ratio off light silhouettes {c['rmse_ratio_off_silhouettes']:.3f}: "
        f"{'agree' if c['agree'] else 'DO NOT AGREE'}")
    return {"name": name, "path": path, "scene": scene, "size": (w, h), "mc_ref": mc_ref, "mc_path": mc_path,
            "mc_meta": mc_meta, "mi_ref": mi_ref, "mi_meta": mi_meta, "validation": v}


def private_copy(binary, out):
    """A copy of the mcrt binary named by its hash: a rebuild during the run
    cannot mix two binaries in one set of measurements."""
    src = Path(binary)
    if not src.is_file():
        raise SystemExit(f"mcrt binary {binary} not found (build it with scripts/build.sh)")
    sha = hashlib.sha256(src.read_bytes()).hexdigest()
    dst = out / "bin" / f"mcrt-{sha[:12]}"
    if not dst.exists():
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, dst.with_suffix(".tmp"))
        os.replace(dst.with_suffix(".tmp"), dst)
    return dst


def main(a, argv):
    commands = []
    a.out.mkdir(parents=True, exist_ok=True)
    configs = [(n, parse_flags(f), f) for n, f in a.configs]
    ref_flags = parse_flags(a.mcrt_ref_args)
    if a.xml:
        for p in a.scenes:
            prepare_scene(a, p, None, None, ref_flags, commands)
        print("\n".join(str(a.out / "xml" / f"{Path(p).stem}.xml") for p in a.scenes))
        return
    mcrt = Mcrt(private_copy(a.mcrt, a.out), a.threads, lambda purpose, cmd: commands.append((purpose, cmd)))
    mi = Mitsuba(a.threads, a.variant)
    measure.probe(mcrt, a.scenes[0], configs + [("reference", ref_flags, a.mcrt_ref_args)], a.out, log)
    res = {"bench_command": shlex.join(["python", "-m", "bench.mitsuba", *argv]), "machine": machine(),
           "mcrt": {"binary": str(mcrt.binary), "copied_from": str(a.mcrt), "sha256": mcrt.sha256,
                    "threads": a.threads,
                    "configs": {n: f for n, _, f in configs}, "reference_flags": a.mcrt_ref_args},
           "mitsuba_version": mi.version, "drjit_version": mi.drjit_version, "mitsuba_variant": mi.variant,
           "mitsuba_threads": mi.threads, "image_reader": images.READER,
           "settings": {"size": a.size, "spp": a.spp, "seeds": a.seeds, "ref_spp": a.ref_spp,
                        "samplers": a.samplers, "max_depth": a.max_depth,
                        "mitsuba_ref_sampler": a.mitsuba_ref_sampler},
           "validation": {}, "runs": []}
    for p in a.scenes:
        s = prepare_scene(a, p, mcrt, mi, ref_flags, commands)
        res["validation"][s["name"]] = s["validation"]
        res["runs"] += measure.interleaved(a, s, mcrt, mi, configs, log)
        finish(a, res, mcrt, commands, final=False)
    res["machine"]["load_after"] = [round(x, 2) for x in os.getloadavg()]
    finish(a, res, mcrt, commands, final=True)


def finish(a, res, mcrt, commands, final):
    res["table"], res["best_ld_sampler"] = report.aggregate(res["runs"])
    res["setup_lines"] = measure.setup_lines(a, res)
    res["commands"] = commands
    res["commands_summary"] = measure.command_summary(res, commands)
    (a.out / "results.json").write_text(json.dumps(res, indent=1, default=str))
    md = report.markdown(res)
    (a.out / "results.md").write_text(md)
    if final:
        print(md)
        log(f"wrote {a.out / 'results.md'} and {a.out / 'results.json'}")
