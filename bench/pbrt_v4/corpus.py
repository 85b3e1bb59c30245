"""`python3 -m bench.pbrt_v4 corpus DIR`: every pbrt-v4 scene file under DIR
(a local copy of Bitterli's scenes in pbrt-v4 form, or any other set),
tried by mcrt and by pbrt-v4 at 8x8 pixels and 1 sample, and reported as
accepted or with the renderer's reason (the first line it prints).

A scene file is a `.pbrt` file with `WorldBegin`. DIR is first copied (as
hard links where it can) into OUT/corpus, and there, when --stand-ins is
given, every file a scene names that is absent gets a stand-in, listed in
the report:
- a mesh (`.ply`): one triangle of 1e-3 units at the origin;
- an image (`.png`, `.tga`, `.exr`, `.pfm`): 1x1 pixel of 0.5 grey;
- an included `.pbrt`: an empty file.
`Include "models/.pbrt"` (a name with no stem, which pbrt-v4 refuses as
well; living-room-3) is removed from the copy, and the report says so.
"""
import os
import re
import shutil
import struct
import subprocess
import tempfile
import zlib
from pathlib import Path

from . import renderers, scene_copy

_REF = re.compile(r'(?:"string filename"\s*\[?\s*|\b(?:Include|Import)\s+)"([^"]+)"')
_EMPTY_INCLUDE = re.compile(r'^(\s*)(Include|Import)\s+"([^"]*/)?\.pbrt"', re.M)
IMAGE = {".png", ".tga", ".exr", ".pfm"}


def _scene_files(root):
    out = []
    for p in sorted(root.rglob("*.pbrt")):
        try:
            if "WorldBegin" in p.read_text(errors="replace"):
                out.append(p)
        except OSError:
            pass
    return out


def _references(top):
    """(name as written, resolved path) of every file `top` and its
    present includes name, resolved against top's directory as pbrt-v4
    does."""
    base, seen, todo, out = top.parent, set(), [top], []
    while todo:
        f = todo.pop()
        if f in seen or not f.exists():
            continue
        seen.add(f)
        text = f.read_text(errors="replace")
        # The Film's filename is an output, not a file the scene reads.
        text = "".join(_without_film(text))
        for name in _REF.findall(text):
            path = base / name
            out.append((name, path))
            if path.suffix == ".pbrt":
                todo.append(path)
    return out


def _without_film(text):
    """The text with each Film statement left out."""
    stmts = scene_copy._statements(text)
    at = 0
    for st in stmts:
        if st[0] == "Film":
            yield text[at:st[1]]
            at = st[2]
    yield text[at:]


def _png(path):
    raw = b"\x00\x80\x80\x80"
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def _exr(path):
    """1x1 pixel of 0.5 grey: a single-part scanline OpenEXR file, float RGB,
    no compression (openexr.com, "OpenEXR File Layout")."""
    attr = lambda name, kind, value: name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value
    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<4i", 0, 0, 0, 0)
    header = (struct.pack("<ii", 20000630, 2) + attr("channels", "chlist", channels)
              + attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box)
              + attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    pixels = struct.pack("<3f", 0.5, 0.5, 0.5)
    offset = len(header) + 8
    path.write_bytes(header + struct.pack("<Q", offset) + struct.pack("<ii", 0, len(pixels)) + pixels)


def _stand_in(path):
    path.parent.mkdir(parents=True, exist_ok=True)
    ext = path.suffix.lower()
    if ext == ".ply":
        path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n0.001 0 0\n0 0.001 0\n3 0 1 2\n")
    elif ext == ".png":
        _png(path)
    elif ext == ".tga":  # uncompressed true colour, 1x1, BGR
        path.write_bytes(bytes([0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 1, 0, 24, 0]) + b"\x80\x80\x80")
    elif ext == ".pfm":
        path.write_bytes(b"PF\n1 1\n-1.0\n" + struct.pack("<3f", 0.5, 0.5, 0.5))
    elif ext == ".exr":
        _exr(path)
    elif ext == ".pbrt":
        path.write_text("# stand-in: absent from the copy\n")
    else:
        return False
    return True


