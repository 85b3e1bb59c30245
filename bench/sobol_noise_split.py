#!/usr/bin/env python3
"""What the image's sample generator leaves of a light's noise and of the rest.

For each scene and spp: renders with area and with projected-solid-angle
sampling (every light), with independent and with Sobol samples, SEEDS
seeds each, and from the spread of each pixel over the seeds the image's
variance per pixel sample (seed variance x spp, mean over pixels and
channels). Projected solid angle has no noise of its own for an unoccluded
light on a diffuse receiver, so

    light = V(area) - V(projected)     rest = V(projected)

and kappa_l = light(sobol) / light(independent), kappa_R = rest(sobol) /
rest(independent): how much the sequence removes of each. `auto`'s rule
(docs/auto.md) is modelled on independent samples; where kappa_l is far
below kappa_R the light's noise it would remove is mostly gone already.
No reference image is needed. Also printed: the share of the rest held by
the noisiest 1 % of pixels (edges in view).

Usage: bench/sobol_noise_split.py SCENE... [--spp 8 32] [--seeds 24]
       [--size 128] [--integrator mis] [--max-depth 1] [--mcrt build/mcrt]
SCENE: a scene file, or a member of the study's generated families
(scripts/mcrt_study/scenes.py: tri_distance_h10, size_rect_x4, ...).
"""
import argparse
import os
from pathlib import Path
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'scripts'))
from mcrt_study.exr import read_rgb  # noqa: E402
from mcrt_study.scenes import family_member, write_member  # noqa: E402


def per_sample_variance(args, scene, sampler, strategy, spp, out):
    images = []
    for seed in range(1, args.seeds + 1):
        subprocess.run([args.mcrt, 'render', scene, '-o', out, '--quiet', '--spp', str(spp),
                        '--width', str(args.size), '--height', str(args.size),
                        '--max-depth', str(args.max_depth), '--integrator', args.integrator,
                        '--sampler', sampler, '--light-sampling', strategy, '--seed', str(seed),
                        '--threads', str(args.threads)], check=True)
        images.append(read_rgb(out).astype(np.float64))
    v = np.array(images).var(axis=0, ddof=1).mean(axis=2) * spp
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('scenes', nargs='+')
    ap.add_argument('--spp', type=int, nargs='+', default=[8, 32])
    ap.add_argument('--seeds', type=int, default=24)
    ap.add_argument('--size', type=int, default=128)
    ap.add_argument('--integrator', default='mis')
    ap.add_argument('--max-depth', type=int, default=1)
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--mcrt', default='build/mcrt')
    args = ap.parse_args()
    print('| scene | spp | light, independent | rest, independent | light, Sobol | rest, Sobol '
          '| kappa_l | kappa_R | rest in the noisiest 1 % of pixels (Sobol) |')
    print('|---|---:|---:|---:|---:|---:|---:|---:|---:|')
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, 'x.exr')
        for scene in args.scenes:
            if not os.path.isfile(scene):
                member = family_member(scene)
                if member is None:
                    sys.exit(f'{scene}: no such file or generated family member')
                scene = str(write_member(member, Path(tmp)))
            for spp in args.spp:
                v = {(s, t): per_sample_variance(args, scene, s, t, spp, out)
                     for s in ('independent', 'sobol') for t in ('area', 'projected-solid-angle')}
                rest_i, rest_s = v['independent', 'projected-solid-angle'], v['sobol', 'projected-solid-angle']
                light_i = v['independent', 'area'].mean() - rest_i.mean()
                light_s = v['sobol', 'area'].mean() - rest_s.mean()
                top = np.sort(rest_s.ravel())[-max(1, rest_s.size // 100):].sum() / rest_s.sum()
                name = os.path.splitext(os.path.basename(scene))[0]
                print(f'| {name} | {spp} | {light_i:.3g} | {rest_i.mean():.3g} | {light_s:.3g} | '
                      f'{rest_s.mean():.3g} | {light_s / light_i:.3g} | {rest_s.mean() / rest_i.mean():.3g} '
                      f'| {top:.2f} |', flush=True)


if __name__ == '__main__':
    main()
