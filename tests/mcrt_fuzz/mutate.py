"""Random mutations of the shipped scenes.

Case ``mutate/<scene>/<n>`` takes shipped scene number ``n mod S`` (the
.pbrt files under scenes/pbrt and scenes/*.json), copies it and every file
it refers to into the case directory (relative paths kept), and applies 1-4
operators drawn from the case's own random stream (``case_rng``: a hash of
the run's seed and the id), so any case is rebuilt from (seed, id) alone.

Operators
  pbrt text (crude tokens: strings, brackets, words, comments):
    number -> an interesting value, number x 10^k, delete / duplicate a
    token, delete / duplicate / swap lines, insert a directive from a
    dictionary of valid pbrt-v4 snippets, change a string to another known
    name, truncate, flip bytes
  JSON: number -> an interesting value (written raw: 1e39, -0, 1e999, a
    400-digit integer, ...), delete a key, change a value's type, duplicate
    a key, change a string to another known name, truncate, flip bytes
  binary (PLY, PNG, .gz): flip bits, truncate, zero a span, duplicate a
    span; PLY headers also get their numbers replaced; a .gz is mutated
    either as it is or decompressed, mutated and compressed again
Each mutant renders at 8x8, 1 spp, one thread, with --light-sampling,
--light-select, --integrator and --sampler sometimes chosen at random.
Any ok class is expected.
"""

from __future__ import annotations

import functools
import gzip
import json
import re
import zlib
from pathlib import Path

from . import artifacts as A
from .cases import INTEGRATORS, LIGHT_SAMPLINGS, LIGHT_SELECTS, SAMPLERS
from .model import RENDER_FLAGS, Case, case_rng, file

INTERESTING = ["0", "-0", "-1", "1", "1e-45", "1e-38", "1e38", "3.4028235e38", "1e39", "1e300", "2147483648",
               "-2147483649", "4294967296", "1e-300", "nan", "inf", "-inf", "0x10", "1" + "7" * 399,
               "0.5", "16384", "16385", "1048577", "-1e38", "1e-7"]

