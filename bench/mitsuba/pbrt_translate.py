"""pbrt-v4 scene file (mcrt's subset, docs/pbrt.md) -> Mitsuba 3 scene.

`translate(path, work_dir, ...)` interprets the directives of pbrt_parse with
pbrt-v4's graphics state (CTM, AttributeBegin/End, ReverseOrientation, named
materials and textures, the current area light, Attribute defaults) and
returns a `Scene`: the Mitsuba nodes in the tuple style of writers.py
(("rgb", [...]), ("float", x), ...), so that writers turns them into a
mi.load_dict dict or XML. Meshes and image textures are written to files in
`work_dir`. Anything outside the subset is refused with PbrtError
("FILE:LINE: what").

The choices, each also in README.md:
- camera: Mitsuba's camera space has +x at the image's left, pbrt's at its
  right, so to_world = inverse(camera-from-world) * Scale(-1, 1, 1); the
  fov applies to the shorter axis (fov_axis "smaller"). The product must be
  a rotation (or a rotation and a mirror): no scale.
- depth: Mitsuba's path max_depth = pbrt maxdepth + 1 (Mitsuba counts the
  emitter's vertex; the JSON bench's convention, checked there).
- BSDFs: diffuse and conductors are wrapped in `twosided` (pbrt-v4 shades
  either side; Mitsuba's are black from the back); dielectrics are two-sided
  by nature. Rough ones (max alpha >= 1e-3, pbrt-v4's EffectivelySmooth) are
  GGX with visible-normal sampling; alpha = sqrt(roughness) when
  remaproughness (pbrt-v4's RoughnessToAlpha), else the roughness itself.
- conductor `reflectance` r: eta = 1, k = 2 sqrt(r) / sqrt(1 - r), which is
  what pbrt-v4 does with it (not Mitsuba's specular_reflectance, which scales
  the Fresnel term of given eta/k).
- named spectra: `named_spectra="mitsuba"` gives a metal Mitsuba's own
  preset (`material` "Cu", "Au", ...: Mitsuba's data, integrated to RGB by
  Mitsuba); "pbrt" gives pbrt-v4's tables as mcrt converts them
  (src/pbrt/spectrum.cpp), so that only the renderers differ. A glass is
  its IOR at 550 nm either way (Mitsuba renders no dispersion in RGB).
- area lights: Mitsuba's area emitter is one-sided. A two-sided pbrt light
  becomes two copies of its shape, the second with flipped normals and moved
  by 1e-5 of the scene's size behind the first, each emitting to its own side.
- textures: imagemap -> bitmap of a linear float EXR written here (decoded
  with the file's encoding, `scale` and `invert` applied, flipped
  vertically: pbrt-v4 looks up (s, 1 - t), Mitsuba (s, t) with row 0 at
  t = 0), wrap repeat or clamp, bilinear; checkerboard (2-D) -> checkerboard
  with to_uv = (s u + ds, t v + dt) / 2 (Mitsuba's cells are half a unit);
  constant and scale of constants -> the value; float textures only as
  constants.
- filters: box (radius 0.5) -> box; triangle r -> tent r; gaussian sigma ->
  gaussian stddev = sigma, whose window Mitsuba fixes at 4 sigma (pbrt:
  `radius`, default 1.5 = 3 sigma, minus the value at the radius): the same
  mean, a slightly different blur.
"""
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .pbrt_mesh import Mesh, bilinear_to_triangles, read_ply, write_ply
from .pbrt_parse import PbrtError, parse_file

GLASS_IOR_550 = {  # pbrt-v4's named glasses at 550 nm (src/pbrt/spectrum.cpp)
    "glass-BK7": 1.51854, "glass-BAF10": 1.67305, "glass-FK51A": 1.4878, "glass-LASF9": 1.85581,
    "glass-F5": 1.67709, "glass-F10": 1.73357, "glass-F11": 1.79112}
# pbrt-v4's metal tables as mcrt converts them to RGB (src/pbrt/spectrum.cpp)
PBRT_METAL_RGB = {
    "Ag": ([0.128661, 0.123346, 0.151831], [4.07651, 3.30939, 2.37055]),
    "Al": ([1.42089, 0.937391, 0.577384], [7.74914, 6.6383, 5.33153]),
    "Au": ([0.0771668, 0.390458, 1.57352], [3.38512, 2.53215, 1.77101]),
    "Cu": ([0.0664227, 0.966261, 1.20706], [3.30469, 2.60231, 2.35849]),
    "CuZn": ([0.415342, 0.513783, 1.13897], [3.688, 2.7056, 1.7608]),
    "MgO": ([1.72586, 1.74324, 1.75283], [0.0, 0.0, 0.0]),
    "TiO2": ([2.84447, 2.95747, 3.19054], [7.88159e-05, 0.0, 0.000693437])}
