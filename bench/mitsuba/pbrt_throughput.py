"""`python -m bench.mitsuba --pbrt-throughput`: render throughput and
efficiency of mcrt against Mitsuba 3's LLVM variant on a >= 1M-triangle mesh.

The scene (mesh_scene.py) is a pbrt-v4 file written into OUT: the Cornell
room, one area light and a displaced icosphere of 20 * 4^level triangles.
mcrt reads the file itself; Mitsuba renders it translated by pbrt_translate,
in `llvm_ad_rgb` (the JIT-compiled wavefront variant, tracing with Embree)
and, for context, `scalar_rgb`. Both with the same threads, size, spp, depth
(path, maxdepth 5; Mitsuba max_depth 6), box filter, independent sampler.

Timing: mcrt's `render_seconds` of --stats (rendering alone; the process's
wall time minus it is reported as mcrt's load: parsing, the PLY, the BVH
build, the EXR written). Mitsuba's: mitsuba_run.Mitsuba.render, the wall time
of mi.render + dr.eval + dr.sync_thread, after one untimed warm-up render of
the same size and spp (JIT compilation, kernel cache); its load is
mi.load_dict (the PLY and Embree's build), timed once.

Rounds: each round runs every configuration once, in turn, the order reversed
on every other round; all renders of round r use seed r + 1. Samples per
second = width * height * spp / seconds; the mcrt / Mitsuba ratios are taken
within each round and reported as median (min..max).

Efficiency: 1 / (mean MSE * mean seconds) over the rounds, each MSE against
that renderer's own converged reference (images.reference: two halves with
seeds the rounds never use; Mitsuba's rendered with llvm_ad_rgb in passes of
--ref-pass-spp so that the wavefront stays small). The two references'
means are compared within their noise.

Profile: one mcrt render under `perf record --call-graph dwarf`; each sample
is put in the category of the innermost frame that matches one of CATEGORIES,
and in the render or the load phase by whether its stack holds render_with.
"""
import json
import os
import re
import shlex
import shutil
import statistics
import subprocess
import time
from pathlib import Path

import numpy as np

from . import images, mesh_scene, pbrt_compare, pbrt_translate
from .mcrt_run import Mcrt
from .pbrt_parse import PbrtError

ROOT = Path(__file__).resolve().parents[2]
LLVM = "llvm_ad_rgb"
MCRT_CONFIGS = [  # (name, flags)
    ("mcrt", []),                           # as the file sets it: Russian roulette from the 1st bounce
    ("mcrt --rr-depth 5", ["--rr-depth", "5"]),  # no roulette at maxdepth 5: Mitsuba's work per sample
]

# (category, regex on the frame's name with template arguments and parameter lists removed)
CATEGORIES = [
    ("BVH traversal", r"mcrt::bvh::(traverse|closest|any|occluded)|basic_scene::hit_accelerated"
                      r"|basic_scene::(hit|occluded|any_hit)$"),
    ("triangle intersection", r"intersect_triangle|triangle::hit$|triangle::intersect"),
    ("hit record (surface_at, normals, ray origins)", r"triangle::(surface_at|normal)|hit_record::|spawn_origin"
                                                      r"|surface_point"),
    ("light selection and sampling", r"light_selection|_sampler::(sample|pdf)|rect_area|triangle_area|"
                                     r"dispatch::{lambda|mcrt::dispatch$|triangle::area|sample_light|light_pdf|"
                                     r"spherical_triangle|mcrt::sample$|mcrt::pdf$"),
    ("BSDF and shading", r"lambert|bsdf|material|scatter|onb|cosine_hemisphere|diffuse"),
    ("sampler (random numbers)", r"independent_sampler|pixel_sampler|pcg|random|rng"),
    ("camera rays", r"camera::"),
    ("integrator (path loop, MIS, film)", r"next_event_integrator|mis_integrator|shadow_ray_radiance|heuristic"
                                          r"|render_with|film|accumulate"),
]
LOAD_RE = r"load_scene|load_pbrt|build_accelerator|bvh::build|bvh::bvh$|read_ply|add_mesh|_dl_|dl_main"


