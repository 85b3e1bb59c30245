"""`python -m bench.mitsuba --pbrt FILE.pbrt ...`: one pbrt-v4 file rendered by
mcrt (which reads it itself) and by Mitsuba 3 (through pbrt_translate) at the
same resolution, spp and depth; both EXRs, a side-by-side PNG (mcrt |
Mitsuba | difference) and the numbers.

Each renderer renders two halves of the spp with different seeds; their
difference gives each image's own noise, hence the standard error of the
mean difference and the RMSE that noise alone would give. The means are
over all pixels and the three channels, as `mcrt diff` takes them.
"""
import json
import os
import shlex
import subprocess
import time
from pathlib import Path

import numpy as np

from . import images, pbrt_translate, writers
from .pbrt_parse import PbrtError

SEEDS = (11, 12)


def mitsuba_tree(sc, width, height, spp, max_depth, sampler="independent"):
    """(name, node) pairs of the Mitsuba scene, in writers' tuple style."""
    sensor = {"type": "perspective", "fov": ("float", sc.fov), "fov_axis": ("string", "smaller"),
              "near_clip": ("float", 1e-3), "far_clip": ("float", 1e7),
              "to_world": ("matrix", sc.camera_to_world),
              "sampler": {"type": sampler, "sample_count": ("integer", spp)},
              "film": {"type": "hdrfilm", "width": ("integer", width), "height": ("integer", height),
                       "pixel_format": ("string", "rgb"), "component_format": ("string", "float32"),
                       "sample_border": ("boolean", True),
                       "rfilter": sc.rfilter}}
    if sc.lens_radius > 0.0:  # the same thin lens: concentric disk samples, focus along camera z
        sensor["type"] = "thinlens"
        sensor["aperture_radius"] = ("float", sc.lens_radius)
        sensor["focus_distance"] = ("float", sc.focal_distance)
    integ = {"type": "path", "max_depth": ("integer", max_depth + 1), "hide_emitters": ("boolean", False)}
    return [("integrator", integ), ("sensor", sensor), *sc.bsdfs.items(), *sc.shapes]


def to_dict(tree, mi):
    out = {"type": "scene"}
    for name, node in tree:
        out[name] = writers._to_dict_value(node, mi)
    return out


def to_xml(tree, comment):
    lines = ['<?xml version="1.0" encoding="utf-8"?>', f"<!-- {comment} -->", '<scene version="3.0.0">']
    for name, node in tree:
        tag = name if name in ("integrator", "sensor") else "bsdf" if name.startswith("mat") else "shape"
        lines += writers._xml_node(tag, node, name if tag in ("bsdf", "shape") else None, 1)
    return "\n".join(lines + ["</scene>"]) + "\n"


def stats(a, b):
    """Image (A + B) / 2 from two independent halves, and its noise."""
    a64, b64 = a.astype(np.float64), b.astype(np.float64)
    n = a.size
    return {"img": (a64 + b64) / 2, "mean": float(((a64 + b64) / 2).mean()),
            "channel_means": [float(x) for x in ((a64 + b64) / 2).reshape(-1, 3).mean(axis=0)],
            "var_of_mean": float(np.sum((a64 - b64).sum(axis=2) ** 2) / 4 / n ** 2),
            "noise_mse": float(np.mean((a64 - b64) ** 2) / 4)}


def png(path, mc, mi_img, width):
    """mcrt | Mitsuba | signed difference of luminance (blue: Mitsuba below, red: above)."""
    from PIL import Image, ImageDraw
    from matplotlib import cm

    def srgb(x):
        x = np.clip(x, 0, 1)
        return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    lum = lambda x: x @ np.array([0.2126, 0.7152, 0.0722])
    d = lum(mi_img) - lum(mc)
    scale = 4 * float(np.sqrt(np.mean(d ** 2))) or 1.0
    heat = cm.coolwarm(np.clip(0.5 + 0.5 * d / scale, 0, 1))[..., :3]
    h, w = mc.shape[:2]
    ph = max(1, round(h * width / w))
    tiles = [Image.fromarray((255 * t).round().astype(np.uint8)).resize((width, ph), Image.BILINEAR)
             for t in (srgb(mc), srgb(mi_img), heat)]
    out = Image.new("RGB", (3 * width, ph + 14), "white")
    for k, t in enumerate(tiles):
        out.paste(t, (k * width, 14))
    draw = ImageDraw.Draw(out)
    for k, label in enumerate(("mcrt", "Mitsuba 3", f"Mitsuba - mcrt, +-{scale:.3g}")):
        draw.text((k * width + 3, 1), label, fill="black")
    out.save(path)
    return scale


