#!/usr/bin/env python3
"""auto against the fixed strategies in a results.csv of scripts/study.py (the triangle families, the strategy map).

Per scene and depth mode (global light marked), and per strategy, the efficiency 1/(MSE x seconds) of each seed, averaged over the sweep's spp;
per scene the ratio auto / best fixed strategy (the best by its mean over seeds) and auto / pbrt (where
pbrt was run), each
as the mean over seeds with a 95 % t interval (3 seeds: t = 4.30); then the geometric means over the
scenes. Prints a markdown table.

    python3 bench/auto_summary.py bench/results/triangle_map/results.csv
"""
import csv
import math
import statistics
import sys
from collections import defaultdict

T95 = {2: 12.71, 3: 4.30, 4: 3.18, 5: 2.78}


def main(path: str) -> int:
    eff = defaultdict(lambda: defaultdict(list))  # (scene) -> (strategy, seed) -> [eff per spp]
    params = {}
    for r in csv.DictReader(open(path)):
        mse, sec = float(r["mse"]), float(r["seconds"])
        if not (mse > 0 and sec > 0):
            continue
        scene = r["scene"] + ("" if r["max_depth"] == "1" else " (global)")
        eff[scene][(r["strategy"], int(r["seed"]))].append(1.0 / (mse * sec))
        params[scene] = (r["family"], float(r["family_param"]), r["max_depth"], float(r["light_solid_angle"]))
    fixed = ["area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "pbrt"]
    with_pbrt = any(s == "pbrt" for per in eff.values() for s, _ in per)
    print("| scene | solid angle (sr) | best fixed | auto ÷ best (95 % CI over seeds) |"
          + (" auto ÷ pbrt (95 % CI) |" if with_pbrt else "") + " auto's rank |")
    print("|---|---:|---|---:|" + ("---:|" if with_pbrt else "") + "---:|")
    g_best, g_pbrt, below = [], [], []
    for scene in sorted(eff, key=lambda s: params[s][:2]):
        per = eff[scene]
        seeds = sorted({k[1] for k in per})
        mean = {s: statistics.mean(statistics.mean(per[(s, k)]) for k in seeds if (s, k) in per)
                for s in fixed + ["auto"] if all((s, k) in per for k in seeds)}
        if "auto" not in mean:
            continue
        best = max((s for s in fixed if s in mean), key=lambda s: mean[s])

        def ratio(other):
            xs = [statistics.mean(per[("auto", k)]) / statistics.mean(per[(other, k)]) for k in seeds]
            m = statistics.mean(xs)
            h = T95.get(len(xs), 2.0) * statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")
            return m, h, mean["auto"] / mean[other]

        mb, hb, rb = ratio(best)
        rank = 1 + sum(mean[s] > mean["auto"] for s in fixed if s in mean)
        g_best.append(rb)
        if rb < 0.9:
            below.append(scene)
        pbrt_cell = ""
        if with_pbrt:
            mp, hp, rp = ratio("pbrt")
            g_pbrt.append(rp)
            pbrt_cell = f" {rp:.3f} ({mp - hp:.2f}–{mp + hp:.2f}) |"
        print(f"| {scene} | {params[scene][3]:.3g} | {best} | {rb:.3f} ({mb - hb:.2f}–{mb + hb:.2f}) |{pbrt_cell} {rank} |")
    gm = lambda xs: math.exp(sum(map(math.log, xs)) / len(xs))
    print(f"\nGeometric means over {len(g_best)} scenes: auto ÷ best fixed {gm(g_best):.3f}"
          + (f", auto ÷ pbrt {gm(g_pbrt):.3f}" if with_pbrt else "")
          + f"; auto below 0.9× the best at {len(below)}: {', '.join(below) or 'none'}.")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
