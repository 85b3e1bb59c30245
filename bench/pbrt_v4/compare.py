"""`python3 -m bench.pbrt_v4 FILE.pbrt ...`: one pbrt-v4 file rendered by
mcrt and by pbrt-v4 at the same resolution, spp and depth, from one
settings copy of the file (scene_copy.py), and compared three ways:

1. **Mean per channel** of each renderer's converged image (REF spp, two
   halves of different seeds), and their relative difference, with its
   standard error from the halves.
2. **8x8-block z-scores**: K runs of each renderer at SPP with seeds
   1..K; per block and channel, z = (m_mcrt - m_pbrt) / sqrt(se_mcrt^2 +
   se_pbrt^2), the standard errors across the K runs (so each renderer's
   own noise, whatever its distribution over pixels). With K = 8 the
   statistic is about Student's t with some 14 degrees of freedom: |z| >= 4
   has probability about 0.0013 per block where the images agree.
3. **Efficiency** 1/(MSE * seconds) of each run against its own
   renderer's converged image, the converged image's own noise (from its
   halves) subtracted from the MSE; the runs interleaved (mcrt, pbrt-v4,
   pbrt-v4, mcrt, ...), 2 threads each by default.

`--tolerance X` checks "mean per channel within X %, |z| < 4 on >= 99 % of
the 8x8 blocks" and exits 1 when it fails.
"""
import hashlib
import json
import statistics
from pathlib import Path

import numpy as np

from . import renderers, scene_copy

REF_SEEDS = (1000001, 1000002)
BLOCK = 8


def _sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]