# Valid pbrt-v4 snippets, inserted at random lines.
SNIPPETS = [
    "AttributeBegin", "AttributeEnd", "TransformBegin", "TransformEnd", "Identity", "ReverseOrientation",
    "Translate 1 2 3", "Scale 2 2 2", "Scale -1 1 1", "Scale 0 0 0", "Rotate 45 0 1 0", "Rotate 90 1 0 0",
    "LookAt 0 0 -5  0 0 0  0 1 0", "CoordinateSystem \"mine\"", "CoordSysTransform \"mine\"",
    "CoordSysTransform \"camera\"", "Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 ]",
    "ConcatTransform [ 2 0 0 0  0 2 0 0  0 0 2 0  1 1 1 1 ]", "WorldBegin", "WorldEnd",
    "Camera \"perspective\" \"float fov\" 30", "Camera \"perspective\" \"float lensradius\" 0.1",
    "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16",
    "Film \"gbuffer\" \"string filename\" \"x.exr\"", "Sampler \"halton\" \"integer pixelsamples\" 4",
    "Sampler \"stratified\" \"integer xsamples\" 2 \"integer ysamples\" 2", "Integrator \"volpath\" \"integer maxdepth\" 2",
    "Integrator \"path\" \"string lightsampler\" \"power\"", "Integrator \"bdpt\"",
    "Integrator \"sppm\" \"float radius\" 0.1", "Integrator \"mlt\"", "Integrator \"simplepath\"", "Integrator \"randomwalk\"",
    "PixelFilter \"gaussian\" \"float xradius\" 2", "PixelFilter \"triangle\"", "PixelFilter \"box\"",
    "ColorSpace \"srgb\"", "Option \"string rendercoordsys\" \"world\"", "Option \"integer seed\" 7",
    "Accelerator \"bvh\"", "MediumInterface \"\" \"\"", "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"",
    "Material \"diffuse\" \"rgb reflectance\" [ 0.2 0.4 0.6 ]", "Material \"conductor\" \"float roughness\" 0.1",
    "Material \"dielectric\" \"float eta\" 1.33", "Material \"coateddiffuse\"",
    "Material \"coateddiffuse\" \"rgb albedo\" [ 0.5 0.5 0.5 ] \"float g\" 0.5 \"float thickness\" 0.2",
    "Material \"coatedconductor\" \"float interface.roughness\" 0.1 \"float conductor.roughness\" 0.3",
    "Material \"mix\" \"string materials\" [ \"m\" \"m\" ] \"float amount\" 0.3",
    "Material \"diffusetransmission\" \"rgb transmittance\" [ 0.5 0.5 0.5 ]", "Material \"thindielectric\"", "Material \"interface\"",
    "MakeNamedMaterial \"m\" \"string type\" \"diffuse\"", "NamedMaterial \"m\"",
    "Texture \"tx\" \"spectrum\" \"checkerboard\" \"float uscale\" 4",
    "Texture \"tf\" \"float\" \"constant\" \"float value\" 0.5",
    "Texture \"ti\" \"spectrum\" \"imagemap\" \"string filename\" \"checker.png\"",
    "Material \"diffuse\" \"texture reflectance\" \"tx\"",
    "AreaLightSource \"diffuse\" \"rgb L\" [ 4 4 4 ]", "AreaLightSource \"diffuse\" \"blackbody L\" 3000",
    "AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ] \"bool twosided\" true",
    "AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 1 ] \"float scale\" -1",
    "LightSource \"point\" \"rgb I\" [ 1 1 1 ]", "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]",
    "Shape \"sphere\" \"float radius\" 0.5", "Shape \"disk\" \"float radius\" 1 \"float height\" 0.1",
    "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"integer indices\" [ 0 1 2 ]",
    "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"normal N\" [ 0 0 1  0 0 1  0 0 1 ]"
    " \"point2 uv\" [ 0 0  1 0  0 1 ] \"integer indices\" [ 0 1 2 ]",
    "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ]",
    "Shape \"plymesh\" \"string filename\" \"floor.ply\"", "Shape \"plymesh\" \"string filename\" \"torus.ply.gz\"",
    "Shape \"loopsubdiv\"", "ObjectBegin \"o\"", "ObjectEnd", "ObjectInstance \"o\"",
    "Include \"unit_cube.pbrt\"", "Import \"unit_cube.pbrt\"",
    "Attribute \"shape\" \"float radius\" 2", "Attribute \"light\" \"float scale\" 0",
    "Attribute \"material\" \"float roughness\" 0.5",
]

# Names a string token may become.
NAMES = [
    "trianglemesh", "plymesh", "bilinearmesh", "sphere", "disk", "cylinder", "curve", "loopsubdiv",
    "diffuse", "conductor", "dielectric", "diffusetransmission", "coateddiffuse", "coatedconductor", "mix", "interface",
    "thindielectric", "subsurface", "measured", "hair",
    "imagemap", "constant", "scale", "checkerboard", "ptex", "spectrum", "float",
    "perspective", "orthographic", "realistic", "rgb", "gbuffer", "spectral",
    "independent", "stratified", "sobol", "zsobol", "halton", "pmj02bn", "path", "volpath", "bdpt", "sppm",
    "mlt", "simplepath", "simplevolpath", "randomwalk", "lightpath", "ambientocclusion",
    "box", "gaussian", "triangle", "mitchell", "bvh", "power", "uniform",
    "float radius", "float fov", "integer indices", "point3 P", "normal N", "point2 uv", "rgb L", "rgb reflectance",
    "blackbody L", "spectrum eta", "spectrum k", "texture reflectance", "rgb transmittance",
    "texture roughness", "string filename",
    "bool twosided", "float scale", "integer xresolution", "integer pixelsamples", "integer maxdepth",
    "float roughness", "float eta", "float thickness", "rgb albedo", "float g", "integer nsamples",
    "float interface.roughness", "float conductor.roughness", "string materials", "float amount", "spectrum conductor.eta", "string encoding", "string wrap", "float uscale", "vector3 S",
    "metal-Au-eta", "metal-Cu-k", "glass-BK7", "stdillum-D65", "srgb", "linear", "gamma 2.2",
    "floor.ply", "icosphere.ply", "torus.ply.gz", "checker.png", "unit_cube.pbrt", "missing.ply", "",
    "floor", "wall", "glass", "gold", "copper", "checks", "stripes", "bumpy",
]

