"""The scenes of the study: scene files by name or path, generated scene families, their size and depth.

Every --scenes entry becomes SceneInfo objects in load_scenes: a scene file (by
name in scenes/ or by path) one, a generated family's name all its members, a
member's name that member (its file written to OUT/scenes/ first). The families,
and the solid angles of lights reported in the CSV, are in the section at the end.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from .config import (
    DEFAULT_SCALE, GENERATED_SCENES_DIR, MCRT_DEFAULT_MAX_DEPTH, SCENES_DIR, FamilyMember, SceneInfo, Settings,
)
from .pbrt_families import PBRT_FAMILIES, pbrt_file_settings
from .solid_angles import (  # noqa: F401 (re-exported: the solid angles of lights)
    _cross, _dot, _sub, disk_solid_angle_on_axis, ellipse_solid_angle, polygon_solid_angle, sphere_solid_angle,
    triangle_solid_angle, triangles_solid_angles,
)
from .util import bad_input, sha256_file


def scene_path(spec: str) -> Path:
    """A scene's file from its name (scenes/NAME.json) or path."""
    path = Path(spec)
    return SCENES_DIR / f"{spec}.json" if not path.suffix else path


def scene_file_max_depth(path: Path) -> int:
    """The max depth a scene file asks for (mcrt's default when it gives none)."""
    if path.suffix == ".pbrt":
        return pbrt_file_settings(path.read_text(encoding="utf-8"))[2]
    render = json.loads(path.read_text(encoding="utf-8")).get("render", {})
    return int(render.get("max_depth", MCRT_DEFAULT_MAX_DEPTH))


def load_scene(spec: str, settings: Settings) -> SceneInfo:
    """Find a scene by name or path, and read its size and depth (with the overrides applied).

    A family member's name (see below) is written to OUT/scenes/NAME.json first.
    """
    member = family_member(spec)
    path = write_member(member, settings.out) if member is not None else scene_path(spec)
    if not path.is_file():
        raise bad_input(f"scene not found: {spec}")
    if path.suffix == ".pbrt":  # a pbrt-v4 file: its Film's resolution, its Integrator's maxdepth
        data: dict = {}
        own_width, own_height, own_depth = pbrt_file_settings(path.read_text(encoding="utf-8"))
    else:
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except ValueError as err:
            raise bad_input(f"{path}: not a JSON scene file ({err})")
        camera = data.get("camera", {})
        own_width, own_height = int(camera.get("width", 0)), int(camera.get("height", 0))
        own_depth = int(data.get("render", {}).get("max_depth", MCRT_DEFAULT_MAX_DEPTH))
    width = settings.width or int(round(own_width * DEFAULT_SCALE))
    height = settings.height or int(round(own_height * DEFAULT_SCALE))
    if width <= 0 or height <= 0:
        raise bad_input(f"{path}: no camera width/height; pass --width and --height")
    max_depth = settings.max_depth or own_depth
    if member is not None:
        return SceneInfo(name=member.name, path=path.resolve(), content_sha256=sha256_file(path),
                         width=width, height=height, max_depth=max_depth, family=member.family,
                         family_param=member.param, light_solid_angle=member.solid_angle)
    return SceneInfo(name=path.stem, path=path.resolve(), content_sha256=sha256_file(path),
                     width=width, height=height, max_depth=max_depth,
                     light_solid_angle=first_light_solid_angle(data, CORNELL_CENTRE) if data else None)




def load_scenes(specs: list[str], settings: Settings) -> list[SceneInfo]:
    """Every --scenes entry as SceneInfo objects: a family name gives all its members, in order.

    Repeats (a member named on its own and through its family) are kept once.
    """
    names: list[str] = []
    for spec in specs:
        names += [m.name for m in FAMILIES[spec]()] if spec in FAMILIES else [spec]
    return [load_scene(name, settings) for name in dict.fromkeys(names)]