def _copy_tree(src, dst):
    if dst.exists():
        shutil.rmtree(dst)
    try:
        shutil.copytree(src, dst, copy_function=os.link)
    except OSError:
        shutil.rmtree(dst, ignore_errors=True)
        shutil.copytree(src, dst)


def _first_line(text):
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith(("Warning", "pbrt version", "Copyright", "[")):
            return line[:300]
    return "(no message)"


def _try(name, binary, scene, work):
    """'accepted' or the renderer's reason."""
    out = work / f"{name}.exr"
    try:
        copy = scene_copy.settings_copy(scene, 8, 8, 1, 5)
    except scene_copy.SceneError as e:
        return f"(settings copy) {e}"
    try:
        if name == "mcrt":
            cmd = [str(binary), "render", str(copy), "-o", str(out), "--spp", "1", "--threads", "2", "--quiet"]
        else:
            cmd = [str(binary), "--nthreads", "2", "--quiet", "--spp", "1", "--outfile", str(out), str(copy)]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
        except subprocess.TimeoutExpired:
            return "timed out (30 min)"
        if p.returncode == 0 and out.exists():
            return "accepted"
        return f"exit {p.returncode}: " + _first_line(p.stderr + "\n" + p.stdout).replace(str(copy), scene.name) \
            .replace(copy.name, scene.name)
    finally:
        copy.unlink(missing_ok=True)
        out.unlink(missing_ok=True)


def run(args):
    src, out_dir = Path(args.dir).resolve(), Path(args.out).resolve()
    work = out_dir / "corpus"
    _copy_tree(src, work)
    tmp = Path(tempfile.mkdtemp(prefix="corpus-", dir=out_dir))
    rows, stand_ins, repairs = [], [], []
    for scene in _scene_files(work):
        rel = scene.relative_to(work)
        text = scene.read_text(errors="replace")
        if _EMPTY_INCLUDE.search(text):
            scene.unlink()  # a hard link: write a file of its own
            scene.write_text(_EMPTY_INCLUDE.sub(r"\1# (removed by bench.pbrt_v4: no such file) \2", text))
            repairs.append(f"{rel}: `Include \"models/.pbrt\"` removed (a name with no stem; pbrt-v4 refuses it too)")
        if args.stand_ins:
            for name, path in _references(scene):
                if not path.exists() and _stand_in(path):
                    stand_ins.append((str(rel), name))
        rows.append((str(rel), _try("mcrt", args.mcrt, scene, tmp), _try("pbrt-v4", args.pbrt, scene, tmp)))
        print(f"{rows[-1][0]}: mcrt {rows[-1][1]} | pbrt-v4 {rows[-1][2]}", flush=True)
    shutil.rmtree(tmp, ignore_errors=True)
    lines = [f"{len(rows)} scene files under {src}; mcrt accepts {sum(r[1] == 'accepted' for r in rows)}, "
             f"pbrt-v4 {sum(r[2] == 'accepted' for r in rows)} (8x8 pixels, 1 sample, 2 threads)", "",
             "| file | mcrt | pbrt-v4 |", "|---|---|---|"]
    lines += [f"| {f} | {m.replace('|', '/')} | {p.replace('|', '/')} |" for f, m, p in rows]
    if repairs:
        lines += ["", "Repairs in the copy:", *[f"- {r}" for r in repairs]]
    lines += ["", f"Stand-ins for absent files ({len(stand_ins)}; per scene file, by kind, the first names):"
              if stand_ins else "No stand-ins."]
    per = {}
    for rel, name in stand_ins:
        per.setdefault(rel, {}).setdefault(Path(name).suffix.lower(), []).append(name)
    for rel, kinds in per.items():
        parts = [f"{len(v)} {k} ({', '.join(v[:3])}{', …' if len(v) > 3 else ''})" for k, v in sorted(kinds.items())]
        lines.append(f"- {rel}: " + "; ".join(parts))
    report = "\n".join(lines) + "\n"
    (out_dir / "corpus.md").write_text(report)
    print(report)
    return 0