JSON_NAMES = ["lambertian", "metal", "dielectric", "diffuse_light", "xz_rect", "xy_rect", "yz_rect", "xz_rect_sa",
              "rect", "rect_sa", "ellipse", "ellipse_sa", "sphere", "box", "area", "solid-angle",
              "projected-solid-angle", "auto", "white", "light", "red", "green", "glass", "", "nope"]

TOKEN = re.compile(r'"[^"\n]*"?|#[^\n]*|\[|\]|[^\s\[\]"#]+')
NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


# --------------------------------------------------------------------------
# The shipped scenes and the files they refer to


# How many slots of the cycle each scene takes: pbrt files more than JSON
# ones, the feature scene (PLY, .ply.gz, PNG) most.
WEIGHTS = {"pbrt-features": 3, "pbrt-unit_cube": 1, "pbrt": 2, "json": 1}


@functools.lru_cache(maxsize=None)
def shipped() -> list[tuple[str, Path, list[str]]]:
    """The cycle of (key, top-level file, referenced files relative to it):
    mutation n takes entry n mod its length."""
    scenes = []
    for top in sorted((A.SCENES / "pbrt").rglob("*.pbrt")):
        key = "pbrt-" + (top.stem if top.parent == A.SCENES / "pbrt" else top.parent.name)
        scenes.append((key, top, referenced(top)))
    for top in sorted(A.SCENES.glob("*.json")):
        scenes.append(("json-" + top.stem, top, []))
    cycle = []
    for rnd in range(max(WEIGHTS.values())):
        for key, top, refs in scenes:
            if rnd < WEIGHTS.get(key, WEIGHTS[key.split("-")[0]]):
                cycle.append((key, top, refs))
    return cycle


def referenced(top: Path) -> list[str]:
    """Every existing file a pbrt scene names (recursively through Includes)."""
    seen: list[str] = []
    todo = [top]
    while todo:
        text = todo.pop().read_text("utf-8", "replace")
        for name in re.findall(r'"([^"\s]+\.(?:pbrt|ply|gz|png|exr|pfm|tga|spd))"', text):
            p = top.parent / name
            if name not in seen and p.is_file():
                seen.append(name)
                if name.endswith(".pbrt"):
                    todo.append(p)
    return seen


# --------------------------------------------------------------------------
# Operators


def _spans(text: str, numbers_only=False, strings_only=False):
    out = []
    for m in TOKEN.finditer(text):
        t = m.group()
        if t.startswith("#"):
            continue
        if numbers_only and not NUMBER.match(t):
            continue
        if strings_only and not t.startswith('"'):
            continue
        out.append((m.start(), m.end(), t))
    return out


def _replace(text, span, new):
    return text[:span[0]] + new + text[span[1]:]


def op_number_interesting(rng, text):
    spans = _spans(text, numbers_only=True)
    if not spans:
        return text, None
    s = rng.choice(spans)
    v = rng.choice(INTERESTING)
    return _replace(text, s, v), f"number {s[2]} -> {v[:20]}"


def op_number_scale(rng, text):
    spans = _spans(text, numbers_only=True)
    if not spans:
        return text, None
    s = rng.choice(spans)
    # Mostly moderate factors (the scene stays valid), sometimes extreme ones.
    k = rng.randint(-12, 12) if rng.random() < 0.8 else rng.randint(-45, 45)
    try:
        v = "%.9g" % (float(s[2]) * 10.0 ** k)
    except OverflowError:
        v = "1e999"
    return _replace(text, s, v), f"number {s[2]} x 1e{k}"