# --------------------------------------------------------------------------
# Generated scene families.
#
# A family expands one --scenes entry (its name) into several scene files,
# written to OUT/scenes/NAME.json when the study runs (never committed). The
# files are printed from the parameters alone (fixed key order, numbers rounded
# to 6 decimals), so they are byte-identical from run to run and their content
# hash keys the cached references like any scene file's.
#
# size_rect, size_disk, size_sphere: the Cornell box of scenes/cornell_rect.json
#   (camera, materials, walls, boxes copied) with its ceiling light replaced by a
#   rectangle (the seed's 130x105 aspect), a disk (the rectangle's area) or a
#   sphere (projected area pi r^2 = the rectangle's area, centre 1 unit plus r
#   below the ceiling), centred at x=278, z=279.5, at 1/16, 1/4, 1, 2, 4, 8 times
#   the seed's area (13,650; spheres: see below). The emission is 15 x 13,650 / area, so radiance x
#   area (planar) or radiance x projected area (sphere) is the seed's 204,750:
#   the planar lights emit the seed's power; the sphere, emitting from its whole
#   surface, emits 4x that (pi L 4 pi r^2), but every point of the box sees it
#   roughly as bright as the disk of the same size. Planar lights are clamped to
#   stay 1 unit inside the 555x555 ceiling (never needed at these sizes: the 8x
#   rectangle is 367.7x297.0). Spheres take 1/16, 1/8, 1/4, 1/2, 1 and 2 times
#   the seed's area instead: a 4x sphere (r = 131.8) would reach below the tall
#   box's top (y=330) and cut into it, an 8x one contain the box's centre.
# distance: the seed's 130x105 rectangle (emission 15, facing down) at height h
#   over a 4000x4000 white floor, no walls, h/130 in 0.01 ... 10. The Cornell
#   boxes are scaled about the floor point under the light by
#   s = min(1, h / 660), so the tall box (330) reaches at most h/2, and dropped
#   when the tall box would be under 10 units (h < 20: h/130 = 0.01, 0.03, 0.1).
#   The camera looks at the floor point under the light from 1300 units away,
#   45 degrees up, from the side (-x, +z) where no box stands in the way; it is
#   below the light at the largest height (which is then out of the frame), and
#   above the others, whose backs (black) hide some floor beyond the light.
#
# The triangle and many-light families are pbrt-v4 files (OUT/scenes/NAME.pbrt;
# the JSON format has no triangles), written by pbrt_families.py:
#
# tri_size, tri_distance, tri_aspect, tri_grazing: one emissive triangle (a
#   trianglemesh with AreaLightSource "diffuse", black material: a pure emitter)
#   over a 400x400 diffuse floor (albedo 0.73) with a cube (side 0.5, the same
#   white) standing at (-2, 0, -2) beside it; lengths in units of the reference
#   triangle's edge: equilateral, edge 1 (area sqrt(3)/4), centroid 1 above the
#   floor point (0, 0, 0), facing down, radiance 10. Every member's radiance is
#   10 x sqrt(3)/4 / its area (area from the corners as written), so every
#   member emits the reference's power. The camera (LookAt, Camera
#   "perspective", fov 40, 600x600, box filter, maxdepth 50) looks at the floor
#   point under the light from 10 units away, 45 degrees up, from the (-x, +z)
#   side; it sees the backs (black) of the triangles, never their emission.
#   tri_size: the equilateral triangle at 1/16, 1/4, 1, 2, 4, 8 times the
#     reference's area (members tri_size_1of16 ... tri_size_x8).
#   tri_distance: the reference triangle at heights h = 0.01, 0.03, 0.1, 0.3,
#     1, 3, 10 (h / edge; members tri_distance_h0.01 ... tri_distance_h10).
#   tri_aspect: slivers of the reference's area, an isosceles triangle with
#     its base along x sqrt(k) times the equilateral's and its height 1/sqrt(k)
#     times, so base / height is k times the equilateral's, k = 1, 10, 100,
#     1000, 10^4 (members tri_aspect_a1 ... tri_aspect_a10000; the last is 100
#     long and 0.0087 wide).
#   tri_grazing: the reference triangle tilted about the x axis (towards -z)
#     until the cosine between its normal and straight down is c = 1, 0.5, 0.1,
#     0.03, 0.01, 0.001 (members tri_grazing_c1 ... tri_grazing_c0.001): its
#     plane then passes at a distance c from the floor point under it, and the
#     floor along the line it cuts sees it at grazing angles (the floor beyond
#     it, +z, nearly not at all).
# many_lights: the scenes of many_lights_scenes.py (bench/many_lights.py's),
#   320x240: a 20x20 floor with 40 boxes under N = 10, 100, 1000, 10^4, 10^5
#   small emitters (triangles and quads, facing down, radiance log-uniform over
#   three decades; members many_lights_n10 ... many_lights_n100000), and the same
#   floor beside a wavy emissive curtain of 12,800 triangles and 20 small
#   lights (many_lights_mesh); every radiance scaled so that each member emits
#   a power (pi x radiance x area, summed) of 100. The files of 10^4 and 10^5
#   lights take seconds to make (3 and 30 MB).
#
# Each member has a family parameter (light area / 13,650, or h / 130; for the
# triangles area / the reference's, h / edge, k, c; for many_lights the number
# of emitters, 12,800 for the mesh) and the light's solid angle seen from the
# family's reference point: the centre of the box (278, 278, 279.5), or the
# floor point under the light's centre; for many_lights the median over its
# emitting triangles of their solid angle from the floor point the camera
# looks at, (0, 0, 0.5).
# --------------------------------------------------------------------------