def strip_name(sym):
    """'a::b<x, c<y>>::f(int) const' -> 'a::b::f'."""
    out, depth = [], 0
    for ch in sym:
        if ch in "<(":
            depth += 1
        elif ch in ">)":
            depth = max(0, depth - 1)
        elif depth == 0:
            out.append(ch)
    return "".join(out).replace(" const", "").strip()


def classify(frames):
    """(phase, category) of one perf sample; frames innermost first."""
    names = [strip_name(f) for f in frames]
    render = any("render_with" in n for n in names)
    if not render:
        return "load and other", ("load (parse, PLY, BVH build)" if any(re.search(LOAD_RE, n) for n in names)
                                  else "other (process start, image output, kernel)")
    for n in names:
        for cat, rx in CATEGORIES:
            if re.search(rx, n):
                if cat in ("BVH traversal", "triangle intersection", "hit record (surface_at, normals, ray origins)"):
                    kind = "shadow" if any("shadow_ray_radiance" in m for m in names) else "path"
                    return "render", f"{cat} [{kind} rays]"
                return "render", cat
    return "render", "other (kernel, libc, unresolved)"


def profile(a, mcrt, scene, w, h, log):
    """One mcrt render under perf: the category shares and the top symbols (self time)."""
    perf = shutil.which("perf") or "/usr/bin/perf"
    if not Path(perf).exists():
        return {"error": "perf not found"}
    data = a.out / "perf.data"
    cmd = [perf, "record", "--call-graph", "dwarf,16384", "-F", str(a.perf_freq), "-o", str(data), "--",
           mcrt.binary, "render", str(scene), "-o", str(a.out / "perf.exr"), "--width", str(w),
           "--height", str(h), "--spp", str(a.profile_spp), "--seed", "7", "--threads", str(a.threads),
           "--stats", str(a.out / "perf.stats.json"), "--quiet"]
    log(shlex.join(cmd))
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return {"error": f"perf record failed ({p.returncode}): {p.stderr.strip()[-500:]}", "command": shlex.join(cmd)}
    st = json.loads((a.out / "perf.stats.json").read_text())
    script = subprocess.run([perf, "script", "-i", str(data), "-F", "tid,ip,sym", "--no-inline"],
                            capture_output=True, text=True)
    counts, total, unresolved = {}, 0, 0
    for block in script.stdout.split("\n\n"):
        lines = [l.strip() for l in block.strip().splitlines()]
        if len(lines) < 2:
            continue
        frames = [l.split(None, 1)[1] if len(l.split(None, 1)) == 2 else "[unknown]" for l in lines[1:]]
        unresolved += frames[0] == "[unknown]"
        key = classify(frames)
        counts[key] = counts.get(key, 0) + 1
        total += 1
    rep = subprocess.run([perf, "report", "-i", str(data), "--no-children", "--sort", "sym", "-g", "none",
                          "--stdio", "-q", "-t", "|"], capture_output=True, text=True)
    top = []
    for line in rep.stdout.splitlines():
        parts = line.split("|", 1)
        if len(parts) == 2 and parts[0].strip().endswith("%"):
            top.append((float(parts[0].strip().rstrip("%")), strip_name(parts[1].strip().removeprefix("[.] ")
                                                                       .removeprefix("[k] "))))
    merged = {}
    for pct, name in top:
        merged[name] = merged.get(name, 0) + pct
    top = sorted(merged.items(), key=lambda x: -x[1])[:25]
    render_n = sum(n for (ph, _), n in counts.items() if ph == "render")
    return {"command": shlex.join(cmd), "render_seconds": st["render_seconds"], "spp": a.profile_spp,
            "samples": total, "render_samples": render_n, "unresolved_leaf": unresolved,
            "shares": sorted([{"phase": ph, "category": c, "samples": n, "of_total": n / total,
                               "of_render": n / render_n if ph == "render" and render_n else None}
                              for (ph, c), n in counts.items()], key=lambda r: (r["phase"] != "render",
                                                                                -r["samples"])),
            "top_self": [{"symbol": n, "percent": p} for n, p in top]}