def op_token_delete(rng, text):
    spans = _spans(text)
    if not spans:
        return text, None
    s = rng.choice(spans)
    return _replace(text, s, ""), f"delete token {s[2][:30]}"


def op_token_duplicate(rng, text):
    spans = _spans(text)
    if not spans:
        return text, None
    s = rng.choice(spans)
    return _replace(text, s, s[2] + " " + s[2]), f"duplicate token {s[2][:30]}"


def op_line_delete(rng, text):
    lines = text.split("\n")
    i = rng.randrange(len(lines))
    del lines[i]
    return "\n".join(lines), f"delete line {i + 1}"


def op_line_duplicate(rng, text):
    lines = text.split("\n")
    i = rng.randrange(len(lines))
    lines.insert(i, lines[i])
    return "\n".join(lines), f"duplicate line {i + 1}"


def op_line_swap(rng, text):
    lines = text.split("\n")
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines), f"swap lines {i + 1} and {j + 1}"


def op_insert_snippet(rng, text):
    lines = text.split("\n")
    i = rng.randrange(len(lines) + 1)
    s = rng.choice(SNIPPETS)
    lines.insert(i, s)
    return "\n".join(lines), f"insert at line {i + 1}: {s[:40]}"


def op_string_swap(rng, text):
    spans = _spans(text, strings_only=True)
    if not spans:
        return text, None
    s = rng.choice(spans)
    v = rng.choice(NAMES)
    return _replace(text, s, f'"{v}"'), f"string {s[2][:30]} -> \"{v}\""


def op_truncate(rng, data):
    if not data:
        return data, None
    n = rng.randrange(len(data))
    return data[:n], f"truncate at {n}"


def op_flip_bytes(rng, data: bytes):
    if not data:
        return data, None
    b = bytearray(data)
    k = rng.randint(1, 8)
    for _ in range(k):
        i = rng.randrange(len(b))
        b[i] ^= rng.randint(1, 255)
    return bytes(b), f"flip {k} bytes"


def op_flip_bits(rng, data: bytes):
    if not data:
        return data, None
    b = bytearray(data)
    k = rng.randint(1, 16)
    for _ in range(k):
        i = rng.randrange(len(b))
        b[i] ^= 1 << rng.randrange(8)
    return bytes(b), f"flip {k} bits"


def op_zero_span(rng, data: bytes):
    if not data:
        return data, None
    i = rng.randrange(len(data))
    n = rng.randint(1, min(256, len(data) - i))
    return data[:i] + bytes(n) + data[i + n:], f"zero {n} bytes at {i}"


def op_duplicate_span(rng, data: bytes):
    if not data:
        return data, None
    i = rng.randrange(len(data))
    n = rng.randint(1, min(512, len(data) - i))
    return data[:i + n] + data[i:i + n] + data[i + n:], f"duplicate {n} bytes at {i}"


def op_ply_header_number(rng, data: bytes):
    end = data.find(b"end_header")
    if end < 0:
        return data, None
    head = data[:end].decode("latin-1")
    spans = [m for m in re.finditer(r"(?<=\s)\d+(?=\s)", head)]
    if not spans:
        return data, None
    m = rng.choice(spans)
    v = rng.choice(["0", "1", "2", "3", "-1", "4294967296", "1000000000000000000", "2147483647", "65536",
                    str(int(m.group()) + 1), str(int(m.group()) * 1000)])
    return (head[:m.start()] + v + head[m.end():]).encode("latin-1") + data[end:], f"PLY header {m.group()} -> {v}"


