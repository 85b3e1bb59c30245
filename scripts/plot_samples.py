#!/usr/bin/env python3
"""Where each light-sampling strategy puts its samples.

Runs ``mcrt samples`` for every strategy and observer given and draws, per
(observer, strategy), two panels: the points reached on the light (in the
light's own plane, or for a sphere as seen from the observer), and the
unit-square points the samples came from (the inverse image of the light
points), both coloured by the density per unit solid angle returned with the
sample. Used for the README's figure::

    .venv/bin/python scripts/plot_samples.py scenes/cornell_rect.json --light 0 \\
        --observer near 278,1,279 0,1,0 --observer far 20,300,540 1,0,0 \\
        --strategies area solid-angle -o docs/samples_rect.png

Options: ``--n`` samples per panel (default 1500), ``--seed``, ``--mcrt``.
"""
from __future__ import annotations

import argparse
import csv
import io
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPO_ROOT = Path(__file__).resolve().parent.parent


def run_samples(mcrt: Path, scene: Path, light: int, origin: str, normal: str, strategy: str, n: int,
                seed: int) -> np.ndarray:
    """The CSV of ``mcrt samples`` as an array of rows u1,u2,dx,dy,dz,px,py,pz,pdf."""
    cmd = [str(mcrt), "samples", str(scene), "--light", str(light), "--from", origin, "--normal", normal,
           "--light-sampling", strategy, "--n", str(n), "--seed", str(seed)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"plot_samples.py: {' '.join(cmd)}: {proc.stderr.strip()}")
    rows = list(csv.reader(io.StringIO(proc.stdout)))
    return np.array([[float(x) for x in r] for r in rows[1:]])


def plane_coordinates(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """2-D coordinates of points lying (nearly) on a plane: its two principal axes."""
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return centred @ vt[0], centred @ vt[1]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", type=Path)
    p.add_argument("--light", type=int, default=0)
    p.add_argument("--observer", nargs=3, action="append", metavar=("NAME", "X,Y,Z", "NX,NY,NZ"), required=True,
                   help="a named receiving point and its surface normal (repeatable)")
    p.add_argument("--strategies", nargs="+", default=["area", "solid-angle"])
    p.add_argument("--n", type=int, default=1500)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--mcrt", type=Path, default=REPO_ROOT / "build" / "mcrt")
    p.add_argument("-o", "--output", type=Path, required=True)
    args = p.parse_args(argv)

    rows, cols = len(args.observer), 2 * len(args.strategies)
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols, 2.7 * rows), squeeze=False)
    for i, (name, origin, normal) in enumerate(args.observer):
        for j, strategy in enumerate(args.strategies):
            data = run_samples(args.mcrt, args.scene, args.light, origin, normal, strategy, args.n, args.seed)
            ok = data[:, 8] > 0
            pdf = data[ok, 8]
            colour = np.log10(pdf / np.median(pdf)) if ok.any() else None
            ax_light, ax_square = axes[i][2 * j], axes[i][2 * j + 1]
            if ok.sum() >= 3:
                x, y = plane_coordinates(data[ok, 5:8])
                ax_light.scatter(x, y, s=1.5, c=colour, cmap="viridis", vmin=-1, vmax=1, linewidths=0)
            ax_light.set_aspect("equal", adjustable="datalim")
            ax_square.scatter(data[ok, 0], data[ok, 1], s=1.5, c=colour, cmap="viridis", vmin=-1, vmax=1,
                              linewidths=0)
            ax_square.scatter(data[~ok, 0], data[~ok, 1], s=1.5, c="lightgrey", linewidths=0)
            ax_square.set_xlim(0, 1)
            ax_square.set_ylim(0, 1)
            ax_square.set_aspect("equal")
            ax_light.set_title(f"{name}: {strategy}\non the light", fontsize=8)
            ax_square.set_title(f"{name}: {strategy}\nunit square", fontsize=8)
            for ax in (ax_light, ax_square):
                ax.set_xticks([])
                ax.set_yticks([])
    fig.suptitle(f"{args.scene.name}, light {args.light}: {args.n} samples per panel, colour log10(pdf / median)",
                 fontsize=9)
    fig.tight_layout()
    args.output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.output, dpi=110)
    print(f"wrote {args.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