def wait_idle(limit_min, threshold, log):
    t0 = time.time()
    while os.getloadavg()[0] >= threshold and time.time() - t0 < 60 * limit_min:
        log(f"load average {os.getloadavg()[0]:.2f} >= {threshold}: waiting")
        time.sleep(30)
    return os.getloadavg()


def machine():
    model = next((l.split(":", 1)[1].strip() for l in subprocess.run(["lscpu"], capture_output=True, text=True)
                  .stdout.splitlines() if l.startswith("Model name")), "?")
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    return {"nproc": os.cpu_count(), "cpu": model, "repo_commit": commit}


def summarize(runs, configs, w, h, spp):
    by = {c: [r for r in runs if r["config"] == c] for c in configs}
    s = {}
    for c, rs in by.items():
        secs, mses = [r["seconds"] for r in rs], [r["mse"] for r in rs]
        s[c] = {"seconds_mean": float(np.mean(secs)), "mse_mean": float(np.mean(mses)),
                "sps_median": statistics.median(r["sps"] for r in rs),
                "sps_min": min(r["sps"] for r in rs), "sps_max": max(r["sps"] for r in rs),
                "efficiency": 1 / (float(np.mean(mses)) * float(np.mean(secs)))}
        loads = [r["load_seconds"] for r in rs if "load_seconds" in r]
        if loads:
            s[c]["load_seconds_median"] = statistics.median(loads)
    ratios = {}
    for c in configs:
        if c.startswith("mcrt"):
            per = [(r, m) for r in by[c] for m in by[f"mitsuba {LLVM}"] if m["round"] == r["round"]]
            sp = [r["sps"] / m["sps"] for r, m in per]
            ef = [r["efficiency"] / m["efficiency"] for r, m in per]
            ratios[c] = {"sps_median": statistics.median(sp), "sps_min": min(sp), "sps_max": max(sp),
                         "eff_of_means": s[c]["efficiency"] / s[f"mitsuba {LLVM}"]["efficiency"],
                         "eff_median": statistics.median(ef), "eff_min": min(ef), "eff_max": max(ef),
                         "mse_ratio": s[c]["mse_mean"] / s[f"mitsuba {LLVM}"]["mse_mean"]}
    return s, ratios


def ref_check(mc, mc_meta, mt, mt_meta):
    d = mt.astype(np.float64) - mc.astype(np.float64)
    se = float(np.sqrt(mc_meta["var_of_mean"] + mt_meta["var_of_mean"]))
    return {"mcrt_mean": mc_meta["mean"], "mitsuba_mean": mt_meta["mean"],
            "rel_diff_percent": 100 * (mt_meta["mean"] - mc_meta["mean"]) / mc_meta["mean"],
            "rel_diff_se_percent": 100 * se / mc_meta["mean"],
            "z": (mt_meta["mean"] - mc_meta["mean"]) / se if se else 0.0,
            "rmse": float(np.sqrt(np.mean(d ** 2))),
            "rmse_from_noise": float(np.sqrt(mc_meta["noise_mse"] + mt_meta["noise_mse"]))}