CORNELL_CENTRE = (278.0, 278.0, 279.5)
SEED_RECT = (130.0, 105.0)
SEED_AREA = SEED_RECT[0] * SEED_RECT[1]  # 13,650
SEED_EMIT = 15.0
SEED_POWER = SEED_EMIT * SEED_AREA  # radiance x (projected) area of every size_* light
CEILING_Y = 554.0
BOX_SIZE = 555.0
LIGHT_X, LIGHT_Z = 278.0, 279.5
SIZE_RATIOS = [(1 / 16, "1of16"), (1 / 4, "1of4"), (1.0, "x1"), (2.0, "x2"), (4.0, "x4"), (8.0, "x8")]
# Spheres stop at 2x: a larger one (r > 111) would reach below the tall box's
# top (y = 330) under the ceiling, and at 8x contain the box's centre.
SPHERE_SIZE_RATIOS = [(1 / 16, "1of16"), (1 / 8, "1of8"), (1 / 4, "1of4"), (1 / 2, "1of2"), (1.0, "x1"), (2.0, "x2")]
DISTANCE_RATIOS = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0]
DISTANCE_FLOOR = 4000.0
DISTANCE_BOX_MIN_HEIGHT = 10.0  # boxes scaled below this are dropped
DISTANCE_CAMERA = {"distance": 1300.0, "elevation_deg": 45.0, "azimuth": (-1.0, 1.0)}

CORNELL_CAMERA = {"lookfrom": [278, 278, -800], "lookat": [278, 278, 0], "vup": [0, 1, 0], "vfov": 40,
                  "width": 600, "height": 600}
CORNELL_RENDER = {"spp": 100, "max_depth": 50, "background": [0, 0, 0]}
CORNELL_MATERIALS = {
    "red": {"type": "lambertian", "albedo": [0.65, 0.05, 0.05]},
    "white": {"type": "lambertian", "albedo": [0.73, 0.73, 0.73]},
    "green": {"type": "lambertian", "albedo": [0.12, 0.45, 0.15]},
}
TALL_BOX = {"type": "box", "min": [0, 0, 0], "max": [165, 330, 165], "material": "white", "rotate_y": 15,
            "translate": [265, 0, 295]}
SHORT_BOX = {"type": "box", "min": [0, 0, 0], "max": [165, 165, 165], "material": "white", "rotate_y": -18,
             "translate": [130, 0, 65]}
CORNELL_WALLS_BEFORE_LIGHT = [
    {"type": "yz_rect", "y0": 0, "y1": 555, "z0": 0, "z1": 555, "k": 555, "material": "green"},
    {"type": "yz_rect", "y0": 0, "y1": 555, "z0": 0, "z1": 555, "k": 0, "material": "red"},
]
CORNELL_OBJECTS_AFTER_LIGHT = [
    {"type": "xz_rect", "x0": 0, "x1": 555, "z0": 0, "z1": 555, "k": 555, "material": "white"},
    {"type": "xz_rect", "x0": 0, "x1": 555, "z0": 0, "z1": 555, "k": 0, "material": "white"},
    {"type": "xy_rect", "x0": 0, "x1": 555, "y0": 0, "y1": 555, "k": 555, "material": "white"},
    TALL_BOX,
    SHORT_BOX,
]


def _num(x: float) -> float | int:
    """A number as written to a scene file: rounded to 6 decimals, integral values as int."""
    r = round(float(x), 6)
    return int(r) if r == int(r) else r


