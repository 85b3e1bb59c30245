"""The many-light pbrt-v4 scenes: N = 10 ... 10^5 small emitters, and an emissive mesh of 12,800 triangles.

Used by bench/many_lights.py (the light selections' efficiency) and by the study's
many_lights family (scenes.py). Seeded and deterministic: the same arguments give the same
text, byte for byte.

  lights_N: a 20 x 20 diffuse floor (albedo 0.5) with 40 diffuse boxes on it, and N small
    emitters (triangles and quads, 0.3 / sqrt(N / 10) across within a factor 3, at heights
    0.05 to 3 over the floor, facing down within 32 degrees), their radiance log-uniform over
    three decades; the camera looks down at the floor from 12 units and sees only the lights'
    backs.
  mesh_light: the same floor and boxes beside a wavy emissive curtain of 2 x 80 x 80 = 12800
    triangles (radiance varying along it), and 20 small lights.

`scale` multiplies every emitter's radiance (1: the scenes as bench/many_lights.py writes
them); scene_power gives the power (pi x radiance x area, summed) a scale applies to.
"""

from __future__ import annotations

import math
import os
import random
from dataclasses import dataclass

import numpy as np

LIGHT_COUNTS = (10, 100, 1000, 10000, 100000)
MESH_SEED = 77
# The 12 triangles of a box's 6 faces, its 8 corners numbered 4 ix + 2 iy + iz.
BOX_INDICES = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4,
               1, 5, 7, 1, 7, 3]


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


def box_shape(points) -> str:
    """A box's trianglemesh from its 8 corners (BOX_INDICES' numbering)."""
    pts = ' '.join(f'{x:.5f} {y:.5f} {z:.5f}' for x, y, z in points)
    return f'Shape "trianglemesh" "point3 P" [ {pts} ] "integer indices" [ {" ".join(map(str, BOX_INDICES))} ]\n'


def boxes(rng):
    out = []
    for _ in range(40):
        cx, cz = rng.uniform(-8, 8), rng.uniform(-8, 8)
        sx, sy, sz = rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.5), rng.uniform(0.2, 1.0)
        out.append(box_shape([(cx + dx * sx, dy * sy, cz + dz * sz)
                              for dx in (-0.5, 0.5) for dy in (0, 1) for dz in (-0.5, 0.5)]))
    return ''.join(out)


@dataclass(frozen=True)
class Emitter:
    """One emissive trianglemesh: its points, triangles (index triples), radiance and how the file
    prints them (digits of the points and of L, ReverseOrientation)."""

    points: list
    triangles: list
    radiance: float
    point_format: str
    radiance_format: str
    reverse: bool = False
    triangle_separator: str = '  '  # between the index triples

    def power(self) -> float:
        """pi x radiance x area (one-sided)."""
        p = np.asarray(self.points, dtype=float)
        t = np.asarray(self.triangles, dtype=int)
        area = 0.5 * np.linalg.norm(np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]), axis=1).sum()
        return math.pi * self.radiance * float(area)

    def text(self, scale: float = 1.0) -> str:
        L = format(self.radiance * scale, self.radiance_format)
        ps = ' '.join(format(v, self.point_format) for p in self.points for v in p)
        idx = self.triangle_separator.join(' '.join(map(str, t)) for t in self.triangles)
        return ('AttributeBegin\n' + ('ReverseOrientation\n' if self.reverse else '') +
                f'AreaLightSource "diffuse" "rgb L" [ {L} {L} {L} ]\n'
                'Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n'
                f'Shape "trianglemesh" "point3 P" [ {ps} ] "integer indices" [ {idx} ]\nAttributeEnd\n')


def small_light_emitters(rng, n, spread=9.0) -> list[Emitter]:
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
            tris = [(0, 1, 2)]
        else:
            pts = [np.array(c) + size * (sx * t + sy * b) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            tris = [(0, 1, 2), (0, 2, 3)]
        # The winding makes the geometric normal cross(p1 - p0, p2 - p0) = b x t... orient it towards nrm.
        e = np.cross(pts[1] - pts[0], pts[2] - pts[0])
        out.append(Emitter(pts, tris, L, '.6f', '.5f', bool(np.dot(e, nrm) < 0)))
    return out


def small_lights(rng, n, spread=9.0):
    return ''.join(e.text() for e in small_light_emitters(rng, n, spread))


def mesh_light_emitters(rng, k=80) -> list[Emitter]:
    # A wavy curtain at x ~ -9 (y from 0.2 to 4, z over [-9, 9]) emitting
    # towards +x, in 8 strips of different radiance: 2 x 80 x 80 triangles.
    out = []
    strips = 8
    for s in range(strips):
        L = 10 ** rng.uniform(-0.5, 1.0)
        z0 = -9 + 18 * s / strips
        rows = k // strips
        pts, tris = [], []
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
                tris += [(a, b, c), (b, d, c)]  # normal +x
        out.append(Emitter(pts, tris, L, '.5f', '.4f', triangle_separator=' '))
    return out


def mesh_light(rng, k=80):
    return ''.join(e.text() for e in mesh_light_emitters(rng, k))


def scene_parts(name: str, res=(160, 120), spp: int = 16) -> tuple[str, list[Emitter]]:
    """A scene's text before its emitters (camera, floor, boxes) and its emitters in file order;
    name: lights_N (N in LIGHT_COUNTS) or mesh_light."""
    if name == 'mesh_light':
        rng = random.Random(MESH_SEED)
        head = header(res, spp, name) + boxes(rng)
        return head, mesh_light_emitters(rng) + small_light_emitters(rng, 20)
    n = int(name.removeprefix('lights_'))
    rng = random.Random(1000 + n)
    head = header(res, spp, name) + boxes(rng)
    return head, small_light_emitters(rng, n)


def scene_power(emitters: list[Emitter]) -> float:
    """Total power of the emitters at scale 1: sum of pi x radiance x area."""
    return sum(e.power() for e in emitters)


def scene_text(name: str, res=(160, 120), spp: int = 16, scale: float = 1.0) -> str:
    """The text of scene `name` (lights_N or mesh_light), every radiance times `scale`."""
    head, emitters = scene_parts(name, res, spp)
    return head + ''.join(e.text(scale) for e in emitters)


SCENE_NAMES = [f'lights_{n}' for n in LIGHT_COUNTS] + ['mesh_light']


def write_scenes(outdir, res=(160, 120)):
    os.makedirs(outdir, exist_ok=True)
    for name in SCENE_NAMES:
        with open(os.path.join(outdir, name + '.pbrt'), 'w') as f:
            f.write(scene_text(name, res))
    return list(SCENE_NAMES)
