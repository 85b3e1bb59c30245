"""Input files built by hand: the tiny base scenes, PNG, PFM, EXR and PLY
writers, gzip members and the cached gzip bomb.

Everything here is standard library only and deterministic.
"""

from __future__ import annotations

import functools
import gzip
import json
import struct
import zlib
from pathlib import Path

# The repository (this file is tests/mcrt_fuzz/artifacts.py).
REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"

# --------------------------------------------------------------------------
# The base pbrt-v4 scene: a camera, a one-sided quad light facing down and a
# floor.  It renders in well under a second at 8x8, 1 spp.  The parts are
# kept apart so that a case can vary one of them.

CAMERA = 'LookAt 0 1 -4  0 0.5 0  0 1 0\nCamera "perspective" "float fov" [ 45 ]\n'
OPTIONS = ('Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]\n'
           'Sampler "independent" "integer pixelsamples" [ 1 ]\n'
           'Integrator "path" "integer maxdepth" [ 3 ]\n')
LIGHT_MESH = ('Shape "trianglemesh" "point3 P" [ -1 2 -1  1 2 -1  1 2 1  -1 2 1 ]'
              ' "integer indices" [ 0 1 2  0 2 3 ]\n')
LIGHT = ('AttributeBegin\n'
         '  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]\n'
         '  ' + LIGHT_MESH +
         'AttributeEnd\n')
FLOOR = ('Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]\n'
         'Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ]'
         ' "integer indices" [ 0 1 2  0 2 3 ]\n')
WORLD = LIGHT + FLOOR


def pbrt_scene(*, head: str = "", camera: str = CAMERA, options: str = OPTIONS,
               world_head: str = "", light: str = LIGHT, floor: str = FLOOR,
               world_tail: str = "") -> str:
    """The base scene with any part replaced or extended."""
    return (head + camera + options + "WorldBegin\n" + world_head + light + floor
            + world_tail)


BASE_PBRT = pbrt_scene()


def light_with(params: str, shape: str = LIGHT_MESH) -> str:
    """The base light with other AreaLightSource parameters."""
    return ('AttributeBegin\n  AreaLightSource "diffuse" ' + params + '\n  ' + shape
            + 'AttributeEnd\n')


def tri_mesh(points: list[float], indices: list[int], extra: str = "") -> str:
    """A Shape "trianglemesh" line."""
    p = " ".join(_num(v) for v in points)
    i = " ".join(str(v) for v in indices)
    return f'Shape "trianglemesh" "point3 P" [ {p} ] "integer indices" [ {i} ]{extra}\n'


def _num(v) -> str:
    return v if isinstance(v, str) else repr(v)


# --------------------------------------------------------------------------
# The base JSON scene (scene-format.md): a floor and a rectangle light.

def json_scene_obj() -> dict:
    return {
        "camera": {"lookfrom": [0, 1, -4], "lookat": [0, 0.5, 0], "vup": [0, 1, 0],
                   "vfov": 45, "width": 8, "height": 8},
        "render": {"spp": 1, "max_depth": 3, "background": [0, 0, 0]},
        "materials": {
            "white": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]},
            "light": {"type": "diffuse_light", "emit": [1, 1, 1]},
        },
        "objects": [
            {"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"},
            {"type": "xz_rect", "x0": -1, "x1": 1, "z0": -1, "z1": 1, "k": 2, "material": "light",
             "flip": True},
            {"type": "sphere", "center": [0.5, 0.3, 0], "radius": 0.3, "material": "white"},
        ],
    }


def json_text(obj) -> str:
    return json.dumps(obj, indent=1)


BASE_JSON = json_text(json_scene_obj())

# --------------------------------------------------------------------------
# Images


def png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png(width: int, height: int, *, color_type: int = 2, bit_depth: int = 8,
        pixel: bytes | None = None) -> bytes:
    """A valid PNG filled with one pixel value (raw bytes of one pixel)."""
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color_type]
    bpp = channels * bit_depth // 8
    if pixel is None:
        pixel = b"\x80" * bpp
    row = b"\x00" + pixel * width
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0)
    return (PNG_SIGNATURE + png_chunk(b"IHDR", ihdr)
            + png_chunk(b"IDAT", zlib.compress(row * height)) + png_chunk(b"IEND", b""))


def png_lying_size(width: int, height: int) -> bytes:
    """A valid 1x1 PNG whose IHDR then claims width x height (CRC fixed)."""
    good = png(1, 1)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    start = len(PNG_SIGNATURE)
    end = start + 8 + 13 + 4
    return good[:start] + png_chunk(b"IHDR", ihdr) + good[end:]