def _light_material(emit: float) -> dict:
    e = _num(emit)
    return {"type": "diffuse_light", "emit": [e, e, e]}


def _cornell_scene(light: dict, emit: float) -> dict:
    return {"camera": dict(CORNELL_CAMERA), "render": dict(CORNELL_RENDER),
            "materials": {**CORNELL_MATERIALS, "light": _light_material(emit)},
            "objects": [*CORNELL_WALLS_BEFORE_LIGHT, light, *CORNELL_OBJECTS_AFTER_LIGHT]}


def _planar_scale(ratio: float, half_extent: float) -> float:
    """Linear scale of a light of `ratio` times the seed's area, clamped to stay 1 unit inside the ceiling
    (half_extent: the light's largest half-width at ratio 1)."""
    limit = min(LIGHT_X, BOX_SIZE - LIGHT_X, LIGHT_Z, BOX_SIZE - LIGHT_Z) - 1.0
    return min(math.sqrt(ratio), limit / half_extent)


def size_rect_family() -> list[FamilyMember]:
    """The ceiling rectangle at each size (the seed's 130x105 aspect)."""
    members = []
    for ratio, tag in SIZE_RATIOS:
        k = _planar_scale(ratio, SEED_RECT[0] / 2)
        w, d = SEED_RECT[0] * k, SEED_RECT[1] * k
        x0, x1, z0, z1 = (_num(v) for v in (LIGHT_X - w / 2, LIGHT_X + w / 2, LIGHT_Z - d / 2, LIGHT_Z + d / 2))
        area = (x1 - x0) * (z1 - z0)
        light = {"type": "xz_rect", "x0": x0, "x1": x1, "z0": z0, "z1": z1, "k": _num(CEILING_Y),
                 "material": "light", "flip": True}
        corners = [(x0, CEILING_Y, z0), (x1, CEILING_Y, z0), (x1, CEILING_Y, z1), (x0, CEILING_Y, z1)]
        members.append(FamilyMember(f"size_rect_{tag}", "size_rect", k * k,
                                    _cornell_scene(light, SEED_POWER / area),
                                    polygon_solid_angle(CORNELL_CENTRE, corners)))
    return members


def size_disk_family() -> list[FamilyMember]:
    """The ceiling disk at each size (the rectangle's area)."""
    members = []
    for ratio, tag in SIZE_RATIOS:
        k = _planar_scale(ratio, math.sqrt(SEED_AREA / math.pi))
        radius = _num(math.sqrt(SEED_AREA / math.pi) * k)
        area = math.pi * radius * radius
        light = {"type": "ellipse", "center": [_num(LIGHT_X), _num(CEILING_Y), _num(LIGHT_Z)],
                 "axis1": [radius, 0, 0], "axis2": [0, 0, radius], "material": "light"}  # normal -y
        members.append(FamilyMember(f"size_disk_{tag}", "size_disk", k * k,
                                    _cornell_scene(light, SEED_POWER / area),
                                    disk_solid_angle_on_axis(CEILING_Y - CORNELL_CENTRE[1], radius)))
    return members


def size_sphere_family() -> list[FamilyMember]:
    """The sphere light under the ceiling at each size (projected area pi r^2 = the rectangle's area)."""
    members = []
    for ratio, tag in SPHERE_SIZE_RATIOS:
        k = _planar_scale(ratio, math.sqrt(SEED_AREA / math.pi))
        radius = _num(math.sqrt(SEED_AREA / math.pi) * k)
        centre = (LIGHT_X, _num(CEILING_Y - radius - 1.0), LIGHT_Z)
        area = math.pi * radius * radius
        light = {"type": "sphere", "center": [_num(c) for c in centre], "radius": radius, "material": "light"}
        members.append(FamilyMember(f"size_sphere_{tag}", "size_sphere", k * k,
                                    _cornell_scene(light, SEED_POWER / area),
                                    sphere_solid_angle(math.dist(CORNELL_CENTRE, centre), radius)))
    return members


def _scaled_box(box: dict, s: float, centre: tuple[float, float]) -> dict:
    """A box scaled by s about the floor point `centre` (x, z): size times s, position drawn towards it."""
    tx, ty, tz = box["translate"]
    return {**box, "max": [_num(v * s) for v in box["max"]],
            "translate": [_num(centre[0] + s * (tx - centre[0])), _num(ty * s), _num(centre[1] + s * (tz - centre[1]))]}


