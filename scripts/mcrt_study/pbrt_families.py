"""The study's generated pbrt-v4 families: one emissive triangle over a floor (tri_size,
tri_distance, tri_aspect, tri_grazing) and many lights (many_lights).

The JSON scene format has no triangles, so these members are pbrt-v4 files (mcrt reads both).
Their geometry is described in the comment block of scenes.py, beside the JSON families; this
module writes them, and reads the resolution and max depth of any pbrt-v4 file.
"""

from __future__ import annotations

import functools
import math
import re
import statistics

from .config import FamilyMember
from .many_lights_scenes import LIGHT_COUNTS, box_shape, scene_parts, scene_power
from .solid_angles import triangle_solid_angle, triangles_solid_angles

# The reference triangle: equilateral, edge 1, centroid 1 edge over the floor point (0, 0, 0),
# facing down, radiance 10; its radiance x area is every triangle member's.
TRI_EDGE = 1.0
TRI_AREA = math.sqrt(3.0) / 4.0 * TRI_EDGE ** 2
TRI_EMIT = 10.0
TRI_POWER = TRI_EMIT * TRI_AREA  # radiance x area of every triangle member (power / pi)
TRI_HEIGHT = 1.0 * TRI_EDGE
TRI_FLOOR = 400.0 * TRI_EDGE  # side of the square floor, centred under the triangle
TRI_ALBEDO = 0.73
# A cube (side 0.5 edge) on the floor beside the light: shadows, and light between it and the floor.
TRI_BOX = {"centre": (-2.0, -2.0), "side": 0.5}
TRI_CAMERA = {"distance": 10.0, "elevation_deg": 45.0, "azimuth": (-1.0, 1.0), "fov": 40.0}
TRI_RESOLUTION = (600, 600)
TRI_MAX_DEPTH = 50
TRI_SIZE_RATIOS = [(1 / 16, "1of16"), (1 / 4, "1of4"), (1.0, "x1"), (2.0, "x2"), (4.0, "x4"), (8.0, "x8")]
TRI_DISTANCE_RATIOS = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0]
TRI_ASPECTS = [1.0, 10.0, 100.0, 1000.0, 10000.0]
# tri_grazing: the cosine between the triangle's normal and straight down (its tilt about the
# x axis, towards -z, is acos of it).
TRI_GRAZING_COSINES = [1.0, 0.5, 0.1, 0.03, 0.01, 0.001]

# many_lights: the scenes of many_lights_scenes.py at this resolution, their radiance scaled so
# that every member emits MANY_LIGHTS_POWER; light solid angles from the floor point the camera
# looks at.
MANY_LIGHTS_POWER = 100.0
MANY_LIGHTS_RESOLUTION = (320, 240)
MANY_LIGHTS_POINT = (0.0, 0.0, 0.5)
MANY_LIGHTS_MESH = "many_lights_mesh"


def _num(x: float) -> str:
    """A number as written to a pbrt file: rounded to 6 decimals, integral values without a point."""
    r = round(float(x), 6)
    return str(int(r)) if r == int(r) else repr(r)


def _pts(points) -> str:
    return "  ".join(" ".join(_num(v) for v in p) for p in points)


def _round(points) -> list[tuple[float, float, float]]:
    return [tuple(round(float(v), 6) + 0.0 for v in p) for p in points]


def tri_camera() -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """The triangle families' eye and look-at point: the floor point under the light, from 10 edges
    away, 45 degrees up, from the (-x, +z) side (behind a tilted triangle, which faces -z: the
    camera sees the backs of every member's triangle, not its emission)."""
    c = TRI_CAMERA
    el = math.radians(c["elevation_deg"])
    ax, az = c["azimuth"]
    norm = math.hypot(ax, az)
    horiz = c["distance"] * math.cos(el)
    eye = (horiz * ax / norm, c["distance"] * math.sin(el), horiz * az / norm)
    return tuple(round(v, 6) + 0.0 for v in eye), (0.0, 0.0, 0.0)


