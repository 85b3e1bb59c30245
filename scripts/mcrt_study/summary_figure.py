"""The one-figure summary of the committed results (docs/images/summary.png).

    cd scripts && ../.venv/bin/python -m mcrt_study.summary_figure [--out PNG] [--print]

Three panels, from the committed data only (nothing is rendered):

(a) where each fixed strategy pays: efficiency 1/(MSE x time) of solid-angle
    and projected-solid-angle sampling over area sampling's, nee and Sobol,
    direct lighting, on the members of the four generated families of
    bench/results/strategy_map (size_rect, size_disk, size_sphere, distance),
    against the light's solid angle;
(b) auto against the best fixed strategy: auto's efficiency over the best of
    area, solid angle and projected solid angle, at every point (scene and
    depth mode) of bench/results/strategy_map and bench/results/auto;
(c) mcrt against Mitsuba 3: each mcrt configuration's efficiency over
    Mitsuba's path tracer with its default (independent) and its best
    (multijitter) sampler, geometric mean over spp (bench/results/mitsuba/results.json).

The efficiencies are those of the study's reports: per configuration the
geometric mean over its renders (analysis.analyse_configs). --print writes the
numbers the panels show to stdout.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

from .analysis import analyse_configs, family_crossovers
from .config import (CSV_COLUMNS, PRE_SELECT_CSV_COLUMNS, REPO_ROOT, STRATEGY_STYLE, SceneInfo, build_parser,
                     resolve_settings)
from .results import parse_row

RESULTS = REPO_ROOT / "bench" / "results"
MAP_DIR = RESULTS / "strategy_map"
AUTO_DIR = RESULTS / "auto"
MITSUBA_JSON = RESULTS / "mitsuba" / "results.json"
DEFAULT_PNG = REPO_ROOT / "docs" / "images" / "summary.png"

FIXED = ["area", "solid-angle", "projected-solid-angle"]
FAMILIES = ["size_rect", "size_disk", "size_sphere", "distance"]
FAMILY_STYLE = {"size_rect": ("s", "rectangle (size)"), "size_disk": ("o", "disk (size)"),
                "size_sphere": ("^", "sphere (size)"), "distance": ("D", "rectangle (distance)")}
MODE_DEPTH_DIRECT = 1


def read_rows(csv_path: Path) -> list[dict]:
    """The rows of a committed results.csv of the current format, or of the one before the
    light_select column (its rows: the default selection, as parse_row reads them; the file is
    never rewritten here)."""
    with csv_path.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames not in (CSV_COLUMNS, PRE_SELECT_CSV_COLUMNS):
            raise SystemExit(f"summary_figure: {csv_path}: not the study's current CSV format, "
                             "nor the one before light_select")
        return [parse_row(r) for r in reader]


def scenes_of(rows: list[dict]) -> list[SceneInfo]:
    """The scenes of a CSV, in first-appearance order, from its own columns (the global depth is
    the scene's largest max depth)."""
    found: dict[str, SceneInfo] = {}
    depth: dict[str, int] = {}
    for r in rows:
        depth[r["scene"]] = max(depth.get(r["scene"], 0), r["max_depth"])
    for r in rows:
        if r["scene"] not in found:
            found[r["scene"]] = SceneInfo(r["scene"], Path(r["scene"]), "", 0, 0, depth[r["scene"]],
                                          r["family"], r["family_param"], r["light_solid_angle"])
    return list(found.values())


def analyse(csv_dir: Path) -> tuple[dict, object, list[SceneInfo], list[tuple[str, str, int]]]:
    """The per-configuration analysis of a committed study (nee, Sobol, the four strategies)."""
    rows = read_rows(csv_dir / "results.csv")
    strategies = [s for s in [*FIXED, "auto"] if any(r["strategy"] == s for r in rows)]
    argv = ["study.py", "--report-only", "--out", str(csv_dir), "--integrators", "nee", "--samplers", "sobol",
            "--strategies", *strategies, "--spp", *sorted({str(r["spp"]) for r in rows}, key=int),
            "--seeds", *sorted({str(r["seed"]) for r in rows}, key=int)]
    settings = resolve_settings(build_parser().parse_args(argv[1:]), argv)
    scenes = scenes_of(rows)
    panels = [(sc.name, mode, depth) for mode in settings.depths for sc in scenes
              for m, depth in sc.depth_modes(settings.depths) if m == mode]
    return analyse_configs(rows, settings, panels), settings, scenes, panels


def auto_over_best(analysis: dict, panels: list[tuple[str, str, int]]) -> list[dict]:
    """Per point (scene, mode): auto's efficiency over the best fixed strategy's, and which that is."""
    from .config import Config

    points = []
    for scene, mode, depth in panels:
        per = analysis[(scene, depth)]
        fixed = {s: per[Config(s, "nee", "sobol")]["efficiency"] for s in FIXED if Config(s, "nee", "sobol") in per}
        auto = per.get(Config("auto", "nee", "sobol"))
        if not fixed or auto is None:
            continue
        best = max(fixed, key=fixed.get)
        points.append({"scene": scene, "mode": mode, "best": best, "ratio": auto["efficiency"] / fixed[best],
                       "over_every_fixed": auto["efficiency"] > fixed[best]})
    return points


def geomean(values: list[float]) -> float:
    """The geometric mean (nan for none)."""
    return math.exp(sum(map(math.log, values)) / len(values)) if values else float("nan")


def mitsuba_ratios(path: Path) -> dict:
    """Per scene and mcrt configuration: the geometric mean over spp of the efficiency over
    Mitsuba's independent sampler and over its best low-discrepancy one; and the validation."""
    data = json.loads(path.read_text(encoding="utf-8"))
    out: dict = {"ratios": {}, "best_ld": data["best_ld_sampler"], "validation": {},
                 "variant": data.get("mitsuba_variant", "scalar_rgb")}
    for row in data["table"]:
        if row["renderer"] != "mcrt":
            continue
        key = (row["scene"], row["config"].split(":", 1)[1])
        out["ratios"].setdefault(key, {"independent": [], "best_ld": []})
        out["ratios"][key]["independent"].append(row["ratio_to_mitsuba_independent"])
        out["ratios"][key]["best_ld"].append(row["ratio_to_mitsuba_best_ld"])
    out["ratios"] = {k: {w: geomean(v) for w, v in d.items()} for k, d in out["ratios"].items()}
    for scene, v in data["validation"].items():
        ref = v["references"]
        out["validation"][scene] = (ref["mean_diff_percent"], ref["mean_diff_se_percent"])
    return out


def summary() -> dict:
    """Every number the figure shows."""
    map_analysis, map_settings, map_scenes, map_panels = analyse(MAP_DIR)
    crossings = family_crossovers(map_analysis, map_settings, map_scenes)
    auto_analysis, _, _, auto_panels = analyse(AUTO_DIR)
    return {"families": [c for c in crossings if c["strategy"] in FIXED[1:]],
            "map_points": auto_over_best(map_analysis, map_panels),
            "seed_points": auto_over_best(auto_analysis, auto_panels),
            "family_of": {sc.name: sc.family for sc in map_scenes},
            "mitsuba": mitsuba_ratios(MITSUBA_JSON)}


def print_summary(s: dict) -> None:
    """The panels' numbers as text."""
    for f in s["families"]:
        r = f["series"]["ratio"]
        cross = ", ".join(f"{c:.3g} sr" for c in f["crossings"]) or f["verdict"]
        print(f"(a) {f['family']:<11} {f['mode']:<6} {f['strategy']:<21} {min(r):.3g}-{max(r):.3g}x area; "
              f"crosses 1: {cross}")
    for name, points in (("strategy map", s["map_points"]), ("seed scenes", s["seed_points"])):
        r = [p["ratio"] for p in points]
        print(f"(b) {name}: {sum(x >= 0.9 for x in r)} of {len(r)} points at >= 0.9x the best fixed strategy, "
              f"{sum(p['over_every_fixed'] for p in points)} above every fixed one; range {min(r):.3g}-{max(r):.3g}; "
              f"geometric mean {geomean(r):.4g}")
        for mode in ("global", "direct"):
            rm = [p["ratio"] for p in points if p["mode"] == mode]
            print(f"    {mode}: geometric mean {geomean(rm):.4g}, lowest {min(rm):.3g}")
        for p in points:
            if p["scene"] == "cornell_two_lights":
                print(f"    cornell_two_lights {p['mode']}: {p['ratio']:.3g}x the best fixed ({p['best']})")
    m = s["mitsuba"]
    for (scene, config), v in sorted(m["ratios"].items()):
        print(f"(c) {scene:<19} {config:<22} {v['independent']:.3g}x Mitsuba independent, "
              f"{v['best_ld']:.3g}x Mitsuba {m['best_ld'][scene].split(':')[1]}")
    for scene, (d, se) in m["validation"].items():
        print(f"    validation {scene}: converged images differ by {d:+.3f} % +- {se:.3f} %")


def draw(s: dict, png: Path) -> None:
    """The three panels, written to `png`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker as ticker
    import numpy as np

    plain = ticker.FuncFormatter(lambda v, _: f"{v:g}")
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), gridspec_kw={"width_ratios": [1.05, 1.25, 1.0]})

    # (a) fixed strategies over area sampling against the light's solid angle, direct light.
    ax = axes[0]
    for f in s["families"]:
        if f["mode"] != "direct":
            continue
        ser = f["series"]
        order = np.argsort(ser["solid_angle"])
        x, r = np.asarray(ser["solid_angle"])[order], np.asarray(ser["ratio"])[order]
        marker, _ = FAMILY_STYLE[f["family"]]
        ax.plot(x, r, marker=marker, ms=5, lw=1.2, color=STRATEGY_STYLE[f["strategy"]]["color"],
                ls="--" if f["strategy"] == "projected-solid-angle" else "-")
    ax.axhline(1.0, color="k", lw=0.9)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.yaxis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(plain)
    ax.yaxis.set_minor_formatter(ticker.NullFormatter())
    ax.xaxis.set_major_formatter(plain)
    ax.set_xlabel("light solid angle (sr)")
    ax.set_ylabel("efficiency / area sampling's")
    ax.set_title("(a) where a fixed strategy pays\nnee, Sobol, direct light; 25 generated scenes", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=STRATEGY_STYLE[st]["color"], lw=1.5, label=STRATEGY_STYLE[st]["label"],
                          ls="--" if st == "projected-solid-angle" else "-") for st in FIXED[1:]]
    handles += [plt.Line2D([], [], color="0.3", marker=m, ls="none", label=label)
                for m, label in (FAMILY_STYLE[fam] for fam in FAMILIES)]
    ax.legend(handles=handles, fontsize=7, loc="upper left")
    ax.annotate("above 1: better than area sampling", (0.02, 1.0), xycoords=("axes fraction", "data"),
                xytext=(0, 3), textcoords="offset points", fontsize=7, color="0.3")

    # (b) auto over the best fixed strategy, per point.
    ax = axes[1]
    groups = [(fam, [p for p in s["map_points"] if s["family_of"][p["scene"]] == fam]) for fam in FAMILIES]
    groups.append(("Cornell", s["seed_points"]))
    labels = {"size_rect": "rect\n(size)", "size_disk": "disk\n(size)", "size_sphere": "sphere\n(size)",
              "distance": "rect\n(distance)", "Cornell": "Cornell\nscenes"}
    colors = {"global": "tab:red", "direct": "tab:purple"}
    x0, ticks = 0, []
    for name, points in groups:
        for mode in ("global", "direct"):
            mine = [p for p in points if p["mode"] == mode]
            xs = x0 + np.arange(len(mine)) * 1.0
            ax.plot(xs, [p["ratio"] for p in mine], "o", ms=5, color=colors[mode],
                    mfc=colors[mode] if mode == "direct" else "white", label=f"{mode} light" if name == "Cornell" else None)
        n = max(len([p for p in points if p["mode"] == m]) for m in ("global", "direct"))
        ticks.append((x0 + (n - 1) / 2, labels[name]))
        x0 += n + 1.5
    ax.axhline(1.0, color="k", lw=0.9)
    ax.axhline(0.9, color="k", lw=0.8, ls=":")
    ax.set_yscale("log")
    ax.set_ylim(0.8, 3.2)
    ax.yaxis.set_major_locator(ticker.FixedLocator([0.8, 0.9, 1.0, 1.25, 1.5, 2.0, 3.0]))
    ax.yaxis.set_major_formatter(plain)
    ax.yaxis.set_minor_formatter(ticker.NullFormatter())
    ax.set_xticks([t for t, _ in ticks])
    ax.set_xticklabels([label for _, label in ticks], fontsize=8)
    ax.set_ylabel("auto / best fixed strategy (efficiency)")
    mr, sr = ([p["ratio"] for p in s[k]] for k in ("map_points", "seed_points"))
    ax.set_title(f"(b) auto against the best fixed strategy (nee, Sobol)\n"
                 f"map: {sum(r >= 0.9 for r in mr)} of {len(mr)} points ≥ 0.9×, geometric mean {geomean(mr):.2f}×; "
                 f"Cornell: {sum(r >= 0.9 for r in sr)} of {len(sr)}, {geomean(sr):.2f}×", fontsize=9)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")

    # (c) mcrt against Mitsuba 3.
    ax = axes[2]
    m = s["mitsuba"]
    scenes = sorted({sc for sc, _ in m["ratios"]}, key=lambda sc: sc != "cornell_rect")
    configs = ["mixture", "mis-independent-area", "mis-sobol-area", "mis-sobol-solid-angle"]
    config_labels = ["mixture,\nindependent", "mis,\nindependent", "mis,\nsobol", "mis, sobol,\nsolid angle"]
    width = 0.38
    scene_colors = ["tab:blue", "tab:orange"]
    for k, scene in enumerate(scenes):
        xs = np.arange(len(configs)) + (k - 0.5) * width
        best = [m["ratios"][(scene, c)]["best_ld"] for c in configs]
        indep = [m["ratios"][(scene, c)]["independent"] for c in configs]
        ax.bar(xs, best, width * 0.92, color=scene_colors[k], alpha=0.85)
        ax.plot(xs, indep, "v", ms=7, color=scene_colors[k], mec="k", mew=0.6, ls="none")
        for x, v in zip(xs, indep):
            ax.annotate(f"{v:.1f}", (x, v), xytext=(0, 5), textcoords="offset points", ha="center", fontsize=7)
        for x, v in zip(xs, best):
            ax.annotate(f"{v:.2f}", (x, v), xytext=(0, -10), textcoords="offset points", ha="center", fontsize=6)
    ax.axhline(1.0, color="k", lw=0.9)
    ax.set_yscale("log")
    ax.set_ylim(0.2, 40)
    ax.yaxis.set_major_locator(ticker.FixedLocator([0.25, 0.5, 1, 2, 5, 10, 20]))
    ax.yaxis.set_major_formatter(plain)
    ax.yaxis.set_minor_formatter(ticker.NullFormatter())
    ax.set_xticks(range(len(configs)))
    ax.set_xticklabels(config_labels, fontsize=8)
    ax.set_ylabel("mcrt efficiency / Mitsuba 3's")
    ax.set_title(f"(c) mcrt against Mitsuba 3's path tracer ({m['variant']})\n"
                 "efficiency ratio, geometric mean over spp", fontsize=10)
    ax.grid(True, axis="y", alpha=0.3)
    from matplotlib.patches import Patch
    handles = [Patch(color=c, alpha=0.85, label=sc) for sc, c in zip(scenes, scene_colors)]
    handles += [Patch(color="0.6", label="bar: × Mitsuba, multijitter (its best)"),
                plt.Line2D([], [], marker="v", ms=7, color="0.6", mec="k", mew=0.6, ls="none",
                           label="▼: × Mitsuba, independent (its default)")]
    ax.legend(handles=handles, fontsize=7, loc="upper left", ncol=2)

    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m mcrt_study.summary_figure", description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=DEFAULT_PNG, help="the PNG to write (default: docs/images/summary.png)")
    p.add_argument("--print", action="store_true", help="also print the numbers the panels show")
    args = p.parse_args(argv)
    s = summary()
    if args.print:
        print_summary(s)
    draw(s, args.out)
    print(f"summary_figure: {args.out} ({args.out.stat().st_size // 1024} KB)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
