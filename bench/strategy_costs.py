#!/usr/bin/env python3
"""What each light sampling strategy costs per light sample inside a render.

For each scene, renders it with every fixed strategy (nee, Sobol, one
thread, 100 x 100, SPP samples per pixel, REPS runs interleaved, the
fastest kept) and divides each strategy's extra time over the shape's
cheapest strategy by the render's light samples (pixels x spp / the paths
per light sample the `auto` pilot counts, `auto_pilot_paths_per_light_sample`).
These are the in-render costs `auto` weighs with nee, where a light sample's
pdf comes with it (auto_costs::nee in include/mcrt/sampling/auto_strategy.hpp);
the sampler benchmarks time sample + pdf (auto_costs' other table, for the
mixture and mis, which evaluate the light's pdf apart).

Usage: .venv/bin/python bench/strategy_costs.py [--reps 5] [--spp 16] [--mcrt build/mcrt]
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from mcrt_study import scenes as families  # noqa: E402

SCENES = {"rect": ("size_rect_1of4", "size_rect_x1", "size_rect_x8", "distance_h0.1", "distance_h1"),
          "ellipse": ("size_disk_1of4", "size_disk_x1", "size_disk_x8"),
          "sphere": ("size_sphere_1of8", "size_sphere_1of2", "size_sphere_x2")}
STRATEGIES = ("area", "solid-angle", "projected-solid-angle")
CHEAPEST = {"rect": "area", "ellipse": "area", "sphere": "solid-angle"}


def render(mcrt: str, scene: Path, tmp: Path, strategy: str, depth: int, spp: int, threads: int = 1) -> dict:
    stats = tmp / "stats.json"
    subprocess.run([mcrt, "render", str(scene), "-o", str(tmp / "o.exr"), "--spp", str(spp), "--width", "100",
                    "--height", "100", "--max-depth", str(depth), "--integrator", "nee", "--sampler", "sobol",
                    "--threads", str(threads), "--seed", "1", "--light-sampling", strategy, "--quiet", "--stats",
                    str(stats)], check=True)
    return json.loads(stats.read_text())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"))
    a = ap.parse_args()
    print("| shape | scene | light | ns per light sample: area | solid angle | projected solid angle |")
    print("|---|---|---|---:|---:|---:|")
    summary: dict[tuple[str, str], list[dict[str, float]]] = {}
    with tempfile.TemporaryDirectory() as t:
        tmp = Path(t)
        for shape, names in SCENES.items():
            for name in names:
                path = families.write_member(families.family_member(name), tmp)
                for depth, mode in ((1, "direct"), (50, "global")):
                    pilot = render(a.mcrt, path, tmp, "auto", depth, a.spp, threads=2)
                    light_samples = 100 * 100 * a.spp / pilot["auto_pilot_paths_per_light_sample"]
                    times: dict[str, list[float]] = {s: [] for s in STRATEGIES}
                    for _ in range(a.reps):
                        for s in STRATEGIES:
                            times[s].append(render(a.mcrt, path, tmp, s, depth, a.spp)["render_seconds"])
                    base = min(times[CHEAPEST[shape]])
                    extra = {s: (min(times[s]) - base) * 1e9 / light_samples for s in STRATEGIES}
                    summary.setdefault((shape, mode), []).append(extra)
                    print(f"| {shape} | {name} | {mode} | " + " | ".join(f"{extra[s]:+.0f}" for s in STRATEGIES) + " |",
                          flush=True)
    print("\nMedian over each shape's scenes, ns per light sample over the cheapest strategy:\n")
    print("| shape | light | area | solid angle | projected solid angle |\n|---|---|---:|---:|---:|")
    for (shape, mode), rows in summary.items():
        print(f"| {shape} | {mode} | " + " | ".join(f"{statistics.median(r[s] for r in rows):+.0f}" for s in STRATEGIES)
              + " |")


if __name__ == "__main__":
    main()