def op_ply_header_word(rng, data: bytes):
    end = data.find(b"end_header")
    if end < 0:
        return data, None
    head = data[:end].decode("latin-1")
    words = [m for m in re.finditer(r"\b(float|uchar|int|uint|ascii|binary_little_endian|binary_big_endian|"
                                    r"vertex|face|x|y|z|nx|u|v|vertex_indices|list)\b", head)]
    if not words:
        return data, None
    m = rng.choice(words)
    v = rng.choice(["float", "double", "uchar", "char", "int", "uint", "short", "int8", "float64", "ascii",
                    "binary_little_endian", "binary_big_endian", "vertex", "face", "x", "nx", "u", "s",
                    "vertex_indices", "list", "bogus"])
    return (head[:m.start()] + v + head[m.end():]).encode("latin-1") + data[end:], f"PLY header {m.group()} -> {v}"


PBRT_TEXT_OPS = [(op_number_interesting, 5), (op_number_scale, 3), (op_token_delete, 2), (op_token_duplicate, 2),
                 (op_line_delete, 2), (op_line_duplicate, 1), (op_line_swap, 1), (op_insert_snippet, 4),
                 (op_string_swap, 3)]
BYTE_OPS = [(op_truncate, 1), (op_flip_bytes, 1)]
BINARY_OPS = [(op_flip_bits, 3), (op_truncate, 1), (op_zero_span, 2), (op_duplicate_span, 2)]
PLY_OPS = BINARY_OPS + [(op_ply_header_number, 3), (op_ply_header_word, 2)]


def _pick(rng, ops):
    total = sum(w for _, w in ops)
    x = rng.uniform(0, total)
    for op, w in ops:
        x -= w
        if x <= 0:
            return op
    return ops[-1][0]


# JSON ------------------------------------------------------------------------