def pfm(width: int, height: int, texels: list[float], channels: int = 3) -> bytes:
    """A PFM image (little-endian floats; rows bottom to top)."""
    tag = b"PF" if channels == 3 else b"Pf"
    vals = [texels[i % len(texels)] for i in range(width * height * channels)]
    return tag + f"\n{width} {height}\n-1.0\n".encode() + struct.pack(f"<{len(vals)}f", *vals)


def exr(width: int, height: int, texels: list[float]) -> bytes:
    """A minimal scanline OpenEXR (no compression, float B, G, R channels),
    the texels repeated over the image."""
    def attr(name: str, kind: str, value: bytes) -> bytes:
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chans = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (struct.pack("<I", 20000630) + struct.pack("<I", 2)
              + attr("channels", "chlist", chans)
              + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box)
              + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"\0")
    n = width * height * 3
    vals = [texels[i % len(texels)] for i in range(n)]
    lines = []
    for y in range(height):
        row = vals[y * width * 3:(y + 1) * width * 3]
        r, g, b = row[0::3], row[1::3], row[2::3]
        data = struct.pack(f"<{width}f", *b) + struct.pack(f"<{width}f", *g) + struct.pack(f"<{width}f", *r)
        lines.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * height
    table = b""
    for line in lines:
        table += struct.pack("<Q", offset)
        offset += len(line)
    return header + table + b"".join(lines)


@functools.lru_cache(maxsize=None)
def checker_png() -> bytes:
    return (SCENES / "pbrt" / "features" / "checker.png").read_bytes()


# --------------------------------------------------------------------------
# PLY

def ply_ascii(vertices: list[tuple], faces: list[tuple], props: str = "x y z",
              face_prop: str = "property list uchar int vertex_indices") -> bytes:
    """An ASCII PLY; ``props`` names the float vertex properties in order."""
    names = props.split()
    head = ["ply", "format ascii 1.0", f"element vertex {len(vertices)}"]
    head += [f"property float {n}" for n in names]
    head += [f"element face {len(faces)}", face_prop, "end_header"]
    body = [" ".join(_num(v) for v in vert) for vert in vertices]
    body += [" ".join(str(x) for x in (len(f), *f)) for f in faces]
    return ("\n".join(head + body) + "\n").encode()


def ply_binary(vertices: list[tuple], faces: list[tuple], props: str = "x y z",
               big_endian: bool = False, label: str | None = None) -> bytes:
    """A binary PLY (float vertex properties, uchar/int face lists).
    ``label`` overrides the format line's name (to lie about it)."""
    names = props.split()
    e = ">" if big_endian else "<"
    fmt = label or ("binary_big_endian" if big_endian else "binary_little_endian")
    head = ["ply", f"format {fmt} 1.0", f"element vertex {len(vertices)}"]
    head += [f"property float {n}" for n in names]
    head += [f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header"]
    body = b"".join(struct.pack(f"{e}{len(v)}f", *v) for v in vertices)
    body += b"".join(struct.pack(f"{e}B{len(f)}i", len(f), *f) for f in faces)
    return ("\n".join(head) + "\n").encode() + body


# A unit quad at y = 0 facing up, as two triangles.
QUAD_V = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]
QUAD_F = [(0, 2, 1), (0, 3, 2)]


def ply_shape(name: str) -> str:
    return f'Shape "plymesh" "string filename" "{name}"\n'


# --------------------------------------------------------------------------
# gzip

def gz(data: bytes | str) -> bytes:
    """One gzip member, with a fixed mtime so the bytes are reproducible."""
    if isinstance(data, str):
        data = data.encode()
    return gzip.compress(data, compresslevel=6, mtime=0)


BOMB_MEMBER_BYTES = 64 << 20


@functools.lru_cache(maxsize=None)
def zero_member() -> bytes:
    """64 MiB of zeros as one gzip member, compressed once per run (~65 kB)."""
    return gzip.compress(bytes(BOMB_MEMBER_BYTES), compresslevel=9, mtime=0)


def gz_bomb(prefix: bytes | str = b"", gib: float = 3.2) -> bytes:
    """A gzip stream of ``prefix`` followed by ``gib`` GiB of zeros, made of
    concatenated members (zlib and gzip read them as one stream)."""
    n = int(gib * (1 << 30)) // BOMB_MEMBER_BYTES + 1
    head = gz(prefix) if prefix else b""
    return head + zero_member() * n
