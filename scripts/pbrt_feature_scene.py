#!/usr/bin/env python3
"""Writes the meshes and the texture of scenes/pbrt/features/ (features.pbrt
uses them): an icosphere with vertex normals and uv (binary little-endian
PLY), a torus of quads (binary big-endian PLY, gzip-compressed), a floor quad
with uv (ASCII PLY) and an 8-bit sRGB checker image (PNG). Python 3 standard
library only; the output is deterministic.

    python3 scripts/pbrt_feature_scene.py [OUT_DIR]   (default scenes/pbrt/features)
"""
import gzip
import math
import struct
import sys
import zlib
from pathlib import Path


def icosphere(levels):
    t = (1 + math.sqrt(5)) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = [(x + y) / 2 for x, y in zip(v[a], v[b])]
                n = math.sqrt(sum(x * x for x in p))
                v.append(tuple(x / n for x in p))
                mid[key] = len(v) - 1
            return mid[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return v, f


def write_icosphere(path):
    v, f = icosphere(3)
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "property float u\nproperty float v\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(v), len(f)))
    body = bytearray()
    for x, y, z in v:
        u = 0.5 + math.atan2(z, x) / (2 * math.pi)
        w = 0.5 - math.asin(max(-1.0, min(1.0, y))) / math.pi
        body += struct.pack("<8f", x, y, z, x, y, z, u, w)
    for a, b, c in f:
        body += struct.pack("<B3i", 3, a, b, c)
    path.write_bytes(head.encode() + bytes(body))


def write_torus(path, big_r=1.0, r=0.3, nu=48, nv=24):
    verts, faces = [], []
    for i in range(nu):
        for j in range(nv):
            a, b = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            verts.append(((big_r + r * math.cos(b)) * math.cos(a), r * math.sin(b), (big_r + r * math.cos(b)) * math.sin(a)))
    for i in range(nu):
        for j in range(nv):
            i1, j1 = (i + 1) % nu, (j + 1) % nv
            faces.append((i * nv + j, i * nv + j1, i1 * nv + j1, i1 * nv + j))
    head = ("ply\nformat binary_big_endian 1.0\nelement vertex %d\n"
            "property float x\nproperty float y\nproperty float z\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(verts), len(faces)))
    body = bytearray()
    for p in verts:
        body += struct.pack(">3f", *p)
    for q in faces:
        body += struct.pack(">B4i", 4, *q)
    # mtime 0: the same bytes every time.
    path.write_bytes(gzip.compress(head.encode() + bytes(body), mtime=0))


def write_floor(path):
    path.write_text("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "end_header\n-4 0 -4 0 0\n4 0 -4 1 0\n4 0 4 1 1\n-4 0 4 0 1\n4 0 1 2 3\n")


def write_checker_png(path, size=64, cells=8):
    rows = []
    for y in range(size):
        row = bytearray([0])  # filter: none
        for x in range(size):
            even = ((x * cells // size) + (y * cells // size)) % 2 == 0
            row += bytes((200, 190, 170) if even else (40, 60, 90))
        rows.append(bytes(row))
    raw = b"".join(rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    path.write_bytes(png)


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "scenes/pbrt/features")
    out.mkdir(parents=True, exist_ok=True)
    write_icosphere(out / "icosphere.ply")
    write_torus(out / "torus.ply.gz")
    write_floor(out / "floor.ply")
    write_checker_png(out / "checker.png")


if __name__ == "__main__":
    main()