MITSUBA_METALS = {"Ag", "Al", "Au", "Cu", "MgO", "TiO2"}  # presets of Mitsuba 3.9.1 among pbrt's metals


@dataclass
class Scene:
    width: int = 1280
    height: int = 720
    spp: int = 16
    max_depth: int = 5              # pbrt's maxdepth (mcrt's --max-depth)
    camera_to_world: np.ndarray = None
    fov: float = 90.0
    lens_radius: float = 0.0        # pbrt's lensradius: Mitsuba's thinlens where > 0
    focal_distance: float = 1e6     # pbrt's focaldistance (its default 1e6)
    rfilter: dict = field(default_factory=lambda: {"type": "gaussian", "stddev": ("float", 0.5)})
    filter_text: str = "gaussian (pbrt default, radius 1.5, sigma 0.5)"
    bsdfs: dict = field(default_factory=dict)    # id -> node
    shapes: list = field(default_factory=list)   # (id, node)
    notes: list = field(default_factory=list)    # approximations made for this file
    ply_files: list = field(default_factory=list)


def _translate(v):
    m = np.eye(4)
    m[:3, 3] = v
    return m


def _rotate(deg, axis, loc):
    a = np.asarray(axis, float)
    if not np.linalg.norm(a) > 0:
        raise PbrtError(f"{loc}: Rotate: the axis is zero")
    x, y, z = a / np.linalg.norm(a)
    s, c = math.sin(math.radians(deg)), math.cos(math.radians(deg))
    m = np.eye(4)
    m[:3, :3] = [[x * x + (1 - x * x) * c, x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                 [x * y * (1 - c) + z * s, y * y + (1 - y * y) * c, y * z * (1 - c) - x * s],
                 [x * z * (1 - c) - y * s, y * z * (1 - c) + x * s, z * z + (1 - z * z) * c]]
    return m


def _look_at(v, loc):
    pos, look, up = np.asarray(v[0:3]), np.asarray(v[3:6]), np.asarray(v[6:9])
    d = look - pos
    if not np.linalg.norm(d) > 0:
        raise PbrtError(f"{loc}: LookAt: the eye is the point looked at")
    d /= np.linalg.norm(d)
    right = np.cross(up / np.linalg.norm(up), d)
    if not np.linalg.norm(right) > 1e-12:
        raise PbrtError(f"{loc}: LookAt: up is parallel to the view direction")
    right /= np.linalg.norm(right)
    w = np.eye(4)  # world from camera: columns right, up, dir, pos
    w[:3, 0], w[:3, 1], w[:3, 2], w[:3, 3] = right, np.cross(d, right), d, pos
    return np.linalg.inv(w)


def _swaps_handedness(m):
    return np.linalg.det(m[:3, :3]) < 0


class _State:
    def __init__(self):
        self.ctm = np.eye(4)
        self.reverse = False
        self.material = "mat_default"
        self.light = None        # (rgb L, twosided) or None
        self.defaults = {}       # kind -> {name: Param}

    def copy(self):
        s = _State()
        s.ctm, s.reverse, s.material, s.light = self.ctm.copy(), self.reverse, self.material, self.light
        s.defaults = {k: dict(v) for k, v in self.defaults.items()}
        return s


class _Params:
    """A directive's parameters, each lookup marking it used; finish() refuses the rest."""

    def __init__(self, d, defaults=None):
        self.d, self.defaults, self.used = d, defaults or {}, set()
        self.what = d.name + (f' "{d.type}"' if d.type else "") + (f' "{d.args[0]}"' if d.args and
                                                                    isinstance(d.args[0], str) else "")

    def get(self, name):
        if name in self.d.params:
            self.used.add(name)
            return self.d.params[name]
        return self.defaults.get(name)

    def fail(self, why):
        raise PbrtError(f"{self.d.loc}: {self.what}: {why}")

    def one(self, name, default, types=("float",)):
        p = self.get(name)
        if p is None:
            return default
        if p.type not in types or len(p.values) != 1:
            self.fail(f'"{p.type} {name}" must be one {" or ".join(types)}')
        return p.values[0]

    def default_only(self, name, value):
        p = self.get(name)
        if p is not None and p.values != [value]:
            self.fail(f'"{name}" is not supported except at its default {value!r}')

    def finish(self):
        rest = set(self.d.params) - self.used
        if rest:
            self.fail(f'"{sorted(rest)[0]}" is not supported by the Mitsuba translation')


class Translator:
    def __init__(self, path, work_dir, named_spectra="mitsuba"):
        self.path, self.work = Path(path), Path(work_dir)
        self.work.mkdir(parents=True, exist_ok=True)
        self.base = self.path.resolve().parent
        self.named_spectra = named_spectra
        self.s = _State()
        self.stack = []
        self.coordsys = {}
        self.scene = Scene()
        self.named = {}          # named material -> bsdf id
        self.textures = {}       # (kind, name) -> node or ("const", value)
        self.in_world = False
        self.pending_twosided = []
        self.bbox = []           # corners of every shape's world bounds
        self.scene.bsdfs["mat_default"] = _twosided({"type": "diffuse", "reflectance": ("rgb", [0.5] * 3)})
        self.n_mat = 0

    # ---- driver ------------------------------------------------------------
    def run(self):
        ds = parse_file(self.path)
        for d in ds:
            fn = getattr(self, "_" + d.name, None)
            if fn is None:
                raise PbrtError(f"{d.loc}: {d.name}{' ' + repr(d.type) if d.type else ''}: not supported")
            fn(d)
        if not self.in_world:
            raise PbrtError(f"{self.path}: the file has no WorldBegin")
        if self.scene.camera_to_world is None:
            self._camera_matrix(np.eye(4), f"{self.path}")
        self._finish_twosided()
        return self.scene

    # ---- transforms and state ---------------------------------------------
    def _Identity(self, d): self.s.ctm = np.eye(4)
    def _Translate(self, d): self.s.ctm = self.s.ctm @ _translate(d.args)
    def _Scale(self, d): self.s.ctm = self.s.ctm @ np.diag([*d.args, 1.0])
    def _Rotate(self, d): self.s.ctm = self.s.ctm @ _rotate(d.args[0], d.args[1:], d.loc)
    def _LookAt(self, d): self.s.ctm = self.s.ctm @ _look_at(d.args, d.loc)
    def _Transform(self, d): self.s.ctm = np.asarray(d.args, float).reshape(4, 4).T
    def _ConcatTransform(self, d): self.s.ctm = self.s.ctm @ np.asarray(d.args, float).reshape(4, 4).T
    def _CoordinateSystem(self, d): self.coordsys[d.args[0]] = self.s.ctm.copy()
    def _ReverseOrientation(self, d): self.s.reverse = not self.s.reverse

    def _CoordSysTransform(self, d):
        if d.args[0] not in self.coordsys:
            raise PbrtError(f"{d.loc}: CoordSysTransform: no coordinate system named {d.args[0]!r}")
        self.s.ctm = self.coordsys[d.args[0]].copy()

    def _AttributeBegin(self, d): self.stack.append((self.s.copy(), False))
    def _TransformBegin(self, d): self.stack.append((self.s.copy(), True))

    def _AttributeEnd(self, d):
        if not self.stack:
            raise PbrtError(f"{d.loc}: {d.name} without a matching begin")
        saved, only_ctm = self.stack.pop()
        if only_ctm:
            self.s.ctm = saved.ctm
        else:
            self.s = saved
    _TransformEnd = _AttributeEnd

    def _Attribute(self, d):
        if d.args[0] not in ("shape", "light", "material", "texture"):
            raise PbrtError(f"{d.loc}: Attribute {d.args[0]!r}: not supported")
        self.s.defaults.setdefault(d.args[0], {}).update(d.params)

    def _WorldBegin(self, d):
        self.in_world = True
        if self.scene.camera_to_world is None:
            self._camera_matrix(np.eye(4), d.loc)
        self.s.ctm = np.eye(4)
        self.coordsys["world"] = np.eye(4)

    def _WorldEnd(self, d): pass

    def _ColorSpace(self, d):
        if d.args[0] != "srgb":
            raise PbrtError(f"{d.loc}: ColorSpace {d.args[0]!r}: not supported")

    def _Option(self, d):
        for k in d.params:
            if k not in ("rendercoordsys", "seed"):
                raise PbrtError(f"{d.loc}: Option {k!r}: not supported")

    def _Accelerator(self, d): pass

    def _MediumInterface(self, d):
        if any(d.args):
            raise PbrtError(f"{d.loc}: MediumInterface: participating media are not supported")

    # ---- options -------------------------------------------------------------
    def _camera_matrix(self, cam_from_world, loc):
        to_world = np.linalg.inv(cam_from_world) @ np.diag([-1.0, 1, 1, 1])
        r = to_world[:3, :3]
        if not np.allclose(r.T @ r, np.eye(3), atol=1e-5):
            raise PbrtError(f"{loc}: Camera: a camera-from-world with a scale or shear is not supported")
        # det(r) < 0 for a plain LookAt: pbrt's camera space (x right) is the
        # mirror image of Mitsuba's (x left), so Mitsuba's to_world has a reflection.
        self.scene.camera_to_world = to_world

    def _Camera(self, d):
        if d.type != "perspective":
            raise PbrtError(f'{d.loc}: Camera "{d.type}": not supported (supported: perspective)')
        p = _Params(d)
        self.scene.fov = float(p.one("fov", 90.0))
        self.scene.lens_radius = float(p.one("lensradius", 0.0))
        self.scene.focal_distance = float(p.one("focaldistance", 1e6))
        if p.get("screenwindow") is not None or p.get("frameaspectratio") is not None:
            p.fail("screenwindow and frameaspectratio are not translated")
        p.finish()
        self._camera_matrix(self.s.ctm, d.loc)
        self.coordsys["camera"] = np.linalg.inv(self.s.ctm)

    def _Film(self, d):
        if d.type not in ("rgb", "gbuffer"):
            raise PbrtError(f'{d.loc}: Film "{d.type}": not supported')
        p = _Params(d)
        self.scene.width = int(p.one("xresolution", 1280, ("integer",)))
        self.scene.height = int(p.one("yresolution", 720, ("integer",)))
        for k in ("filename", "savefp16", "diagonal"):
            p.get(k)
        p.default_only("iso", 100.0)
        p.default_only("exposuretime", 1.0)
        p.default_only("whitebalance", 0.0)
        p.finish()

    def _PixelFilter(self, d):
        p = _Params(d)
        rx, ry = p.one("xradius", None), p.one("yradius", None)
        if d.type == "box":
            if (rx or 0.5) != 0.5 or (ry or 0.5) != 0.5:
                p.fail("a box radius other than 0.5 has no Mitsuba twin")
            self.scene.rfilter, self.scene.filter_text = {"type": "box"}, "box (radius 0.5)"
        elif d.type == "triangle":
            r = rx or 2.0
            if (ry or 2.0) != r:
                p.fail("different x and y radii have no Mitsuba twin")
            self.scene.rfilter = {"type": "tent", "radius": ("float", float(r))}
            self.scene.filter_text = f"triangle radius {r:g} -> tent radius {r:g}"
        elif d.type == "gaussian":
            sigma, r = p.one("sigma", 0.5), rx or 1.5
            if (ry or 1.5) != r:
                p.fail("different x and y radii have no Mitsuba twin")
            self.scene.rfilter = {"type": "gaussian", "stddev": ("float", float(sigma))}
            self.scene.filter_text = (f"gaussian radius {r:g} sigma {sigma:g} -> gaussian stddev {sigma:g} "
                                      f"(Mitsuba's window: 4 stddev)")
        else:
            raise PbrtError(f'{d.loc}: PixelFilter "{d.type}": not supported')
        p.finish()

    def _Sampler(self, d):
        p = _Params(d)
        if d.type == "stratified":
            self.scene.spp = int(p.one("xsamples", 4, ("integer",))) * int(p.one("ysamples", 4, ("integer",)))
            p.get("jitter")
        elif d.type == "independent":
            self.scene.spp = int(p.one("pixelsamples", 4, ("integer",)))
        elif d.type in ("sobol", "zsobol", "paddedsobol", "halton", "pmj02bn"):
            self.scene.spp = int(p.one("pixelsamples", 16, ("integer",)))
            p.get("randomization")
        else:
            raise PbrtError(f'{d.loc}: Sampler "{d.type}": not supported')
        p.get("seed")
        p.finish()

    def _Integrator(self, d):
        if d.type not in ("path", "volpath"):
            raise PbrtError(f'{d.loc}: Integrator "{d.type}": not supported (supported: path, volpath)')
        p = _Params(d)
        self.scene.max_depth = int(p.one("maxdepth", 5, ("integer",)))
        if p.one("regularize", False, ("bool",)):
            p.fail("regularize true is not supported")
        p.get("lightsampler")  # noise only
        p.finish()

    # ---- spectra and textures ---------------------------------------------
    def _spectrum(self, p, name, use):
        """A spectrum parameter -> RGB list, or ("metal", "Cu", "eta") for a named metal."""
        q = p.get(name)
        if q is None:
            return None
        if q.type in ("rgb", "color"):
            if len(q.values) != 3:
                p.fail(f'"rgb {name}" must have 3 values')
            return [float(x) for x in q.values]
        if q.type == "blackbody":
            return blackbody_rgb(q.values[0])
        if q.type == "spectrum" and q.values and isinstance(q.values[0], str):
            s = q.values[0]
            if s in GLASS_IOR_550:
                return [GLASS_IOR_550[s]] * 3
            parts = s.split("-")
            if len(parts) == 3 and parts[0] == "metal" and parts[1] in PBRT_METAL_RGB and use == "ior":
                return ("metal", parts[1], parts[2])
            p.fail(f'"spectrum {name}" names {s!r}, which is not translated')
        if q.type == "float" and use == "ior":
            return [float(q.values[0])] * 3
        p.fail(f'"{q.type} {name}" is not translated (rgb, blackbody or a named spectrum)')

    def _float_value(self, p, name, default):
        """A float parameter or a float texture that is a constant -> float."""
        q = p.get(name)
        if q is None:
            return default
        if q.type == "texture":
            t = self.textures.get(("float", q.values[0]))
            if t is None:
                p.fail(f'"texture {name}" names no float texture {q.values[0]!r}')
            if t[0] != "const":
                p.fail(f'"texture {name}": only constant float textures are translated')
            return t[1]
        return float(p.one(name, default))

    def _spectrum_node(self, p, name, default):
        """A material's spectrum parameter or texture -> Mitsuba value node."""
        q = p.get(name)
        if q is not None and q.type == "texture":
            t = self.textures.get(("spectrum", q.values[0])) or self.textures.get(("float", q.values[0]))
            if t is None:
                p.fail(f'"texture {name}" names no texture {q.values[0]!r}')
            return ("rgb", [t[1]] * 3 if np.isscalar(t[1]) else t[1]) if t[0] == "const" else t[1]
        v = self._spectrum(p, name, "albedo")
        # pbrt-v4 clamps a reflectance to [0, 1]
        return ("rgb", [min(max(x, 0.0), 1.0) for x in v] if v is not None else [default] * 3)

    def _Texture(self, d):
        name, kind, cls = d.args
        if kind not in ("spectrum", "float", "color"):
            raise PbrtError(f"{d.loc}: Texture {name!r}: type {kind!r} not supported")
        kind = "float" if kind == "float" else "spectrum"
        p = _Params(d, self.s.defaults.get("texture"))

        def value(pname, default):  # a constant or a texture: ("const", v) or ("node", node)
            q = p.get(pname)
            if q is not None and q.type == "texture":
                t = self.textures.get((kind, q.values[0])) or self.textures.get(("float", q.values[0]))
                if t is None:
                    p.fail(f'"texture {pname}" names no texture {q.values[0]!r}')
                return t
            if kind == "float":
                return ("const", float(p.one(pname, default)))
            v = self._spectrum(p, pname, "albedo")
            return ("const", v if v is not None else [default] * 3)

        def mapping():
            m = p.one("mapping", "uv", ("string",))
            if m != "uv":
                p.fail("only the uv mapping is translated")
            return (p.one("uscale", 1.0), p.one("vscale", 1.0), p.one("udelta", 0.0), p.one("vdelta", 0.0))

        if cls == "constant":
            t = value("value", 1.0)
        elif cls == "scale":
            a, s = value("tex", 1.0), p.get("scale")
            sv = self._float_value(p, "scale", 1.0) if s is not None else 1.0
            if a[0] == "const":
                t = ("const", a[1] * sv if np.isscalar(a[1]) else [x * sv for x in a[1]])
            elif a[1]["type"] == "bitmap":  # an image times a constant: a scaled copy of the image
                t = ("node", self._scaled_bitmap(a[1], sv, name))
            else:
                p.fail("a scale of a procedural texture is not translated")
        elif cls == "checkerboard":
            su, sv, du, dv = mapping()
            if int(p.one("dimension", 2, ("integer",))) != 2:
                p.fail("only dimension 2 is translated")
            if kind == "float":
                p.fail("a float checkerboard is not translated")
            node = {"type": "checkerboard",
                    "to_uv": ("matrix3", np.array([[su / 2, 0, du / 2], [0, sv / 2, dv / 2], [0, 0, 1.0]]))}
            for key, pname, default in (("color0", "tex1", 1.0), ("color1", "tex2", 0.0)):
                c = value(pname, default)
                node[key] = ("rgb", c[1]) if c[0] == "const" else c[1]
            t = ("node", node)
        elif cls == "imagemap":
            if kind == "float":
                p.fail("float image textures are not translated")
            t = ("node", self._imagemap(p, name, mapping()))
        else:
            raise PbrtError(f"{d.loc}: Texture {name!r} class {cls!r}: not supported")
        p.finish()
        self.textures[(kind, name)] = t

    def _scaled_bitmap(self, node, factor, name):
        import mitsuba as mi
        img = np.array(mi.Bitmap(node["filename"][1]), dtype=np.float32) * factor
        out = self.work / f"tex_{name}.exr"
        write_exr(out, img)
        return dict(node, filename=("string", str(out)))

    def _imagemap(self, p, name, mapping):
        from PIL import Image
        fname = p.one("filename", None, ("string",))
        if fname is None:
            p.fail('has no "string filename"')
        path = Path(fname) if Path(fname).is_absolute() else self.base / fname
        enc = p.one("encoding", "sRGB", ("string",))
        wrap = p.one("wrap", "repeat", ("string",))
        if wrap not in ("repeat", "clamp"):
            p.fail(f"wrap {wrap!r} has no Mitsuba twin (repeat, clamp)")
        p.get("filter")
        p.get("maxanisotropy")
        scale, invert = float(p.one("scale", 1.0)), bool(p.one("invert", False, ("bool",)))
        if path.suffix.lower() == ".exr":
            import mitsuba as mi
            img = np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]
        else:
            im = Image.open(path)
            if im.mode not in ("RGB", "L", "RGBA"):
                p.fail(f"{path}: image mode {im.mode} not translated (8-bit images only)")
            img = np.asarray(im.convert("RGB"), dtype=np.float64) / 255.0
            if enc == "sRGB":
                img = np.where(img <= 0.04045, img / 12.92, ((img + 0.055) / 1.055) ** 2.4)
            elif enc.startswith("gamma "):
                img = img ** float(enc.split()[1])
            elif enc != "linear":
                p.fail(f"encoding {enc!r} not translated")
        img = img * scale
        if invert:
            img = np.maximum(0.0, 1.0 - img)
        out = self.work / f"tex_{name}.exr"
        write_exr(out, np.ascontiguousarray(img[::-1]).astype(np.float32))
        su, sv, du, dv = mapping
        return {"type": "bitmap", "filename": ("string", str(out)), "raw": ("boolean", True),
                "filter_type": ("string", "bilinear"), "wrap_mode": ("string", wrap),
                "to_uv": ("matrix3", np.array([[su, 0, du], [0, sv, dv], [0, 0, 1.0]]))}

    # ---- materials ------------------------------------------------------------
    def _alphas(self, p):
        r = self._float_value(p, "roughness", 0.0)
        u = self._float_value(p, "uroughness", r) if p.get("uroughness") else r
        v = self._float_value(p, "vroughness", r) if p.get("vroughness") else r
        if p.one("remaproughness", True, ("bool",)):
            u, v = math.sqrt(u), math.sqrt(v)
        return u, v

    def _metal(self, p, name, default):
        v = self._spectrum(p, name, "ior")
        if v is None:
            v = ("metal", "Cu", name)  # pbrt-v4's default conductor: copper
        return v

    def _material(self, d, mtype, p):
        for k in ("displacement", "normalmap"):
            if p.get(k) is not None:
                p.fail(f'"{k}" is not supported')
        if mtype == "diffuse":
            node = _twosided({"type": "diffuse", "reflectance": self._spectrum_node(p, "reflectance", 0.5)})
        elif mtype == "conductor":
            au, av = self._alphas(p)
            if p.get("reflectance") is not None:
                if p.get("eta") is not None or p.get("k") is not None:
                    p.fail("gives both reflectance and eta/k")
                r = self._spectrum(p, "reflectance", "albedo")
                r = [min(max(x, 0.0), 0.9999) for x in r]
                eta, k = [1.0] * 3, [2 * math.sqrt(x) / math.sqrt(1 - x) for x in r]
                node = {"eta": ("rgb", eta), "k": ("rgb", k)}
            else:
                eta, k = self._metal(p, "eta", "Cu"), self._metal(p, "k", "Cu")
                node = self._conductor_ior(p, eta, k)
            if max(au, av) < 1e-3:
                node["type"] = "conductor"
            else:
                node.update(type="roughconductor", distribution=("string", "ggx"),
                            sample_visible=("boolean", True), alpha_u=("float", au), alpha_v=("float", av))
            node = _twosided(dict(type=node.pop("type"), **node))
        elif mtype == "dielectric":
            eta = self._spectrum(p, "eta", "ior")
            eta = 1.5 if eta is None else eta[0]
            au, av = self._alphas(p)
            node = {"type": "dielectric", "int_ior": ("float", eta), "ext_ior": ("float", 1.0)}
            if max(au, av) >= 1e-3:
                node.update(type="roughdielectric", distribution=("string", "ggx"),
                            sample_visible=("boolean", True), alpha_u=("float", au), alpha_v=("float", av))
        else:
            raise PbrtError(f'{d.loc}: {d.name} "{mtype}": not supported (supported: diffuse, conductor, dielectric)')
        p.finish()
        self.n_mat += 1
        mid = f"mat{self.n_mat:02d}_{mtype}"
        self.scene.bsdfs[mid] = node
        return mid

    def _conductor_ior(self, p, eta, k):
        if isinstance(eta, tuple) or isinstance(k, tuple):
            if not (isinstance(eta, tuple) and isinstance(k, tuple) and eta[1] == k[1]):
                p.fail("a named metal's eta and k must name the same metal")
            metal = eta[1]
            if self.named_spectra == "mitsuba":
                if metal not in MITSUBA_METALS:
                    p.fail(f"Mitsuba has no preset for {metal!r} (use named spectra 'pbrt')")
                self.scene.notes.append(f"conductor {metal}: Mitsuba's preset material {metal!r}")
                return {"material": ("string", metal)}
            self.scene.notes.append(f"conductor {metal}: pbrt-v4's tables in mcrt's RGB conversion")
            e, kk = PBRT_METAL_RGB[metal]
            return {"eta": ("rgb", e), "k": ("rgb", kk)}
        return {"eta": ("rgb", eta), "k": ("rgb", k)}

    def _Material(self, d):
        self.s.material = self._material(d, d.type, _Params(d, self.s.defaults.get("material")))

    def _MakeNamedMaterial(self, d):
        p = _Params(d, self.s.defaults.get("material"))
        t = p.one("type", None, ("string",))
        if t is None:
            p.fail('has no "string type"')
        self.named[d.args[0]] = self._material(d, t, p)

    def _NamedMaterial(self, d):
        if d.args[0] not in self.named:
            raise PbrtError(f"{d.loc}: NamedMaterial: no material named {d.args[0]!r}")
        self.s.material = self.named[d.args[0]]

    def _AreaLightSource(self, d):
        if d.type != "diffuse":
            raise PbrtError(f'{d.loc}: AreaLightSource "{d.type}": not supported (supported: diffuse)')
        p = _Params(d, self.s.defaults.get("light"))
        L = self._spectrum(p, "L", "illuminant") or [1.0, 1.0, 1.0]
        s = float(p.one("scale", 1.0))
        two = bool(p.one("twosided", False, ("bool",)))
        for k in ("filename", "power"):
            if p.get(k) is not None:
                p.fail(f'"{k}" is not supported')
        p.finish()
        self.s.light = ([x * s for x in L], two)

    # ---- shapes ------------------------------------------------------------------
    def _Shape(self, d):
        p = _Params(d, self.s.defaults.get("shape"))
        a = p.get("alpha")
        if a is not None and a.values != [1.0]:
            p.fail('"alpha" (cut-outs) is not supported')
        ctm, flip_geo = self.s.ctm, self.s.reverse != _swaps_handedness(self.s.ctm)
        i = len(self.scene.shapes)
        if d.type in ("trianglemesh", "bilinearmesh", "plymesh"):
            mesh = self._mesh(d, p)
            p.finish()
            # Mitsuba's normal: cross(p1 - p0, p2 - p0) in world space, or the vertex
            # normals where given; pbrt-v4's: the same, reversed by ReverseOrientation
            # and by a mirroring CTM where there are no normals, and facing the
            # normals (themselves reversed by ReverseOrientation) where there are.
            flip = self.s.reverse if mesh.n is not None else flip_geo
            ply = self.work / f"shape{i:03d}_{d.type}.ply"
            write_ply(ply, mesh)
            self.scene.ply_files.append(ply)
            node = {"type": "ply", "filename": ("string", str(ply)), "to_world": ("matrix", ctm.copy())}
            if mesh.n is None:
                node["face_normals"] = ("boolean", True)
            wp = (ctm @ np.c_[mesh.p, np.ones(len(mesh.p))].T).T[:, :3]
            self.bbox += [wp.min(axis=0), wp.max(axis=0)]
            back_offset = (-self._mesh_normal(mesh, ctm) * (-1 if flip else 1)
                           if self.s.light is not None and self.s.light[1] else None)
        elif d.type == "sphere":
            r = float(p.one("radius", 1.0))
            for k, v in (("zmin", -r), ("zmax", r), ("phimax", 360.0)):
                p.default_only(k, v)
            p.finish()
            s = np.linalg.svd(ctm[:3, :3], compute_uv=False)
            if s.max() - s.min() > 1e-6 * s.max():
                p.fail("a sphere under a non-uniform scale is not supported")
            node = {"type": "sphere", "radius": ("float", r), "to_world": ("matrix", ctm.copy())}
            c, rw = ctm[:3, 3], r * s.max()
            self.bbox += [c - rw, c + rw]
            flip = flip_geo
            back_offset = None
        elif d.type == "disk":
            r, h = float(p.one("radius", 1.0)), float(p.one("height", 0.0))
            p.default_only("innerradius", 0.0)
            p.default_only("phimax", 360.0)
            p.finish()
            node = {"type": "disk", "to_world": ("matrix", ctm @ _translate([0, 0, h]) @ np.diag([r, r, 1.0, 1]))}
            flip = flip_geo
            n = np.linalg.inv(ctm[:3, :3]).T @ [0, 0, 1.0]
            back_offset = -(n / np.linalg.norm(n)) * (-1 if flip else 1)
            c, rw = (ctm @ [0, 0, h, 1.0])[:3], r * np.linalg.norm(ctm[:3, :3], 2)
            self.bbox += [c - rw, c + rw]
        else:
            raise PbrtError(f'{d.loc}: Shape "{d.type}": not supported '
                            "(supported: trianglemesh, plymesh, bilinearmesh, sphere, disk)")
        if flip:
            node["flip_normals"] = ("boolean", True)
        node["bsdf"] = ("ref", self.s.material)
        sid = f"shape{i:03d}_{d.type}"
        light = self.s.light
        if light is not None and any(x != 0 for x in light[0]):
            node["emitter"] = {"type": "area", "radiance": ("rgb", light[0])}
            if light[1]:
                if back_offset is None:
                    p.fail("a two-sided sphere light is not supported")
                self.pending_twosided.append((sid, node, back_offset))
        self.scene.shapes.append((sid, node))

    def _mesh(self, d, p):
        if d.type == "plymesh":
            f = p.one("filename", None, ("string",))
            if f is None:
                p.fail('has no "string filename"')
            if p.get("displacement") is not None:
                p.fail('"displacement" is not supported')
            p.default_only("edgelength", 1.0)
            return read_ply(Path(f) if Path(f).is_absolute() else self.base / f)
        P = p.get("P")
        if P is None or len(P.values) % 3:
            p.fail('needs "point3 P" (3 values per point)')
        pts = np.asarray(P.values, float).reshape(-1, 3)
        N = p.get("N")
        n = np.asarray(N.values, float).reshape(-1, 3) if N is not None else None
        if n is not None and len(n) != len(pts):
            p.fail("N must have one normal per point")
        uvp = p.get("uv") or p.get("st")
        uv = np.asarray(uvp.values, float).reshape(-1, 2) if uvp is not None else None
        if p.get("S") is not None:
            p.fail('"S" (shading tangents) is not supported')
        p.get("faceIndices")
        group = 3 if d.type == "trianglemesh" else 4
        I = p.get("indices")
        idx = (np.asarray(I.values, dtype=np.int64) if I is not None else
               np.arange(group) if len(pts) == group else None)
        if idx is None or len(idx) % group or (idx.size and (idx.min() < 0 or idx.max() >= len(pts))):
            p.fail(f'"indices": missing, not {group} per face, or out of range')
        idx = idx.reshape(-1, group)
        if group == 4:
            idx, auto_uv = bilinear_to_triangles(pts, idx, uv is not None, d.loc)
            uv = uv if uv is not None else auto_uv
        return Mesh(pts, idx, n, uv)

    @staticmethod
    def _mesh_normal(mesh, ctm):
        """The mean front normal of a (planar) mesh in world space, as Mitsuba orients it."""
        p = (ctm @ np.c_[mesh.p, np.ones(len(mesh.p))].T).T[:, :3]
        if mesh.n is not None:
            n = (np.linalg.inv(ctm[:3, :3]).T @ mesh.n.mean(axis=0))
        else:
            a, b, c = p[mesh.idx[:, 0]], p[mesh.idx[:, 1]], p[mesh.idx[:, 2]]
            n = np.cross(b - a, c - a).sum(axis=0)
        return n / np.linalg.norm(n)

    def _finish_twosided(self):
        """Two-sided lights: a flipped copy just behind each (Mitsuba's emitters are one-sided)."""
        if not self.pending_twosided:
            return
        extent = float(np.ptp(np.asarray(self.bbox), axis=0).max())
        for sid, node, back in self.pending_twosided:
            twin = dict(node)
            flip = not (node.get("flip_normals", ("boolean", False))[1])
            twin["flip_normals"] = ("boolean", flip)
            twin["to_world"] = ("matrix", _translate(back * 1e-5 * extent) @ node["to_world"][1])
            self.scene.shapes.append((sid + "_back", twin))
            self.scene.notes.append(f"{sid}: a two-sided light, as two one-sided copies 1e-5 of the "
                                    f"scene's size apart")


def _twosided(bsdf):
    return {"type": "twosided", "bsdf": bsdf}


def blackbody_rgb(kelvin):
    """Planck's law through the CIE 1931 matching functions (Mitsuba's tables),
    to linear sRGB, normalised to luminance 1 (pbrt-v4's scale for an L)."""
    import mitsuba as mi
    c, h, kb = 299792458.0, 6.62606957e-34, 1.3806488e-23
    xyz = np.zeros(3)
    for lam in np.arange(360.5, 830.0, 1.0):
        l = lam * 1e-9
        b = 2 * h * c * c / (l ** 5 * (math.exp(h * c / (l * kb * kelvin)) - 1))
        xyz += b * np.array(mi.cie1931_xyz(float(lam)), dtype=float).reshape(3)
    xyz /= xyz[1]
    m = np.array([[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560],
                  [0.0556434, -0.2040259, 1.0572252]])
    return [float(x) for x in m @ xyz]


def write_exr(path, arr):
    import mitsuba as mi
    mi.Bitmap(np.ascontiguousarray(arr, dtype=np.float32)).write(str(path))


def translate(path, work_dir, named_spectra="mitsuba"):
    return Translator(path, work_dir, named_spectra).run()