def _mcrt_render(a, path, out, w, h, spp, depth, seed, log):
    stats_file = out.with_suffix(".stats.json")
    cmd = [str(a.mcrt), "render", str(path), "-o", str(out), "--width", str(w), "--height", str(h),
           "--spp", str(spp), "--max-depth", str(depth), "--seed", str(seed), "--threads", str(a.threads),
           "--stats", str(stats_file), "--quiet"]
    log(shlex.join(cmd))
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"mcrt failed ({p.returncode}): {p.stderr.strip()}")
    s = json.loads(stats_file.read_text())
    stats_file.unlink()
    return images.read_exr(out), s["render_seconds"], shlex.join(cmd)


def scene_name(path):
    """The file's stem, or for a generic one (scene-v4.pbrt) its scene's folder (cornell-box)."""
    stem = path.name.split(".")[0]
    if not stem.startswith("scene"):
        return stem
    return next((d.name for d in path.parents if d.name not in ("pbrt", "")), stem)


def compare(a, path, mi, log):
    path = Path(path).resolve()
    name = scene_name(path)
    out = a.out / name
    files = out / "mitsuba-files"
    out.mkdir(parents=True, exist_ok=True)
    try:
        sc = pbrt_translate.translate(path, files, a.named_spectra)
    except PbrtError as e:
        raise SystemExit(f"bench.mitsuba --pbrt: {e}") from None
    w = a.size or sc.width
    h = max(1, round(w * sc.height / sc.width)) if a.size else sc.height
    spp = a.spp[0] if a.spp_given else sc.spp
    depth = a.max_depth if a.max_depth is not None else sc.max_depth
    if spp % 2:
        spp += 1  # two halves
    tree = mitsuba_tree(sc, w, h, spp // 2, depth)
    (out / "scene.xml").write_text(to_xml(mitsuba_tree(sc, w, h, spp, depth),
                                          f"translated from {path.name} by bench.mitsuba.pbrt_translate"))
    scene = mi.mi.load_dict(to_dict(tree, mi.mi))
    mi.render(scene, 1, 0)  # warm-up (JIT for LLVM variants), untimed
    halves = {"mcrt": [], "mitsuba": []}
    secs = {"mcrt": 0.0, "mitsuba": 0.0}
    mcrt_cmds = []
    for seed in SEEDS:
        img, t, cmd = _mcrt_render(a, path, out / f"mcrt-half{seed}.exr", w, h, spp // 2, depth, seed, log)
        halves["mcrt"].append(img)
        secs["mcrt"] += t
        mcrt_cmds.append(cmd)
        img, t, _ = mi.render(scene, spp // 2, seed)
        halves["mitsuba"].append(img)
        secs["mitsuba"] += t
        log(f"{name}: seed {seed} done (mcrt {secs['mcrt']:.1f} s, Mitsuba {secs['mitsuba']:.1f} s so far)")
    mc, mt = stats(*halves["mcrt"]), stats(*halves["mitsuba"])
    for k in halves:
        for seed in SEEDS:
            (out / f"{k}-half{seed}.exr").unlink(missing_ok=True)
    images.write_exr(out / "mcrt.exr", mc["img"].astype(np.float32))
    images.write_exr(out / "mitsuba.exr", mt["img"].astype(np.float32))
    diff = mt["img"] - mc["img"]
    se = float(np.sqrt(mc["var_of_mean"] + mt["var_of_mean"]))
    r = {"scene": str(path), "name": name, "size": [w, h], "spp": spp, "max_depth": depth,
         "mitsuba_max_depth": depth + 1, "variant": mi.variant, "mitsuba_version": mi.version,
         "named_spectra": a.named_spectra, "filter": sc.filter_text, "notes": sc.notes,
         "mcrt_mean": mc["mean"], "mitsuba_mean": mt["mean"],
         "mcrt_channel_means": mc["channel_means"], "mitsuba_channel_means": mt["channel_means"],
         "rel_diff_percent": 100 * (mt["mean"] - mc["mean"]) / mc["mean"],
         "rel_diff_se_percent": 100 * se / mc["mean"],
         "rmse": float(np.sqrt(np.mean(diff ** 2))),
         "rmse_expected_from_noise": float(np.sqrt(mc["noise_mse"] + mt["noise_mse"])),
         "seconds": secs, "seeds": list(SEEDS), "mcrt_commands": mcrt_cmds,
         "mitsuba_call": f"mi.render(mi.load_dict(<scene.xml's scene, {spp // 2} spp>), spp={spp // 2}, "
                         f"seed=S) for S in {list(SEEDS)}, averaged"}
    r["z"] = r["rel_diff_percent"] / r["rel_diff_se_percent"] if r["rel_diff_se_percent"] else 0.0
    if a.reference:
        ref = images.read_exr(a.reference).astype(np.float64)
        r["reference"] = {"file": str(a.reference), "size": [ref.shape[1], ref.shape[0]],
                          "mean": float(ref.mean()),
                          "mcrt_rel_percent": 100 * (mc["mean"] - ref.mean()) / ref.mean(),
                          "mitsuba_rel_percent": 100 * (mt["mean"] - ref.mean()) / ref.mean()}
    r["png_scale"] = png(out / f"{name}-side.png", mc["img"], mt["img"], a.png_width)
    (out / "result.json").write_text(json.dumps(r, indent=1))
    return r


def row(r):
    return (f"| {r['name']} | {r['size'][0]}x{r['size'][1]} | {r['spp']} | {r['max_depth']} | "
            f"{r['mcrt_mean']:.5f} | {r['mitsuba_mean']:.5f} | {r['rel_diff_percent']:+.3f} % "
            f"(SE {r['rel_diff_se_percent']:.3f} %) | {r['rmse']:.4f} | {r['rmse_expected_from_noise']:.4f} |")


HEADER = ("| scene | size | spp | depth | mcrt mean | Mitsuba mean | Mitsuba vs mcrt | RMSE | RMSE from noise |\n"
          "|---|---|---|---|---|---|---|---|---|")


def main(a):
    from .mitsuba_run import Mitsuba
    t0 = time.time()
    log = lambda msg: print(f"[{time.time() - t0:7.1f} s] {msg}", flush=True, file=__import__("sys").stderr)
    a.out.mkdir(parents=True, exist_ok=True)
    if not Path(a.mcrt).is_file():
        raise SystemExit(f"mcrt binary {a.mcrt} not found")
    mi = Mitsuba(a.threads, variant=a.variant)
    rows = []
    for p in a.pbrt:
        r = compare(a, p, mi, log)
        rows.append(r)
        log(f"{r['name']}: mcrt {r['mcrt_mean']:.5f}, Mitsuba {r['mitsuba_mean']:.5f}, "
            f"{r['rel_diff_percent']:+.3f} % (SE {r['rel_diff_se_percent']:.3f} %), RMSE {r['rmse']:.4f} "
            f"(noise {r['rmse_expected_from_noise']:.4f})")
        if "reference" in r:
            ref = r["reference"]
            log(f"{r['name']}: reference {ref['file']} mean {ref['mean']:.5f}: mcrt {ref['mcrt_rel_percent']:+.3f} %, "
                f"Mitsuba {ref['mitsuba_rel_percent']:+.3f} %")
    print(HEADER)
    for r in rows:
        print(row(r))