def _json_paths(obj, path=()):
    """Every (path, value) in a JSON document."""
    yield path, obj
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _json_paths(v, path + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _json_paths(v, path + (i,))


def _json_set(obj, path, value):
    for p in path[:-1]:
        obj = obj[p]
    if value is _DELETE:
        del obj[path[-1]]
    else:
        obj[path[-1]] = value


_DELETE = object()


def op_json_structural(rng, data: bytes):
    try:
        obj = json.loads(data)
    except ValueError:
        return op_flip_bytes(rng, data)
    paths = [(p, v) for p, v in _json_paths(obj) if p]
    if not paths:
        return op_truncate(rng, data)
    kind = rng.choice(["number", "number", "number", "delete", "type", "string", "dupkey"])
    raw = None
    if kind == "number":
        nums = [(p, v) for p, v in paths if isinstance(v, (int, float)) and not isinstance(v, bool)]
        if not nums:
            kind = "type"
        else:
            p, v = rng.choice(nums)
            raw = rng.choice(INTERESTING[:15] + ["1e999", "-1e999", "1" + "0" * 400, "1e-400", "0.5", "-0.0"])
            if raw in ("nan", "inf", "-inf", "0x10"):
                raw = {"nan": "NaN", "inf": "Infinity", "-inf": "-Infinity", "0x10": "0x10"}[raw]
            _json_set(obj, p, "@@RAW@@")
            what = f"{'.'.join(map(str, p))}: {v} -> {raw[:20]}"
    if kind == "delete":
        p, _ = rng.choice(paths)
        _json_set(obj, p, _DELETE)
        what = f"delete {'.'.join(map(str, p))}"
    elif kind == "type":
        p, v = rng.choice(paths)
        new = rng.choice([None, True, "text", [], {}, 0, [1, 2], {"a": 1}, [0, 0, 0], -1])
        _json_set(obj, p, new)
        what = f"{'.'.join(map(str, p))} -> {json.dumps(new)}"
    elif kind == "string":
        strs = [(p, v) for p, v in paths if isinstance(v, str)]
        if not strs:
            return op_truncate(rng, data)
        p, v = rng.choice(strs)
        new = rng.choice(JSON_NAMES)
        _json_set(obj, p, new)
        what = f"{'.'.join(map(str, p))}: {v} -> {new}"
    text = json.dumps(obj, indent=1)
    if raw is not None:
        text = text.replace('"@@RAW@@"', raw)
    if kind == "dupkey":
        keys = list(re.finditer(r'"(\w+)": ', text))
        if not keys:
            return text.encode(), None
        m = rng.choice(keys)
        text = text[:m.start()] + f'"{m.group(1)}": 0, ' + text[m.start():]
        what = f"duplicate key {m.group(1)}"
    return text.encode(), what


JSON_OPS = [(op_json_structural, 16), (op_truncate, 1), (op_flip_bytes, 1)]


# --------------------------------------------------------------------------
# Applying operators to a file


def mutate_file(rng, name: str, data: bytes) -> tuple[bytes, str | None]:
    if name.endswith(".gz"):
        if rng.random() < 0.5:
            return _apply(rng, BINARY_OPS, data)
        try:
            inner = gzip.decompress(data)
        except (OSError, EOFError, zlib.error):
            return _apply(rng, BINARY_OPS, data)
        new, what = mutate_file(rng, name[:-3], inner)
        return A.gz(new), (what and f"inside the gzip: {what}")
    if name.endswith(".pbrt"):
        if rng.random() < 0.06:
            return _apply(rng, BYTE_OPS, data)
        text = data.decode("utf-8", "surrogateescape")
        new, what = _pick(rng, PBRT_TEXT_OPS)(rng, text)
        return new.encode("utf-8", "surrogateescape"), what
    if name.endswith(".json"):
        return _apply(rng, JSON_OPS, data)
    if name.endswith(".ply"):
        return _apply(rng, PLY_OPS, data)
    return _apply(rng, BINARY_OPS, data)


def _apply(rng, ops, data):
    return _pick(rng, ops)(rng, data)


def mutation_ids(count: int) -> list[str]:
    scenes = shipped()
    return [f"mutate/{scenes[i % len(scenes)][0]}/{i:05d}" for i in range(count)]


ID_RE = re.compile(r"^mutate/([^/]+)/(\d+)$")


def mutation_case(seed: int, case_id: str) -> Case:
    """Build one mutation case from (seed, id) alone."""
    m = ID_RE.match(case_id)
    if not m:
        raise ValueError(f"not a mutation id: {case_id}")
    scenes = shipped()
    key, top, refs = scenes[int(m.group(2)) % len(scenes)]
    if key != m.group(1):
        raise ValueError(f"{case_id}: mutation {m.group(2)} is of scene {key}")
    rng = case_rng(seed, case_id)
    contents = {top.name: top.read_bytes(), **{r: (top.parent / r).read_bytes() for r in refs}}
    ops = []
    for _ in range(rng.choice((1, 1, 1, 2, 2, 3, 4))):  # 1-4 operators, mostly few
        target = top.name if not refs or rng.random() < 0.75 else rng.choice(refs)
        contents[target], what = mutate_file(rng, target, contents[target])
        if what:
            ops.append(f"{target}: {what}")
    extra = []
    if rng.random() < 0.35:
        extra += ["--light-sampling", rng.choice(LIGHT_SAMPLINGS)]
    if rng.random() < 0.35:
        extra += ["--light-select", rng.choice(LIGHT_SELECTS)]
    if rng.random() < 0.35:
        extra += ["--integrator", rng.choice(INTEGRATORS)]
    if rng.random() < 0.35:
        extra += ["--sampler", rng.choice(SAMPLERS)]
    argv = ["render", top.name, "-o", "out.png", *RENDER_FLAGS, "--stats", "stats.json", *extra]
    return Case(case_id, [file(n, d) for n, d in contents.items()], argv, kind="render",
                outputs=["out.png", "stats.json"], image="out.png", stats="stats.json",
                names=[top.name, *refs], note="; ".join(ops)[:300])


def mutation_cases(seed: int, count: int) -> list[Case]:
    """Cases are built lazily by the runner (contents read at build time are small)."""
    return [mutation_case(seed, i) for i in mutation_ids(count)]
