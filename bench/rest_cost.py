#!/usr/bin/env python3
"""The constants of c_rest's model (include/mcrt/render/rest_cost.hpp).

Renders each scene with `--light-sampling auto` (nee, Sobol, 8 spp) REPS
times, direct and global light, and reads from the stats the pilot's
measured time per light sample and its counted rays and paths per
light sample. The scenes: the thesis's Cornell scenes, the study's size and
distance families (100 x 100), and four of them with 12 further primitives
of each type out of view (150 x 150), so that each type's test cost is seen
apart. The fastest run's time, less the light's cheapest strategy's
modelled cost, is fitted by least squares to
  c_ray (R - P) + R sum_t n_t c_t + c_sample + c_light(light shape)
and the fit, its residuals and the model's constants (as the header has
them) are printed.

Usage: .venv/bin/python bench/rest_cost.py [--reps 5] [--mcrt build/mcrt]
"""
import argparse
import collections
import copy
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from mcrt_study import scenes as families  # noqa: E402

AXIS = ("xz_rect", "yz_rect", "xy_rect", "xz_rect_sa", "yz_rect_sa", "xy_rect_sa")
TYPES = ("axis", "rect", "ellipse", "sphere", "box")
# The header's constants: c_ray, c_t per type, c_sample, c_light (ellipse, sphere).
HEADER = dict(ray=49.9, axis=1.45, rect=1.33, ellipse=1.31, sphere=1.75, box=3.52, sample=22.5,
              ellipse_light=32.7, sphere_light=6.0)
CHEAPEST = {"rect": 17.0, "ellipse": 31.0, "sphere": 54.0}  # auto_costs: the cheapest strategy, ns


def extra(kind: str, i: int) -> dict:
    y = -1e5 - 1000 * i  # far below every scene: tested by every ray, met by none
    return {"xz_rect": {"type": "xz_rect", "x0": 0, "x1": 10, "z0": 0, "z1": 10, "k": y},
            "rect": {"type": "rect", "corner": [0, y, 0], "edge1": [10, 0, 0], "edge2": [0, 5, 5]},
            "ellipse": {"type": "ellipse", "center": [0, y, 0], "axis1": [10, 0, 0], "axis2": [0, 5, 5]},
            "sphere": {"type": "sphere", "center": [0, y, 0], "radius": 10},
            "box": {"type": "box", "min": [0, y, 0], "max": [10, y + 10, 10], "rotate_y": 15}}[kind] | {"material": "white"}


def light_shape(scene: dict) -> str:
    emit = {k for k, m in scene["materials"].items() if m["type"] == "diffuse_light"}
    for o in scene["objects"]:
        if o["material"] in emit:
            t = o["type"]
            return "sphere" if t == "sphere" else "ellipse" if t.startswith("ellipse") else "rect"
    raise ValueError("no light")


def counts(scene: dict) -> dict:
    c = collections.Counter(o["type"] for o in scene["objects"])
    return {"axis": sum(c[t] for t in AXIS), "rect": c["rect"] + c["rect_sa"],
            "ellipse": c["ellipse"] + c["ellipse_sa"], "sphere": c["sphere"], "box": c["box"]}


def settings() -> list[tuple[str, dict, int]]:
    out = []
    for name in ("cornell_rect", "cornell_rect_large", "cornell_disk", "cornell_disk_large", "cornell_sphere",
                 "cornell_two_lights"):
        out.append((name, json.loads((ROOT / "scenes" / f"{name}.json").read_text()), 300))
    members = [m for fam in (families.size_rect_family(), families.size_disk_family(), families.size_sphere_family(),
                             families.distance_family()) for m in fam]
    for m in members:
        out.append((m.name, m.scene, 100))
    for base in ("cornell_rect", "cornell_disk", "cornell_sphere", "distance_h1"):
        scene = next(s for n, s, _ in out if n == base)
        for kind in ("xz_rect", "rect", "ellipse", "sphere", "box"):
            s = copy.deepcopy(scene)
            s["objects"] += [extra(kind, i) for i in range(12)]
            out.append((f"{base}+12 {kind}", s, 150))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"))
    a = ap.parse_args()
    rows, names = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene, size in settings():
            path = Path(tmp) / "scene.json"
            path.write_text(json.dumps(scene))
            for depth in (1, 50):
                runs = []
                for rep in range(a.reps):
                    stats = Path(tmp) / "stats.json"
                    subprocess.run([a.mcrt, "render", str(path), "-o", str(Path(tmp) / "o.exr"), "--spp", "8",
                                    "--width", str(size), "--height", str(size), "--max-depth", str(depth),
                                    "--integrator", "nee", "--sampler", "sobol", "--seed", str(rep + 1),
                                    "--light-sampling", "auto", "--quiet", "--stats", str(stats)], check=True)
                    runs.append(json.loads(stats.read_text()))
                fastest = min(runs, key=lambda j: j["auto_pilot_ns_per_light_sample"])
                r, p = fastest["auto_pilot_rays_per_light_sample"], fastest["auto_pilot_paths_per_light_sample"]
                n, shape = counts(scene), light_shape(scene)
                x = [r - p] + [r * n[t] for t in TYPES] + [1.0, shape == "ellipse", shape == "sphere"]
                rows.append((x, fastest["auto_pilot_ns_per_light_sample"] - CHEAPEST[shape]))
                names.append(f"{name} depth {depth}")
    X = np.array([x for x, _ in rows], dtype=float)
    y = np.array([t for _, t in rows])
    coef = np.linalg.lstsq(X, y, rcond=None)[0]
    labels = ["ray"] + list(TYPES) + ["sample", "ellipse_light", "sphere_light"]
    header = np.array([HEADER[k] for k in labels])
    print("| constant | fit (ns) | header (ns) |\n|---|---:|---:|")
    for k, c, h in zip(labels, coef, header):
        print(f"| {k} | {c:.2f} | {h:.2f} |")
    for label, model in (("fit", X @ coef), ("header", X @ header)):
        rel = model / y - 1
        worst = int(np.argmax(np.abs(rel)))
        print(f"{label}: {len(y)} settings, residual rms {np.sqrt(np.mean(rel ** 2)):.1%}, "
              f"largest {rel[worst]:+.1%} ({names[worst]})")


if __name__ == "__main__":
    main()
