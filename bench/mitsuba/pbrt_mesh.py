"""Meshes of a pbrt-v4 file as triangle PLY files for Mitsuba's `ply` shape.

Mitsuba 3.9.1's PLY loader takes triangles only, so every mesh (the file's
`trianglemesh` and `bilinearmesh`, and `plymesh` files, which may hold quads
and may be gzip-compressed) is read here and written again as a binary
little-endian triangle PLY in object space; the shape's `to_world` is the CTM.

pbrt-v4's rules kept here:
- a PLY quad v0 v1 v2 v3 is the bilinear patch v0 v1 v3 v2: for a planar
  convex quad that is the triangles (v0, v1, v2) and (v0, v2, v3);
- a bilinear patch p00 p10 p01 p11 is the triangles (p00, p10, p11) and
  (p00, p11, p01), with uv (0,0) (1,0) (0,1) (1,1) where the mesh has none;
  a patch that is not planar is refused (as mcrt refuses it).
"""
import gzip
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .pbrt_parse import PbrtError


@dataclass
class Mesh:
    p: np.ndarray            # (n, 3) float
    idx: np.ndarray          # (m, 3) int
    n: np.ndarray = None     # (n, 3) or None
    uv: np.ndarray = None    # (n, 2) or None


_PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
              "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
              "float": "f", "float32": "f", "double": "d", "float64": "d"}


def read_ply(path):
    """A PLY file (ASCII, binary little- or big-endian, .gz) -> Mesh (quads split)."""
    raw = Path(path).read_bytes()
    if str(path).endswith(".gz"):
        raw = gzip.decompress(raw)
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise PbrtError(f"{path}: not a PLY file")
    body_start = raw.index(b"\n", end) + 1
    header = raw[:end].decode("ascii", errors="replace").splitlines()
    fmt, elements = None, []
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            if w[1] == "list":
                elements[-1][2].append((w[4], "list", _PLY_TYPES[w[2]], _PLY_TYPES[w[3]]))
            else:
                elements[-1][2].append((w[2], _PLY_TYPES[w[1]], None, None))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise PbrtError(f"{path}: PLY format {fmt!r} not supported")
    data = {}
    if fmt == "ascii":
        words = raw[body_start:].split()
        pos = 0
        for name, count, props in elements:
            rows = []
            for _ in range(count):
                row = {}
                for pname, kind, ctype, itype in props:
                    if kind == "list":
                        c = int(words[pos])
                        row[pname] = [float(x) for x in words[pos + 1:pos + 1 + c]]
                        pos += 1 + c
                    else:
                        row[pname] = float(words[pos])
                        pos += 1
                rows.append(row)
            data[name] = rows
    else:
        e = "<" if fmt == "binary_little_endian" else ">"
        pos = body_start
        for name, count, props in elements:
            if all(k != "list" for _, k, _, _ in props):  # fixed-size rows: one numpy read
                dt = np.dtype([(pn, e + k) for pn, k, _, _ in props])
                arr = np.frombuffer(raw, dtype=dt, count=count, offset=pos)
                pos += dt.itemsize * count
                data[name] = {pn: arr[pn].astype(float) for pn, _, _, _ in props}
                continue
            rows = []
            for _ in range(count):
                row = {}
                for pname, kind, ctype, itype in props:
                    if kind == "list":
                        (c,) = struct.unpack_from(e + ctype, raw, pos)
                        pos += struct.calcsize(ctype)
                        row[pname] = list(struct.unpack_from(e + itype * c, raw, pos))
                        pos += struct.calcsize(itype) * c
                    else:
                        (row[pname],) = struct.unpack_from(e + kind, raw, pos)
                        pos += struct.calcsize(kind)
                rows.append(row)
            data[name] = rows
    v = data.get("vertex")
    if v is None:
        raise PbrtError(f"{path}: no vertex element")
    col = (lambda k: np.asarray(v[k], float)) if isinstance(v, dict) else \
          (lambda k: np.asarray([r[k] for r in v], float))
    keys = set(v) if isinstance(v, dict) else set(v[0]) if v else set()
    p = np.stack([col("x"), col("y"), col("z")], axis=1)
    n = np.stack([col("nx"), col("ny"), col("nz")], axis=1) if {"nx", "ny", "nz"} <= keys else None
    uv = None
    for a, b in (("u", "v"), ("s", "t"), ("texture_u", "texture_v"), ("texture_s", "texture_t")):
        if {a, b} <= keys:
            uv = np.stack([col(a), col(b)], axis=1)
            break
    tris = []
    for row in data.get("face", []):
        f = row.get("vertex_indices", row.get("vertex_index"))
        if f is None:
            raise PbrtError(f"{path}: faces without vertex_indices")
        f = [int(x) for x in f]
        if len(f) == 3:
            tris.append(f)
        elif len(f) == 4:
            tris += [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]
        else:
            raise PbrtError(f"{path}: a face of {len(f)} vertices (triangles and quads only)")
    idx = np.asarray(tris, dtype=np.int64).reshape(-1, 3)
    if idx.size and (idx.min() < 0 or idx.max() >= len(p)):
        raise PbrtError(f"{path}: an index out of range")
    return Mesh(p, idx, n, uv)


def bilinear_to_triangles(p, patches, has_uv, loc):
    """Bilinear patches (k, 4) -> (triangles (2k, 3), uv of the points or None)."""
    uv = None if has_uv else np.zeros((len(p), 2))
    tris = []
    for k, (a, b, c, d) in enumerate(patches):  # p00 p10 p01 p11
        n = np.cross(p[b] - p[a], p[c] - p[a])
        scale = sum(np.linalg.norm(p[x] - p[a]) for x in (b, c, d))
        if abs(np.dot(n / np.linalg.norm(n), p[d] - p[a])) > 1e-5 * scale:
            raise PbrtError(f"{loc}: bilinearmesh patch {k} is not planar")
        if uv is not None:
            uv[a], uv[b], uv[c], uv[d] = (0, 0), (1, 0), (0, 1), (1, 1)
        tris += [[a, b, d], [a, d, c]]
    return np.asarray(tris, dtype=np.int64), uv


def write_ply(path, m):
    """Binary little-endian triangle PLY with optional normals and uv."""
    n, props = len(m.p), ["x", "y", "z"]
    cols = [m.p]
    if m.n is not None:
        props += ["nx", "ny", "nz"]
        cols.append(m.n)
    if m.uv is not None:
        props += ["u", "v"]
        cols.append(m.uv)
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {n}"]
    head += [f"property float {x}" for x in props]
    head += [f"element face {len(m.idx)}", "property list uchar int vertex_indices", "end_header"]
    verts = np.concatenate(cols, axis=1).astype("<f4")
    faces = np.zeros(len(m.idx), dtype=[("c", "u1"), ("i", "<i4", 3)])
    faces["c"], faces["i"] = 3, m.idx
    with open(path, "wb") as f:
        f.write(("\n".join(head) + "\n").encode())
        f.write(verts.tobytes())
        f.write(faces.tobytes())