def markdown(r):
    w, h, spp = r["size"][0], r["size"][1], r["spp"]
    what = (f"{r['mesh']['triangles']:,} mesh triangles + 12 wall and light triangles" if r["mesh"]["triangles"]
            else "the file's own shapes and lights")
    first = r["configs"][0]
    L = [f"Scene: `{r['scene']}` ({what}), "
         f"{w}x{h}, {spp} spp, path maxdepth {r['max_depth']}, box filter, independent sampler, "
         f"{r['threads']} threads each.", "",
         f"Loads: mcrt {r['summary'][first]['load_seconds_median']:.2f} s (median process wall time minus "
         f"render_seconds: parse, PLY, BVH build, EXR write); Mitsuba `{LLVM}` mi.load_dict "
         f"{r['mitsuba_load_seconds'][LLVM]:.2f} s"
         + (f", `scalar_rgb` {r['mitsuba_load_seconds']['scalar_rgb']:.2f} s" if "scalar_rgb" in
            r["mitsuba_load_seconds"] else "")
         + f"; the Python translation {r['translate_seconds']:.1f} s (not counted).", "",
         "| round | " + " | ".join(r["configs"]) + " |", "|---|" + "---|" * len(r["configs"])]
    for k in range(r["rounds"]):
        cells = []
        for c in r["configs"]:
            x = next(x for x in r["runs"] if x["round"] == k and x["config"] == c)
            cells.append(f"{x['seconds']:.3f} s, {x['sps'] / 1e6:.3f} M/s, MSE {x['mse']:.3e}")
        L.append(f"| {k + 1} | " + " | ".join(cells) + " |")
    L += ["", "| configuration | samples/s median (min..max) | mean s | mean MSE | efficiency 1/(MSE s) |",
          "|---|---|---|---|---|"]
    for c in r["configs"]:
        s = r["summary"][c]
        L.append(f"| {c} | {s['sps_median'] / 1e6:.3f} M ({s['sps_min'] / 1e6:.3f}..{s['sps_max'] / 1e6:.3f}) | "
                 f"{s['seconds_mean']:.3f} | {s['mse_mean']:.4e} | {s['efficiency']:.4g} |")
    L += ["", f"| mcrt / Mitsuba `{LLVM}` | samples/s, median of rounds (min..max) | efficiency, of the means "
              "| efficiency, median of rounds (min..max) | MSE ratio |", "|---|---|---|---|---|"]
    for c, q in r["ratios"].items():
        L.append(f"| {c} | {q['sps_median']:.3f} ({q['sps_min']:.3f}..{q['sps_max']:.3f}) | "
                 f"{q['eff_of_means']:.3f} | {q['eff_median']:.3f} ({q['eff_min']:.3f}..{q['eff_max']:.3f}) | "
                 f"{q['mse_ratio']:.3f} |")
    rc = r["reference_check"]
    L += ["", f"References ({r['ref_spp']} spp each, own renderer): mcrt mean {rc['mcrt_mean']:.6f}, "
              f"Mitsuba mean {rc['mitsuba_mean']:.6f}, Mitsuba vs mcrt {rc['rel_diff_percent']:+.3f} % "
              f"(SE {rc['rel_diff_se_percent']:.3f} %, z = {rc['z']:+.2f}); RMSE of the difference "
              f"{rc['rmse']:.4g}, from their noise alone {rc['rmse_from_noise']:.4g}. Reference noise in "
              f"each MSE: mcrt {r['ref_noise_mse']['mcrt']:.3e}, Mitsuba {r['ref_noise_mse']['mitsuba']:.3e}."]
    pr = r.get("profile")
    if pr and "error" not in pr:
        L += ["", f"mcrt profile ({pr['spp']} spp, render {pr['render_seconds']:.2f} s; {pr['samples']} perf "
                  f"samples, {pr['render_samples']} in the render):", "",
              "| phase | category | share of the render | share of the process |", "|---|---|---|---|"]
        for x in pr["shares"]:
            of_render = "" if x["of_render"] is None else f"{100 * x['of_render']:.1f} %"
            L.append(f"| {x['phase']} | {x['category']} | {of_render} | {100 * x['of_total']:.1f} % |")
        L += ["", "Top symbols, self time over the whole process (templates stripped):", "",
              "| % | symbol |", "|---|---|"]
        L += [f"| {x['percent']:.2f} | `{x['symbol']}` |" for x in pr["top_self"][:15]]
    elif pr:
        L += ["", f"Profile: {pr['error']}"]
    return "\n".join(L) + "\n"


