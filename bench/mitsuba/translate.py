"""mcrt scene JSON (scenes/FORMAT.md) -> Mitsuba 3 scene, as a dict for
mi.load_dict and as XML text. Both are written from one neutral description
(`describe`), so the two cannot drift apart.

Conventions (each checked by the bench's validation, see README.md here):
- camera: mcrt's image right is cross(vup, lookfrom - lookat) = cross(dir, up);
  Mitsuba's look_at puts cross(up, dir) at the image *left*, so a plain
  look_at(lookfrom, lookat, vup) with fov_axis "y" gives the same image.
- film: hdrfilm, linear RGB float32, box reconstruction filter (radius 0.5:
  each sample lands in its own pixel, as mcrt's box-filtered mean).
- planar shapes: Mitsuba's rectangle ([-1,1]^2) and disk (unit) face +z in
  local space; to_world has columns (a, b, n, centre) with a x b along the
  mcrt front normal n, so the area emitter (one-sided, front only) emits
  where mcrt's light does. No flip_normals is needed for them.
- lambertian -> twosided(diffuse); diffuse_light -> area emitter + black
  diffuse BSDF (Mitsuba's default BSDF would be a 0.5 grey diffuse).
- integrator: path, max_depth = mcrt max_depth + 1 (Mitsuba counts path
  vertices, the emitter's included: max_depth 1 = emitters seen directly).
"""
import json
import math
from pathlib import Path

import numpy as np

RECT_AXES = {  # type -> (axis of the normal, the two in-plane axes); front normal +axis
    "xz_rect": (1, 0, 2), "xy_rect": (2, 0, 1), "yz_rect": (0, 1, 2),
}
RECT_RANGES = {"xz_rect": ("x", "z"), "xy_rect": ("x", "y"), "yz_rect": ("y", "z")}


def _v(x):
    return np.asarray(x, dtype=float)


def _frame(center, a, b, n):
    """4x4 to_world with columns (a, b, n, center), a x b along n (swap a, b if not)."""
    if np.dot(np.cross(a, b), n) < 0:
        a, b = b, a
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = a, b, n, center
    return m


def _rot_y(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    m = np.eye(4)  # mcrt's rigid_y: x' = c x + s z, z' = -s x + c z
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


def _translate(t):
    m = np.eye(4)
    m[:3, 3] = t
    return m


def _shape(o):
    """One mcrt object -> (mitsuba type, to_world 4x4 or None, extra params)."""
    t = o["type"].removesuffix("_sa")
    sign = -1.0 if o.get("flip", False) else 1.0
    if t in RECT_AXES:
        ax, i, j = RECT_AXES[t]
        u, w = RECT_RANGES[t]
        c, a, b, n = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
        c[ax], c[i], c[j] = o["k"], (o[u + "0"] + o[u + "1"]) / 2, (o[w + "0"] + o[w + "1"]) / 2
        a[i], b[j], n[ax] = abs(o[u + "1"] - o[u + "0"]) / 2, abs(o[w + "1"] - o[w + "0"]) / 2, sign
        return "rectangle", _frame(c, a, b, n), {}
    if t == "rect":
        e1, e2 = _v(o["edge1"]), _v(o["edge2"])
        n = np.cross(e1, e2)
        return "rectangle", _frame(_v(o["corner"]) + (e1 + e2) / 2, e1 / 2, e2 / 2,
                                   sign * n / np.linalg.norm(n)), {}
    if t == "ellipse":
        a, b = _v(o["axis1"]), _v(o["axis2"])
        n = np.cross(a, b)
        return "disk", _frame(_v(o["center"]), a, b, sign * n / np.linalg.norm(n)), {}
    if t == "sphere":
        return "sphere", None, {"center": [float(x) for x in o["center"]],
                                "radius": float(o["radius"]), "flip_normals": sign < 0}
    if t == "box":
        lo, hi = _v(o["min"]), _v(o["max"])
        local = _translate((lo + hi) / 2) @ np.diag([*((hi - lo) / 2), 1.0])
        m = _translate(o.get("translate", [0, 0, 0])) @ _rot_y(o.get("rotate_y", 0.0)) @ local
        return "cube", m, {"flip_normals": sign < 0}
    raise ValueError(f"objects: type {o['type']!r} has no Mitsuba translation")


def _bsdf(m):
    """mcrt material -> Mitsuba BSDF description (None for lights: handled per shape)."""
    kind = m["type"]
    if kind == "lambertian":
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": ("rgb", m["albedo"])}}
    if kind == "metal":  # Shirley's fuzz has no exact Mitsuba twin: roughness alpha = fuzz
        inner = ({"type": "conductor", "material": ("string", "none")} if m.get("fuzz", 0) == 0 else
                 {"type": "roughconductor", "material": ("string", "none"),
                  "alpha": ("float", float(m["fuzz"]))})
        inner["specular_reflectance"] = ("rgb", m["albedo"])
        return {"type": "twosided", "bsdf": inner}
    if kind == "dielectric":  # Mitsuba: exact Fresnel (mcrt: Schlick)
        return {"type": "dielectric", "int_ior": ("float", float(m["ior"])), "ext_ior": ("float", 1.0)}
    if kind == "diffuse_light":
        return None
    raise ValueError(f"materials: type {kind!r} has no Mitsuba translation")


def describe(scene, width=None, height=None, spp=16, sampler="independent", max_depth=None):
    """The neutral description: camera, film, integrator, named BSDFs, shapes."""
    cam, rnd = scene["camera"], scene.get("render", {})
    depth = rnd.get("max_depth", 50) if max_depth is None else max_depth
    mats = scene["materials"]
    shapes = []
    for i, o in enumerate(scene["objects"]):
        kind, m, extra = _shape(o)
        mat = mats[o["material"]]
        s = {"id": f"obj{i:02d}_{o['type']}", "type": kind, "to_world": m, "params": extra}
        if mat["type"] == "diffuse_light":
            s["emit"] = [float(x) for x in mat["emit"]]
        else:
            s["bsdf_ref"] = o["material"]
        shapes.append(s)
    return {
        "camera": {"origin": cam["lookfrom"], "target": cam["lookat"], "up": cam["vup"],
                   "fov": float(cam["vfov"]), "width": int(width or cam["width"]),
                   "height": int(height or cam["height"])},
        "spp": int(spp), "sampler": sampler,
        "mcrt_max_depth": int(depth), "max_depth": int(depth) + 1,
        "background": [float(x) for x in rnd.get("background", [0, 0, 0])],
        "bsdfs": {k: _bsdf(v) for k, v in mats.items() if _bsdf(v) is not None},
        "shapes": shapes,
    }


def load_scene(path):
    return json.loads(Path(path).read_text())


def front_normals(desc):
    """Front normal of every planar shape (column 2 of to_world), for the report."""
    return {s["id"]: [round(float(x), 6) for x in s["to_world"][:3, 2] / np.linalg.norm(s["to_world"][:3, 2])]
            for s in desc["shapes"] if s["type"] in ("rectangle", "disk")}