def distance_boxes(h: float) -> tuple[float, list[dict]]:
    """The occluders under a light at height h: (scale, boxes); scale 0 when they are dropped."""
    s = min(1.0, h / (2 * TALL_BOX["max"][1]))
    if s * TALL_BOX["max"][1] < DISTANCE_BOX_MIN_HEIGHT:
        return 0.0, []
    return s, [_scaled_box(b, s, (LIGHT_X, LIGHT_Z)) for b in (TALL_BOX, SHORT_BOX)]


def distance_camera() -> dict:
    """The camera of the distance family: at the floor point under the light, 45 degrees up, from (-x, +z)."""
    c = DISTANCE_CAMERA
    el = math.radians(c["elevation_deg"])
    ax, az = c["azimuth"]
    norm = math.hypot(ax, az)
    horiz = c["distance"] * math.cos(el)
    eye = (LIGHT_X + horiz * ax / norm, c["distance"] * math.sin(el), LIGHT_Z + horiz * az / norm)
    return {"lookfrom": [_num(v) for v in eye], "lookat": [_num(LIGHT_X), 0, _num(LIGHT_Z)], "vup": [0, 1, 0],
            "vfov": 40, "width": 600, "height": 600}


def distance_family() -> list[FamilyMember]:
    """The seed's rectangle at heights h = 130 x {0.01 ... 10} over a large floor."""
    members = []
    w, d = SEED_RECT
    half = DISTANCE_FLOOR / 2
    for ratio in DISTANCE_RATIOS:
        h = _num(ratio * SEED_RECT[0])
        x0, x1, z0, z1 = (_num(v) for v in (LIGHT_X - w / 2, LIGHT_X + w / 2, LIGHT_Z - d / 2, LIGHT_Z + d / 2))
        light = {"type": "xz_rect", "x0": x0, "x1": x1, "z0": z0, "z1": z1, "k": h, "material": "light",
                 "flip": True}
        floor = {"type": "xz_rect", "x0": _num(LIGHT_X - half), "x1": _num(LIGHT_X + half),
                 "z0": _num(LIGHT_Z - half), "z1": _num(LIGHT_Z + half), "k": 0, "material": "white"}
        _, boxes = distance_boxes(h)
        scene = {"camera": distance_camera(), "render": dict(CORNELL_RENDER),
                 "materials": {"white": dict(CORNELL_MATERIALS["white"]), "light": _light_material(SEED_EMIT)},
                 "objects": [floor, light, *boxes]}
        corners = [(x0, h, z0), (x1, h, z0), (x1, h, z1), (x0, h, z1)]
        members.append(FamilyMember(f"distance_h{ratio:g}", "distance", ratio, scene,
                                    polygon_solid_angle((LIGHT_X, 0.0, LIGHT_Z), corners)))
    return members


FAMILIES = {"size_rect": size_rect_family, "size_disk": size_disk_family, "size_sphere": size_sphere_family,
            "distance": distance_family, **PBRT_FAMILIES}


def family_member(name: str) -> FamilyMember | None:
    """The generated member of that name, or None."""
    for family, make in FAMILIES.items():
        if name.startswith(family + "_"):
            for member in make():
                if member.name == name:
                    return member
    return None


def scene_text(scene: dict) -> str:
    """A scene as the text of its file, in the style of scenes/*.json (one object per line); deterministic."""
    def dump(value: object) -> str:
        return json.dumps(value, separators=(", ", ": "))
    lines = ["{", f'  "camera": {dump(scene["camera"])},', f'  "render": {dump(scene["render"])},',
             '  "materials": {']
    materials = list(scene["materials"].items())
    lines += [f"    {dump(k)}: {dump(v)}" + ("," if i < len(materials) - 1 else "")
              for i, (k, v) in enumerate(materials)]
    lines += ["  },", '  "objects": [']
    objects = scene["objects"]
    lines += [f"    {dump(o)}" + ("," if i < len(objects) - 1 else "") for i, o in enumerate(objects)]
    lines += ["  ]", "}"]
    return "\n".join(lines) + "\n"