def triangle_corners(base: float, height: float, centroid_y: float, cos_tilt: float = 1.0) -> list[tuple]:
    """An isosceles triangle of that base (along x) and height, centroid at (0, centroid_y, 0),
    facing down tilted towards -z (normal (0, -cos, -sin)); corners in the order whose
    cross(p1 - p0, p2 - p0) is the normal (the emitting side), rounded as in the file."""
    sin_tilt = math.sqrt(max(0.0, 1.0 - cos_tilt * cos_tilt))
    u = (1.0, 0.0, 0.0)
    v = (0.0, -sin_tilt, cos_tilt)  # normal x u: (u, v, normal) right-handed
    local = [(-base / 2, -height / 3), (base / 2, -height / 3), (0.0, 2 * height / 3)]
    return _round([(a * u[0] + b * v[0], centroid_y + a * u[1] + b * v[1], a * u[2] + b * v[2]) for a, b in local])


def triangle_area(corners) -> float:
    """Area of a triangle from its corners."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = corners
    e1, e2 = (bx - ax, by - ay, bz - az), (cx - ax, cy - ay, cz - az)
    n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
    return 0.5 * math.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)


def triangle_scene(name: str, corners) -> str:
    """A triangle member's pbrt-v4 file: camera, floor, cube, and the triangle as a pure emitter
    whose radiance x area is TRI_POWER."""
    eye, at = tri_camera()
    emit = _num(TRI_POWER / triangle_area(corners))
    half = TRI_FLOOR / 2
    floor = [(-half, 0, -half), (half, 0, -half), (half, 0, half), (-half, 0, half)]
    (bx, bz), side = TRI_BOX["centre"], TRI_BOX["side"]
    cube = [(bx + dx * side, dy * side, bz + dz * side) for dx in (-0.5, 0.5) for dy in (0, 1) for dz in (-0.5, 0.5)]
    albedo = " ".join([_num(TRI_ALBEDO)] * 3)
    return (
        f"# {name}: a generated scene of the mcrt study (scripts/mcrt_study/pbrt_families.py)\n"
        f"LookAt {_pts([eye])}  {_pts([at])}  0 1 0\n"
        f'Camera "perspective" "float fov" [ {_num(TRI_CAMERA["fov"])} ]\n'
        f'Film "rgb" "integer xresolution" [ {TRI_RESOLUTION[0]} ] "integer yresolution" [ {TRI_RESOLUTION[1]} ] '
        f'"string filename" [ "{name}.exr" ]\n'
        'PixelFilter "box"\n'
        'Sampler "zsobol" "integer pixelsamples" [ 100 ]\n'
        f'Integrator "path" "integer maxdepth" [ {TRI_MAX_DEPTH} ]\n'
        "WorldBegin\n"
        f'Material "diffuse" "rgb reflectance" [ {albedo} ]\n'
        f'Shape "trianglemesh" "point3 P" [ {_pts(floor)} ] "integer indices" [ 0 1 2  0 2 3 ]\n'
        + box_shape(cube) +
        "AttributeBegin\n"
        f'AreaLightSource "diffuse" "rgb L" [ {emit} {emit} {emit} ]\n'
        'Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n'
        f'Shape "trianglemesh" "point3 P" [ {_pts(corners)} ] "integer indices" [ 0 1 2 ]\n'
        "AttributeEnd\n")


def _triangle_member(name: str, family: str, param: float, corners) -> FamilyMember:
    return FamilyMember(name, family, param, triangle_scene(name, corners),
                        triangle_solid_angle((0.0, 0.0, 0.0), *corners))


def _equilateral(area: float) -> tuple[float, float]:
    """Base and height of the equilateral triangle of that area."""
    edge = math.sqrt(4.0 * area / math.sqrt(3.0))
    return edge, edge * math.sqrt(3.0) / 2.0


def tri_size_family() -> list[FamilyMember]:
    """The equilateral triangle at 1/16 ... 8 times the reference's area, one edge over the floor."""
    members = []
    for ratio, tag in TRI_SIZE_RATIOS:
        base, height = _equilateral(TRI_AREA * ratio)
        members.append(_triangle_member(f"tri_size_{tag}", "tri_size", ratio,
                                        triangle_corners(base, height, TRI_HEIGHT)))
    return members