def main(a):
    from .mitsuba_run import Mitsuba
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
    t0 = time.time()
    log = lambda msg: print(f"[{time.time() - t0:7.1f} s] {msg}", flush=True, file=__import__("sys").stderr)
    a.out.mkdir(parents=True, exist_ok=True)
    if a.throughput_scene:
        # A given file (its own lights and meshes): identified by its text.
        import hashlib  # noqa: PLC0415
        scene = a.throughput_scene
        mesh = {"ply_sha256": hashlib.sha256(scene.read_bytes()).hexdigest(), "triangles": None}
    else:
        scene, mesh = mesh_scene.write(a.out, a.triangles, a.size, a.spp, a.max_depth, log)
    mcrt_configs = a.configs or MCRT_CONFIGS
    w = h = a.size
    mcrt = Mcrt(a.mcrt, a.threads, lambda purpose, cmd: log(f"{purpose}: {cmd}"))
    tt = time.time()
    try:
        sc = pbrt_translate.translate(scene, a.out / "mitsuba-files")
    except PbrtError as e:
        raise SystemExit(f"bench.mitsuba --pbrt-throughput: {e}") from None
    translate_seconds = time.time() - tt
    variants = [LLVM] + ([] if a.no_scalar else ["scalar_rgb"])
    mis, mi_scenes, mi_load = {}, {}, {}
    tree = pbrt_compare.mitsuba_tree(sc, w, h, a.spp, a.max_depth)
    for v in variants:
        mis[v] = Mitsuba(a.threads, variant=v)
        tl = time.time()
        mi_scenes[v] = mis[v].mi.load_dict(pbrt_compare.to_dict(tree, mis[v].mi))
        mi_load[v] = time.time() - tl
        log(f"Mitsuba {v}: loaded in {mi_load[v]:.2f} s")

    def mi_render(v, scene_, spp, seed):
        mis[v].mi.set_variant(v)  # the variants share one process; each render runs under its own
        return mis[v].render(scene_, spp, seed)

    ident = {"scene": scene.read_text(), "ply_sha256": mesh["ply_sha256"], "size": [w, h]}
    # references, cached in OUT/refs
    mc_ref, _, mc_meta, _ = images.reference(
        a.out, "mcrt", dict(ident, renderer="mcrt", sha256=mcrt.sha256, spp=a.ref_spp, depth=a.max_depth),
        a.ref_spp, lambda seed, spp: _mcrt(mcrt, scene, a.out / f"ref-{seed}.exr", spp, seed, w, h, [],
                                           a.max_depth, "reference")[:2], log)
    ref_tree = pbrt_compare.mitsuba_tree(sc, w, h, a.ref_pass_spp, a.max_depth)
    mis[LLVM].mi.set_variant(LLVM)  # load_dict builds the scene of the current variant
    ref_scene = mis[LLVM].mi.load_dict(pbrt_compare.to_dict(ref_tree, mis[LLVM].mi))

    def mi_half(seed, spp):
        passes = max(1, spp // a.ref_pass_spp)
        acc, secs = None, 0.0
        for k in range(passes):
            img, t, _ = mi_render(LLVM, ref_scene, a.ref_pass_spp, seed * 1000 + k)
            acc = img.astype(np.float64) if acc is None else acc + img
            secs += t
        return (acc / passes).astype(np.float32), secs
    mt_ref, _, mt_meta, _ = images.reference(
        a.out, "mitsuba", dict(ident, renderer="mitsuba", version=mis[LLVM].version, variant=LLVM,
                               spp=a.ref_spp, pass_spp=a.ref_pass_spp, depth=a.max_depth),
        a.ref_spp, mi_half, log)
    check = ref_check(mc_ref, mc_meta, mt_ref, mt_meta)
    log(f"references: Mitsuba vs mcrt {check['rel_diff_percent']:+.3f} % (z {check['z']:+.2f}), "
        f"RMSE {check['rmse']:.4g} (noise {check['rmse_from_noise']:.4g})")

    load_before = wait_idle(a.wait_idle, a.idle_load, log) if a.wait_idle else os.getloadavg()
    log(f"load average before the rounds: {load_before}")
    # warm-ups, untimed: mcrt's files into the page cache, Mitsuba's kernels compiled
    _mcrt(mcrt, scene, a.out / "warm.exr", a.spp, 0, w, h, [], a.max_depth, "warm-up")
    for v in variants:
        mi_render(v, mi_scenes[v], a.spp, 0)
    items = [("mcrt", n, f) for n, f in mcrt_configs] + [("mitsuba", f"mitsuba {v}", v) for v in variants]
    runs = []
    for k in range(a.rounds):
        seed = k + 1
        for renderer, name, what in (items if k % 2 == 0 else items[::-1]):
            r = {"round": k, "seed": seed, "config": name}
            if renderer == "mcrt":
                img, sec, st, wall = _mcrt(mcrt, scene, a.out / "run.exr", a.spp, seed, w, h, what,
                                           a.max_depth, f"round {k + 1}")
                r.update(command=st["command"], load_seconds=wall - sec, wall_seconds=wall,
                         mse=images.mse(img, mc_ref), ref_noise_mse=mc_meta["noise_mse"],
                         nonfinite=st.get("nonfinite_samples"))
            else:
                img, sec, cpu = mi_render(what, mi_scenes[what], a.spp, seed)
                r.update(command=f"mi.render(scene, spp={a.spp}, seed={seed}) + dr.eval + dr.sync_thread "
                                 f"[{what}]", cpu_seconds=cpu, mse=images.mse(img, mt_ref),
                         ref_noise_mse=mt_meta["noise_mse"], nonfinite=int(np.count_nonzero(~np.isfinite(img))))
            r.update(seconds=sec, sps=w * h * a.spp / sec, mean=float(img.astype(np.float64).mean()))
            r["efficiency"] = 1 / (r["mse"] * sec)
            runs.append(r)
            log(f"round {k + 1} {name:22s} {sec:7.3f} s  {r['sps'] / 1e6:6.3f} M samples/s  MSE {r['mse']:.4e}  "
                f"eff {r['efficiency']:.4g}")
    load_after = os.getloadavg()
    configs = [n for _, n, _ in items]
    summary, ratios = summarize(runs, configs, w, h, a.spp)
    res = {"scene": str(scene), "mesh": mesh, "size": [w, h], "spp": a.spp, "max_depth": a.max_depth,
           "mitsuba_max_depth": a.max_depth + 1, "threads": a.threads, "rounds": a.rounds,
           "ref_spp": a.ref_spp, "ref_pass_spp": a.ref_pass_spp, "configs": configs, "runs": runs,
           "summary": summary, "ratios": ratios, "reference_check": check,
           "ref_noise_mse": {"mcrt": mc_meta["noise_mse"], "mitsuba": mt_meta["noise_mse"]},
           "mcrt_sha256": mcrt.sha256, "mcrt_binary": mcrt.binary, "mitsuba_version": mis[LLVM].version,
           "drjit_version": mis[LLVM].drjit_version, "mitsuba_load_seconds": mi_load,
           "translate_seconds": translate_seconds, "machine": machine(),
           "loadavg_before": list(load_before), "loadavg_after": list(load_after),
           "filter": sc.filter_text, "notes": sc.notes}
    for c, q in ratios.items():
        log(f"{c} / Mitsuba {LLVM}: samples/s {q['sps_median']:.3f} ({q['sps_min']:.3f}..{q['sps_max']:.3f}), "
            f"efficiency {q['eff_of_means']:.3f} (rounds {q['eff_min']:.3f}..{q['eff_max']:.3f})")
    if not a.no_profile:
        res["profile"] = profile(a, mcrt, scene, w, h, log)
    (a.out / "throughput.json").write_text(json.dumps(res, indent=1))
    md = markdown(res)
    (a.out / "throughput.md").write_text(md)
    print(md)


def _mcrt(mcrt, scene, out, spp, seed, w, h, flags, depth, purpose):
    """(image, render_seconds, stats, process wall seconds) of one mcrt render."""
    t = time.perf_counter()
    st = mcrt.render(scene, out, spp, seed, w, h, flags, depth, purpose=purpose)
    wall = time.perf_counter() - t
    img = images.read_exr(out)
    Path(out).unlink()
    return img, st["render_seconds"], st, wall