def member_text(member: FamilyMember) -> str:
    """The text of a member's scene file: JSON (scene_text) or pbrt-v4."""
    scene = member.scene
    if isinstance(scene, dict):
        return scene_text(scene)
    return scene if isinstance(scene, str) else scene()


def write_member(member: FamilyMember, out: Path) -> Path:
    """Write a member's scene file to OUT/scenes/NAME.json or NAME.pbrt (left untouched when already
    identical)."""
    path = out / GENERATED_SCENES_DIR / f"{member.name}{member.suffix}"
    text = member_text(member)
    if not (path.is_file() and path.read_text(encoding="utf-8") == text):
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.tmp")
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)
    return path


def light_solid_angle(obj: dict, p) -> float | None:
    """Solid angle of a light object of a scene file from p (geometric, whichever side faces p, so
    4 pi from inside a sphere); None for a type not handled."""
    t = obj.get("type", "")
    try:
        if t in ("xz_rect", "xz_rect_sa", "xy_rect", "xy_rect_sa", "yz_rect", "yz_rect_sa"):
            plane = t[:2]
            u0, u1, v0, v1 = (float(obj[plane[0] + "0"]), float(obj[plane[0] + "1"]),
                              float(obj[plane[1] + "0"]), float(obj[plane[1] + "1"]))
            k = float(obj["k"])
            axes = {"xz": (0, 2, 1), "xy": (0, 1, 2), "yz": (1, 2, 0)}[plane]

            def at(u: float, v: float) -> tuple:
                q = [0.0, 0.0, 0.0]
                q[axes[0]], q[axes[1]], q[axes[2]] = u, v, k
                return tuple(q)
            return polygon_solid_angle(p, [at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)])
        if t in ("rect", "rect_sa"):
            c, e1, e2 = (tuple(map(float, obj[k])) for k in ("corner", "edge1", "edge2"))
            c1 = tuple(a + b for a, b in zip(c, e1))
            return polygon_solid_angle(p, [c, c1, tuple(a + b for a, b in zip(c1, e2)),
                                           tuple(a + b for a, b in zip(c, e2))])
        if t in ("ellipse", "ellipse_sa"):
            c, a1, a2 = (tuple(map(float, obj[k])) for k in ("center", "axis1", "axis2"))
            r1, r2 = math.sqrt(_dot(a1, a1)), math.sqrt(_dot(a2, a2))
            n = _cross(a1, a2)
            v = _sub(p, c)
            off_axis = _cross(v, n)
            if math.isclose(r1, r2, rel_tol=1e-9) and _dot(off_axis, off_axis) <= 1e-18 * _dot(v, v) * _dot(n, n):
                return disk_solid_angle_on_axis(math.sqrt(_dot(v, v)), r1)
            return ellipse_solid_angle(p, c, a1, a2)
        if t == "sphere":
            c = tuple(map(float, obj["center"]))
            return sphere_solid_angle(math.dist(p, c), float(obj["radius"]))
    except (KeyError, TypeError, ValueError):
        return None
    return None


def first_light_solid_angle(scene: dict, p) -> float | None:
    """Solid angle from p of a scene's first light (first object whose material is a diffuse_light)."""
    materials = scene.get("materials", {})
    for obj in scene.get("objects", []):
        if materials.get(obj.get("material"), {}).get("type") == "diffuse_light":
            return light_solid_angle(obj, p)
    return None


def scene_columns(name: str, path: Path | None = None) -> dict:
    """The CSV's family columns of a scene by name: family, family parameter, light solid angle.

    For the rows of a CSV written before these columns existed: family members from their
    parameters, other scenes from their file (`path`, else scenes/NAME.json) if it exists.
    """
    member = family_member(name)
    if member is not None:
        return {"family": member.family, "family_param": member.param, "light_solid_angle": member.solid_angle}
    path = path or SCENES_DIR / f"{name}.json"
    solid_angle = None
    if path.is_file() and path.suffix == ".json":
        try:
            solid_angle = first_light_solid_angle(json.loads(path.read_text(encoding="utf-8")), CORNELL_CENTRE)
        except ValueError:
            pass
    return {"family": "", "family_param": None, "light_solid_angle": solid_angle}


def scene_info_columns(scene: SceneInfo) -> dict:
    """The CSV's family columns of a scene of this run."""
    return {"family": scene.family, "family_param": scene.family_param, "light_solid_angle": scene.light_solid_angle}