def tri_distance_family() -> list[FamilyMember]:
    """The reference triangle at heights h = 0.01 ... 10 edges over the floor."""
    base, height = _equilateral(TRI_AREA)
    return [_triangle_member(f"tri_distance_h{ratio:g}", "tri_distance", ratio,
                             triangle_corners(base, height, ratio * TRI_EDGE))
            for ratio in TRI_DISTANCE_RATIOS]


def tri_aspect_family() -> list[FamilyMember]:
    """Slivers of the reference's area: base sqrt(k) times the equilateral's, height 1 / sqrt(k)
    times, k = 1 ... 10^4 (base / height k times the equilateral's)."""
    base, height = _equilateral(TRI_AREA)
    return [_triangle_member(f"tri_aspect_a{k:g}", "tri_aspect", k,
                             triangle_corners(base * math.sqrt(k), height / math.sqrt(k), TRI_HEIGHT))
            for k in TRI_ASPECTS]


def tri_grazing_family() -> list[FamilyMember]:
    """The reference triangle one edge over the floor, tilted about the x axis until its normal
    makes cos = 1 ... 0.001 with straight down: its plane nearly through the floor points under it."""
    base, height = _equilateral(TRI_AREA)
    return [_triangle_member(f"tri_grazing_c{c:g}", "tri_grazing", c,
                             triangle_corners(base, height, TRI_HEIGHT, c))
            for c in TRI_GRAZING_COSINES]


@functools.lru_cache(maxsize=None)
def _many_lights_scene(source: str) -> tuple[str, float]:
    """A many_lights member's text and light solid angle (made once per process): the scene
    `source` of many_lights_scenes.py (lights_N or mesh_light) at MANY_LIGHTS_POWER."""
    import numpy as np

    head, emitters = scene_parts(source, MANY_LIGHTS_RESOLUTION)
    scale = MANY_LIGHTS_POWER / scene_power(emitters)
    text = head + "".join(e.text(scale) for e in emitters)
    triangles = np.concatenate([np.asarray(e.points, float)[np.asarray(e.triangles, int)] for e in emitters])
    return text, float(statistics.median(triangles_solid_angles(MANY_LIGHTS_POINT, triangles)))


def _many_lights_member(name: str, param: float, source: str) -> FamilyMember:
    return FamilyMember(name, "many_lights", param, lambda: _many_lights_scene(source)[0],
                        lambda: _many_lights_scene(source)[1])


def many_lights_family() -> list[FamilyMember]:
    """N = 10 ... 10^5 small emitters (parameter N), and the emissive mesh of 12,800 triangles
    beside 20 small lights (parameter 12,800)."""
    members = [_many_lights_member(f"many_lights_n{n}", n, f"lights_{n}") for n in LIGHT_COUNTS]
    members.append(_many_lights_member(MANY_LIGHTS_MESH, MESH_TRIANGLES, "mesh_light"))
    return members


MESH_TRIANGLES = 12800


PBRT_FAMILIES = {"tri_size": tri_size_family, "tri_distance": tri_distance_family,
                 "tri_aspect": tri_aspect_family, "tri_grazing": tri_grazing_family,
                 "many_lights": many_lights_family}


def _directive_integer(text: str, directive: str, name: str) -> int | None:
    """The first `"integer NAME" [ V ]` (brackets optional) of a directive's line."""
    for line in text.splitlines():
        if line.lstrip().startswith(directive):
            m = re.search(r'"integer\s+' + name + r'"\s*\[?\s*(-?\d+)', line)
            if m:
                return int(m.group(1))
    return None


def pbrt_file_settings(text: str) -> tuple[int, int, int]:
    """Width, height and max depth of a pbrt-v4 file, as mcrt reads them: the Film's
    xresolution and yresolution, the Integrator's maxdepth (pbrt-v4's defaults 1280, 720, 5)."""
    width = _directive_integer(text, "Film", "xresolution")
    height = _directive_integer(text, "Film", "yresolution")
    depth = _directive_integer(text, "Integrator", "maxdepth")
    return (1280 if width is None else width, 720 if height is None else height, 5 if depth is None else depth)
