#!/usr/bin/env python3
"""Many lights: the light selections' efficiency 1 / (MSE x time) on pbrt-v4
scenes of N = 10 ... 10^5 emitters and on one emissive mesh of >= 10^4
triangles.

Run with the study's environment (.venv: numpy):
  .venv/bin/python bench/many_lights.py scenes  OUTDIR          # writes the scene files
  .venv/bin/python bench/many_lights.py run     OUTDIR [--mcrt build/mcrt] [--spp 16]
                                       [--ref-spp 1024] [--seeds 3]
                                       [--select power,bvh,pbrt-bvh] [--only NAME]

`run` renders each scene once at --ref-spp with bvh (the reference: its own
noise is subtracted from each MSE, see below), then each selection at --spp
for --seeds seeds, and prints a table (markdown) of time, MSE and efficiency
relative to power and to pbrt-bvh. The MSE of an image against the
reference counts the reference's own variance too; with independent seeds,
E[MSE] = var_image + var_ref, and var_ref = var_image(spp) x spp / ref_spp
for the reference's selection; the table reports MSE - var_ref estimated
that way, per selection (each selection's variance scales the same way).

The scenes (seeded, deterministic; made by scripts/mcrt_study/many_lights_scenes.py,
which the study's many_lights family uses too):
  lights_N: a 20 x 20 diffuse floor (albedo 0.5) with 40 diffuse boxes on
    it, and N small emitters (triangles and quads, 0.3 / sqrt(N / 10) across
    within a factor 3, at
    heights 0.05 to 3 over the floor, facing down within 32 degrees), their
    radiance log-uniform over three decades; the camera looks down at the
    floor from 12 units and sees only the lights' backs.
  mesh_light: the same floor and boxes beside a wavy emissive curtain of
    2 x 80 x 80 = 12800 triangles (radiance varying along it), and 20 small
    lights.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

# The scenes' generator is the study package's (the study's many_lights family renders them too).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'scripts'))
from mcrt_study.many_lights_scenes import write_scenes  # noqa: E402


def read_exr(path):
    # The study package's reader (mcrt's EXR files: float RGB, ZIP).
    from mcrt_study.exr import read_rgb  # noqa: PLC0415
    return np.asarray(read_rgb(path), dtype=np.float64)


def render(mcrt, scene, out, spp, seed, select, threads, max_depth=0):
    stats = out + '.json'
    cmd = [mcrt, 'render', scene, '-o', out, '--spp', str(spp), '--seed', str(seed), '--light-select', select,
           '--quiet', '--stats', stats]
    if max_depth:
        cmd += ['--max-depth', str(max_depth)]
    if threads:
        cmd += ['--threads', str(threads)]
    subprocess.run(cmd, check=True)
    with open(stats) as f:
        return json.load(f)['render_seconds']


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('what', choices=['scenes', 'run'])
    ap.add_argument('outdir')
    ap.add_argument('--mcrt', default='build/mcrt')
    ap.add_argument('--spp', type=int, default=16)
    ap.add_argument('--ref-spp', type=int, default=1024)
    ap.add_argument('--seeds', type=int, default=3)
    ap.add_argument('--select', default='power,pbrt-bvh,bvh')
    ap.add_argument('--only', default='')
    ap.add_argument('--threads', type=int, default=0)
    ap.add_argument('--max-depth', type=int, default=0, help='override the files\' maxdepth (1: direct light)')
    a = ap.parse_args()
    names = write_scenes(a.outdir)
    if a.what == 'scenes':
        print('\n'.join(names))
        return
    selects = a.select.split(',')
    rows = []
    for name in names:
        if a.only and name not in a.only.split(','):
            continue
        scene = os.path.join(a.outdir, name + '.pbrt')
        ref_path = os.path.join(a.outdir, f'{name}_d{a.max_depth}_ref{a.ref_spp}.exr')
        if not os.path.exists(ref_path):
            t = render(a.mcrt, scene, ref_path, a.ref_spp, 1000, 'bvh', a.threads, a.max_depth)
            print(f'{name}: reference {a.ref_spp} spp in {t:.1f} s', file=sys.stderr)
        ref = read_exr(ref_path)
        res = {}
        # Seeds interleaved across selections (the machine drifts).
        per = {s: {'t': [], 'mse': []} for s in selects}
        for seed in range(a.seeds):
            for s in selects:
                out = os.path.join(a.outdir, f'{name}_d{a.max_depth}_{s}_{seed}.exr')
                t = render(a.mcrt, scene, out, a.spp, seed + 1, s, a.threads, a.max_depth)
                img = read_exr(out)
                per[s]['t'].append(t)
                per[s]['mse'].append(float(np.mean((img - ref) ** 2)))
        ref_share = a.spp / a.ref_spp  # var_ref ~ var_bvh(spp) * spp / ref_spp
        raw_bvh = np.mean(per['bvh']['mse']) if 'bvh' in per else None
        for s in selects:
            t = float(np.mean(per[s]['t']))
            mse_raw = float(np.mean(per[s]['mse']))
            # MSE against the truth: subtract the reference's variance,
            # estimated from bvh's at spp: var_ref = var_bvh * spp / ref_spp,
            # and var_bvh = mse_raw_bvh / (1 + spp / ref_spp).
            var_ref = raw_bvh / (1 + ref_share) * ref_share if raw_bvh is not None else 0.0
            mse = max(mse_raw - var_ref, 1e-30)
            res[s] = {'seconds': t, 'mse': mse, 'efficiency': 1.0 / (mse * t)}
        rows.append((name, res))
        line = f'| {name} | ' + ' | '.join(f'{res[s]["seconds"]:.2f} s, {res[s]["mse"]:.3g}' for s in selects)
        print(line, file=sys.stderr)
    print('| scene | ' + ' | '.join(f'{s}: time, MSE' for s in selects) + ' | ' +
          ' | '.join(f'eff. {s} / power' for s in selects if s != 'power') +
          (' | bvh / pbrt-bvh |' if 'bvh' in selects and 'pbrt-bvh' in selects else ' |'))
    print('|---|' + '---:|' * (len(selects) + len([s for s in selects if s != 'power']) +
                              (1 if 'bvh' in selects and 'pbrt-bvh' in selects else 0)))
    for name, res in rows:
        cells = [f'{res[s]["seconds"]:.2f} s, {res[s]["mse"]:.3g}' for s in selects]
        if 'power' in res:
            cells += [f'{res[s]["efficiency"] / res["power"]["efficiency"]:.2f}' for s in selects if s != 'power']
        if 'bvh' in res and 'pbrt-bvh' in res:
            cells.append(f'{res["bvh"]["efficiency"] / res["pbrt-bvh"]["efficiency"]:.2f}')
        print(f'| {name} | ' + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