def _reference(name, binary, copy, args, out_dir):
    """The mean of two half-REF renders, its per-pixel noise variance, and
    the seconds they took; cached by binary, scene copy and settings."""
    key = hashlib.sha256(f"{name} {_sha(binary)} {_sha(copy)} {args.ref_spp} {args.threads}".encode())
    key = key.hexdigest()[:16]
    halves = []
    for i, seed in enumerate(REF_SEEDS):
        exr = out_dir / "refs" / f"{name}-{key}-{i}.exr"
        exr.parent.mkdir(parents=True, exist_ok=True)
        if not exr.exists():
            tmp = exr.with_name(exr.stem + ".part.exr")
            renderers.RUNNERS[name](binary, copy, tmp, args.ref_spp // 2, seed, args.threads)
            tmp.replace(exr)
        halves.append(renderers.read_exr(exr))
    a, b = halves
    return (a + b) / 2, (a - b) ** 2 / 4


def _blocks(img):
    h, w = (img.shape[0] // BLOCK) * BLOCK, (img.shape[1] // BLOCK) * BLOCK
    return img[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, 3).mean(axis=(1, 3))


def run(args):
    binaries = {"mcrt": Path(args.mcrt), "pbrt-v4": Path(args.pbrt)}
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    standins = Path(args.pbrt).parent.parent / "standins.txt"
    standins = standins.read_text().split() if standins.exists() else []
    if standins and scene_copy.sampler_kind(args.file) == '"pmj02bn"':
        raise scene_copy.SceneError(f"{args.file}: Sampler \"pmj02bn\" reads pbrt-v4's table, a stand-in in this build")
    copy = scene_copy.settings_copy(args.file, args.width, args.height, args.spp, args.max_depth,
                                    integrator=args.integrator, grey_lights=args.grey_lights)
    runs = {n: [] for n in binaries}
    try:
        refs = {n: _reference(n, b, copy, args, out_dir) for n, b in binaries.items()}
        order = list(binaries)
        for k in range(args.seeds):
            for n in (order if k % 2 == 0 else order[::-1]):
                exr = out_dir / f"run-{n}.exr"
                seconds = renderers.RUNNERS[n](binaries[n], copy, exr, args.spp, k + 1, args.threads)
                runs[n].append((renderers.read_exr(exr), seconds))
    finally:
        copy.unlink()

    res = {"file": str(args.file), "grey_lights": args.grey_lights, "width": args.width, "height": args.height, "spp": args.spp,
           "ref_spp": args.ref_spp, "max_depth": args.max_depth, "integrator": args.integrator, "seeds": args.seeds,
           "threads": args.threads, "renderers": {}}
    for n in binaries:
        ref, noise = refs[n]
        imgs = np.stack([r[0] for r in runs[n]])
        mse = [float(np.mean((r[0] - ref) ** 2) - np.mean(noise)) for r in runs[n]]
        secs = [r[1] for r in runs[n]]
        res["renderers"][n] = {
            "channel_means": [float(x) for x in ref.reshape(-1, 3).mean(axis=0)],
            # The standard error of the reference's channel means, from its two halves.
            "channel_se": [float(x) for x in np.sqrt(noise.reshape(-1, 3).sum(axis=0)) / (ref.size // 3)],
            "seconds": statistics.median(secs), "mse": statistics.median(mse),
            "efficiency": statistics.median(1.0 / (m * s) for m, s in zip(mse, secs) if m > 0)
            if any(m > 0 for m in mse) else float("inf"),
            "blocks": _blocks_of(imgs)}
    m, p = res["renderers"]["mcrt"], res["renderers"]["pbrt-v4"]
    res["channel_diff_percent"] = [100 * (a - b) / b if b else 0.0 for a, b in zip(m["channel_means"], p["channel_means"])]
    res["channel_diff_se_percent"] = [100 * float(np.hypot(sa, sb)) / b if b else 0.0 for sa, sb, b in
                                      zip(m["channel_se"], p["channel_se"], p["channel_means"])]
    mb, pb = m.pop("blocks"), p.pop("blocks")
    diff = mb[0] - pb[0]
    se = np.sqrt(mb[1] ** 2 + pb[1] ** 2)
    z = np.where(se > 0, diff / np.where(se > 0, se, 1), np.where(diff == 0, 0.0, np.inf))
    res["blocks"] = int(z.size)
    res["z_below_4_percent"] = float(100 * np.mean(np.abs(z) < 4))
    res["z_max"] = float(np.max(np.abs(z)))
    res["efficiency_ratio"] = m["efficiency"] / p["efficiency"] if p["efficiency"] else float("inf")
    res["pbrt_standins"] = standins
    if args.tolerance is not None:
        res["tolerance_percent"] = args.tolerance
        res["pass"] = bool(max(abs(d) for d in res["channel_diff_percent"]) <= args.tolerance
                           and res["z_below_4_percent"] >= 99.0)
    (out_dir / "results.json").write_text(json.dumps(res, indent=1) + "\n")
    print(report(res))
    return 0 if res.get("pass", True) else 1


def _blocks_of(imgs):
    """Per 8x8 block and channel: the mean over the K runs and its standard error."""
    b = np.stack([_blocks(i) for i in imgs])
    return b.mean(axis=0), b.std(axis=0, ddof=1) / np.sqrt(len(b))


def report(res):
    m, p = res["renderers"]["mcrt"], res["renderers"]["pbrt-v4"]
    grey = " (lights made grey)" if res["grey_lights"] else ""
    lines = [f"{res['file']}{grey}: {res['width']}x{res['height']}, {res['spp']} spp (references {res['ref_spp']}), "
             f"{res.get('integrator', 'path')} maxdepth {res['max_depth']}, {res['seeds']} seeds, {res['threads']} threads each",
             "", "| | mcrt | pbrt-v4 | difference |", "|---|---|---|---|"]
    for c, name in enumerate("RGB"):
        lines.append(f"| mean {name} | {m['channel_means'][c]:.5g} | {p['channel_means'][c]:.5g} | "
                     f"{res['channel_diff_percent'][c]:+.3f} % ± {res['channel_diff_se_percent'][c]:.3f} |")
    lines += [f"| seconds per run (median) | {m['seconds']:.2f} | {p['seconds']:.2f} | |",
              f"| MSE per run (median) | {m['mse']:.4g} | {p['mse']:.4g} | |",
              f"| efficiency 1/(MSE·s) | {m['efficiency']:.4g} | {p['efficiency']:.4g} | "
              f"mcrt {res['efficiency_ratio']:.2f}× |",
              "", f"8×8 blocks × channels: {res['z_below_4_percent']:.2f} % of {res['blocks']} with |z| < 4 "
              f"(max |z| {res['z_max']:.2f})"]
    if res["pbrt_standins"]:
        lines.append(f"pbrt-v4 built with stand-ins for {', '.join(res['pbrt_standins'])} (bench/pbrt_v4/build.sh)")
    if "pass" in res:
        lines.append(f"tolerance {res['tolerance_percent']} %: {'pass' if res['pass'] else 'FAIL'}")
    return "\n".join(lines)
