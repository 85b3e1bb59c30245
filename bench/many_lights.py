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

The scenes (seeded, deterministic):
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
import math
import os
import random
import subprocess
import sys
import time

import numpy as np


def header(res, spp, name):
    return (
        'LookAt 0 12 -9  0 0 0.5  0 1 0\n'
        'Camera "perspective" "float fov" [ 45 ]\n'
        f'Film "rgb" "integer xresolution" [ {res[0]} ] "integer yresolution" [ {res[1]} ] '
        f'"string filename" [ "{name}.exr" ]\n'
        'PixelFilter "box"\n'
        f'Sampler "zsobol" "integer pixelsamples" [ {spp} ]\n'
        'Integrator "path" "integer maxdepth" [ 3 ]\n'
        'WorldBegin\n'
        'Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]\n'
        'Shape "trianglemesh" "point3 P" [ -10 0 -10  10 0 -10  10 0 10  -10 0 10 ] '
        '"integer indices" [ 0 1 2  0 2 3 ]\n')


def boxes(rng):
    out = []
    for _ in range(40):
        cx, cz = rng.uniform(-8, 8), rng.uniform(-8, 8)
        sx, sy, sz = rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.5), rng.uniform(0.2, 1.0)
        p = [(cx + dx * sx, dy * sy, cz + dz * sz) for dx in (-0.5, 0.5) for dy in (0, 1) for dz in (-0.5, 0.5)]
        # Vertex index = 4 ix + 2 iy + iz; the 12 triangles of the 6 faces.
        idx = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
        pts = ' '.join(f'{x:.5f} {y:.5f} {z:.5f}' for x, y, z in p)
        out.append(f'Shape "trianglemesh" "point3 P" [ {pts} ] "integer indices" [ {" ".join(map(str, idx))} ]\n')
    return ''.join(out)


def small_lights(rng, n, spread=9.0):
    out = []
    for _ in range(n):
        c = (rng.uniform(-spread, spread), rng.uniform(0.05, 3.0), rng.uniform(-spread, spread))
        # Sizes shrink as 1 / sqrt(N): the lights' total area (and power)
        # is the same for every N, and the camera sees few of them.
        size = rng.uniform(0.5, 1.5) * 0.3 / math.sqrt(max(n, 10) / 10)
        # A normal within 32 degrees of straight down: the camera above sees
        # only the lights' backs, so that the image's error is the floor's
        # (the light selections'), not the pixels' coverage of bright
        # emitters.
        z = -rng.uniform(0.85, 1.0)
        phi = rng.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - z * z)
        nrm = np.array([r * math.cos(phi), z, r * math.sin(phi)])
        t = np.cross(nrm, [0.3, 0.1, 0.9])
        t /= np.linalg.norm(t)
        b = np.cross(nrm, t)
        L = 10 ** rng.uniform(-1, 2)
        if rng.random() < 0.5:
            pts = [np.array(c) + size * (math.cos(a) * t + math.sin(a) * b) for a in (0.0, 2.1, 4.2)]
            idx = '0 1 2'
        else:
            pts = [np.array(c) + size * (sx * t + sy * b) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            idx = '0 1 2  0 2 3'
        # The winding makes the geometric normal cross(p1 - p0, p2 - p0) = b x t... orient it towards nrm.
        e = np.cross(pts[1] - pts[0], pts[2] - pts[0])
        flip = 'ReverseOrientation\n' if np.dot(e, nrm) < 0 else ''
        ps = ' '.join(f'{v:.6f}' for p in pts for v in p)
        out.append('AttributeBegin\n' + flip +
                   f'AreaLightSource "diffuse" "rgb L" [ {L:.5f} {L:.5f} {L:.5f} ]\n'
                   'Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n'
                   f'Shape "trianglemesh" "point3 P" [ {ps} ] "integer indices" [ {idx} ]\nAttributeEnd\n')
    return ''.join(out)


def mesh_light(rng, k=80):
    # A wavy curtain at x ~ -9 (y from 0.2 to 4, z over [-9, 9]) emitting
    # towards +x, in 8 strips of different radiance: 2 x 80 x 80 triangles.
    out = []
    strips = 8
    for s in range(strips):
        L = 10 ** rng.uniform(-0.5, 1.0)
        z0 = -9 + 18 * s / strips
        rows = k // strips
        pts, idx = [], []
        for j in range(rows + 1):
            for i in range(k + 1):
                y = 0.2 + 3.8 * i / k
                z = z0 + (18 / strips) * j / rows
                x = -9 + 0.5 * math.sin(1.3 * y) * math.cos(0.9 * z)
                pts.append((x, y, z))
        for j in range(rows):
            for i in range(k):
                a = j * (k + 1) + i
                b, c, d = a + 1, a + k + 1, a + k + 2
                idx += [a, b, c, b, d, c]  # normal +x
        ps = ' '.join(f'{x:.5f} {y:.5f} {z:.5f}' for x, y, z in pts)
        out.append('AttributeBegin\n'
                   f'AreaLightSource "diffuse" "rgb L" [ {L:.4f} {L:.4f} {L:.4f} ]\n'
                   'Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n'
                   f'Shape "trianglemesh" "point3 P" [ {ps} ] "integer indices" [ {" ".join(map(str, idx))} ]\n'
                   'AttributeEnd\n')
    return ''.join(out)


def write_scenes(outdir, res=(160, 120)):
    os.makedirs(outdir, exist_ok=True)
    names = []
    for n in (10, 100, 1000, 10000, 100000):
        rng = random.Random(1000 + n)
        name = f'lights_{n}'
        with open(os.path.join(outdir, name + '.pbrt'), 'w') as f:
            f.write(header(res, 16, name) + boxes(rng) + small_lights(rng, n))
        names.append(name)
    rng = random.Random(77)
    with open(os.path.join(outdir, 'mesh_light.pbrt'), 'w') as f:
        f.write(header(res, 16, 'mesh_light') + boxes(rng) + mesh_light(rng) + small_lights(rng, 20))
    names.append('mesh_light')
    return names


def read_exr(path):
    # The study package's reader (mcrt's EXR files: float RGB, ZIP).
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'scripts'))
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
