"""Structural attacks: named families of small hand-made cases.

Each family function returns a list of ``Case``.  Most cases take the tiny
base scene of ``artifacts`` and vary one thing.  A case that must end in a
particular class says so with ``expect`` (for instance a valid but extreme
scene that MUST render, or bad input that MUST be refused even though a
lenient reader would render it); otherwise any ok class is fine and only
the bug classes (crash, hang, memory, non-finite samples, dirty refusal,
bad output) count.

Families (the id's first part):
  syntax    the pbrt tokenizer and parser: empty files, BOM, line endings,
            NUL, invalid UTF-8, huge numbers and lines, nesting, balance
  include   Include / Import of odd files (itself, cycles, devices, FIFOs,
            directories, gzip bombs)
  files     the scene argument itself being an odd file (.pbrt and .json)
  camera    degenerate cameras and transforms
  geometry  extreme or broken mesh, sphere and disk values
  lights    area light and material parameters
  ply       PLY files that lie
  texture   image textures that are odd files or odd images
  flags     the command line: resolution, spp, depth, threads, seed, output
            paths, light strategies, ``mcrt samples`` and ``mcrt diff``
  json      JSON scenes
"""

from __future__ import annotations

import struct
import zlib

from . import artifacts as A
from .model import (Case, diff_case, directory, fifo, file, render_case, samples_case, sparse, symlink)

RENDERED = ("rendered",)
REFUSED = ("clean_refusal",)

LIGHT_SAMPLINGS = ["area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "pbrt", "auto"]
LIGHT_SELECTS = ["power", "uniform", "bvh", "pbrt-bvh"]
INTEGRATORS = ["mis", "nee", "mixture"]
SAMPLERS = ["independent", "stratified", "sobol"]


def pb(case_id: str, text, *, entries=None, expect=None, note="", names=None, extra=None,
       flags=None, slow=False, scene="scene.pbrt") -> Case:
    """A render of a pbrt scene held in ``scene`` (text or bytes or callable)."""
    return render_case(case_id, scene, [file(scene, text), *(entries or [])], extra=extra,
                       flags=flags, names=names, expect=expect, note=note, slow=slow)


def scene_with(**parts) -> str:
    return A.pbrt_scene(**parts)


# --------------------------------------------------------------------------
# 1. syntax

def syntax() -> list[Case]:
    f = "syntax/"
    base = A.BASE_PBRT
    commented = "# the base scene\n" + "".join(
        line + "   # a comment\n" if line else "\n" for line in base.split("\n")[:-1])
    cases = [
        pb(f + "empty", "", note="empty file"),
        pb(f + "whitespace", " \n\t\n   \n", note="whitespace only"),
        pb(f + "comments-only", "# one\n# two\n#\n", note="comments only"),
        pb(f + "bom", "\ufeff" + base, expect=RENDERED, note="UTF-8 BOM before the file (an accepted extension)"),
        pb(f + "cr-only", commented.replace("\n", "\r"), expect=RENDERED,
           note="CR-only line endings with comments"),
        pb(f + "crlf", commented.replace("\n", "\r\n"), expect=RENDERED, note="CRLF line endings"),
        pb(f + "no-final-newline", base.rstrip("\n"), expect=RENDERED, note="no newline at the end"),
        pb(f + "nul-first", b"\0" + base.encode(), note="NUL byte first"),
        pb(f + "nul-in-directive", base.replace("WorldBegin", "World\0Begin").encode(), note="NUL in a directive"),
        pb(f + "nul-in-string", base.replace('"perspective"', '"persp\0ective"').encode(), note="NUL in a string"),
        pb(f + "invalid-utf8-token", base.encode() + b"\xff\xfe\xfd\n", note="invalid UTF-8 as a token"),
        pb(f + "invalid-utf8-comment", b"# \xff\xc3\x28 bad\n" + base.encode(), note="invalid UTF-8 in a comment"),
        pb(f + "invalid-utf8-string", base.replace('"perspective"', '"persp\udcffective"')
           .encode("utf-8", "surrogateescape"), note="invalid UTF-8 in a string"),
        pb(f + "escape-sequence-in-string", base + 'Shape "\x1b[2J\x1b[31mred"\n',
           note="a terminal escape sequence in an unknown shape's name (must not reach stderr raw)"),
        pb(f + "number-100000-digits", base.replace("[ 45 ]", "[ " + "7" * 100000 + " ]"),
           note="a 100000-digit number (the line must stay short)"),
        pb(f + "number-tiny-denormal", base.replace("[ 45 ]", "[ 0." + "0" * 5000 + "1 ]"),
           note="a number that underflows to 0 as fov"),
        pb(f + "number-exponent-huge", base.replace("[ 45 ]", "[ 1e999999999999 ]"), note="exponent overflow"),
        pb(f + "number-forms", base.replace("[ 45 ]", "[ +45. ]").replace("[ 0.5 0.5 0.5 ]", "[ .5 5e-1 +0.5 ]"),
           expect=RENDERED, note="numbers in every form pbrt accepts"),
        pb(f + "number-hex", base.replace("[ 45 ]", "[ 0x2d ]"), note="hexadecimal number"),
        pb(f + "number-nan-token", base.replace("[ 45 ]", "[ nan ]"), note="nan as a number"),
        pb(f + "number-inf-token", base.replace("[ 45 ]", "[ inf ]"), note="inf as a number"),
        pb(f + "long-comment-line", "#" + "x" * (8 << 20) + "\n" + base, note="an 8 MB comment line"),
        pb(f + "long-identifier", base + "A" * (1 << 20) + "\n", note="a 1 MB unknown directive"),
        pb(f + "long-string", base.replace('"perspective"', '"' + "p" * (1 << 20) + '"'),
           note="a 1 MB camera name (the refusal line must stay short)"),
        pb(f + "unterminated-string-eof", base + 'Shape "trianglemesh', note="unterminated string at EOF"),
        pb(f + "unterminated-string-mid", base.replace('"perspective"', '"perspective'),
           note="unterminated string mid-file"),
        pb(f + "newline-in-string", base.replace('"perspective"', '"persp\nective"'), note="newline in a string"),
        pb(f + "nested-open-brackets", base.replace("[ 45 ]", "[" * 100000), note="10^5 nested ["),
        pb(f + "nested-brackets-balanced", base.replace("[ 45 ]", "[" * 100000 + " 45 " + "]" * 100000),
           note="10^5 nested [ ... ]"),
        pb(f + "close-brackets", base.replace("[ 45 ]", "]" * 100000), note="10^5 ]"),
        pb(f + "bracket-unclosed-eof", base + 'Shape "sphere" "float radius" [ 1', note="[ unclosed at EOF"),
        pb(f + "duplicate-worldbegin", base.replace("WorldBegin\n", "WorldBegin\nWorldBegin\n"),
           note="WorldBegin twice"),
        pb(f + "no-worldbegin", base.replace("WorldBegin\n", ""), note="no WorldBegin"),
        pb(f + "worldend", base + "WorldEnd\n", note="WorldEnd (accepted)"),
        pb(f + "after-worldend", base + "WorldEnd\n" + A.FLOOR, note="shapes after WorldEnd"),
        pb(f + "camera-in-world", base + A.CAMERA, note="Camera after WorldBegin"),
        pb(f + "shape-before-world", scene_with(head=A.FLOOR), note="Shape before WorldBegin"),
        pb(f + "arealight-before-world", scene_with(head='AreaLightSource "diffuse"\n'),
           note="AreaLightSource before WorldBegin"),
        pb(f + "unknown-directive", base + "Frobnicate 1 2 3\n", note="unknown directive"),
        pb(f + "lowercase-directive", base + 'shape "sphere"\n', note="directive in lower case"),
        pb(f + "unknown-param-type", base + 'Shape "sphere" "quaternion q" [ 1 2 3 4 ]\n',
           note="unknown parameter type"),
        pb(f + "param-empty", base + 'Shape "sphere" "" [ 1 ]\n', note="empty parameter declaration"),
        pb(f + "param-no-value", base + 'Shape "sphere" "float radius"\n', note="parameter without values"),
        pb(f + "param-type-mismatch-int", base.replace('"float fov"', '"integer fov"'),
           note="integer where float"),
        pb(f + "param-string-for-float", base.replace("[ 45 ]", '[ "45" ]'), note="string value for a float"),
        pb(f + "param-bool-bad", base + 'Shape "sphere" "bool foo" "maybe"\n', note="bad bool"),
        pb(f + "param-rgb-short", scene_with(light=A.light_with('"rgb L" [ 1 1 ]')), note="rgb of 2 values"),
        pb(f + "lookat-short", "LookAt 0 1\n", note="LookAt with 2 numbers at EOF"),
        pb(f + "translate-short", base.replace("WorldBegin\n", "WorldBegin\nTranslate 1 2\n"),
           note="Translate with 2 numbers"),
        pb(f + "directive-at-eof", base + "Shape", note="a directive with nothing after it"),
        pb(f + "number-as-directive", base + "42\n", note="a number where a directive goes"),
    ]
    # Unbalanced blocks in every order.
    blocks = {"Attribute": "AttributeBegin", "Transform": "TransformBegin", "Object": 'ObjectBegin "o"'}
    ends = {"Attribute": "AttributeEnd", "Transform": "TransformEnd", "Object": "ObjectEnd"}
    for b, begin in blocks.items():
        cases.append(pb(f + f"lone-begin-{b.lower()}", base + begin + "\n", note=f"{begin} never closed"))
        cases.append(pb(f + f"lone-end-{b.lower()}", base + ends[b] + "\n", note=f"{ends[b]} without a begin"))
        for e in ends:
            if e == b:
                continue
            cases.append(pb(f + f"begin-{b.lower()}-end-{e.lower()}",
                            base + begin + "\n" + A.FLOOR + ends[e] + "\n",
                            note=f"{begin} closed by {ends[e]}"))
    cases.append(pb(f + "attribute-across-world", scene_with(head="AttributeBegin\n",
                                                            world_head="AttributeEnd\n"),
                    note="AttributeBegin before WorldBegin, AttributeEnd after"))
    cases.append(pb(f + "deep-attributes", base + "AttributeBegin\n" * 100000 + "AttributeEnd\n" * 100000,
                    note="10^5 nested AttributeBegin"))
    cases.append(pb(f + "object-instance-undefined", base + 'ObjectInstance "nope"\n',
                    note="ObjectInstance of nothing"))
    return cases


# --------------------------------------------------------------------------
# 2. include / Import

def include() -> list[Case]:
    cases = []
    world = A.WORLD

    # Import (the same reader) only for the attacks most likely to differ.
    import_too = {"itself", "mutual", "dev-zero", "dev-urandom", "dev-null", "fifo", "directory", "missing",
                  "empty-file", "gz-truncated", "gz-bomb"}

    def inc(name: str, target: str, entries, *, directive="Include", expect=None, note="", slow=False):
        if directive == "Import" and name not in import_too:
            return
        text = A.pbrt_scene(world_head=f'{directive} "{target}"\n')
        # The refusal may name the scene, the included file or any file it includes.
        names = [target, *(e.path for e in entries)]
        cases.append(pb(f"include/{directive.lower()}-{name}", text, entries=entries, expect=expect,
                        names=names, note=note or f"{directive} of {name}", slow=slow))

    for d in ("Include", "Import"):
        inc("itself", "scene.pbrt", [], directive=d)
        inc("mutual", "a.pbrt", [file("a.pbrt", 'Include "b.pbrt"\n'), file("b.pbrt", 'Include "a.pbrt"\n')],
            directive=d, note=f"{d} cycle a -> b -> a")
        inc("dev-zero", "zero.pbrt", [symlink("zero.pbrt", "/dev/zero")], directive=d, slow=True)
        inc("dev-zero-abs", "/dev/zero", [], directive=d, slow=True)
        inc("dev-urandom", "random.pbrt", [symlink("random.pbrt", "/dev/urandom")], directive=d, slow=True)
        inc("dev-null", "null.pbrt", [symlink("null.pbrt", "/dev/null")], directive=d,
            note=f"{d} of /dev/null (empty: may render)")
        inc("fifo", "pipe.pbrt", [fifo("pipe.pbrt")], directive=d, slow=True)
        inc("directory", "dir.pbrt", [directory("dir.pbrt")], directive=d)
        inc("empty-name", "", [], directive=d, note=f'{d} ""')
        inc("missing", "missing.pbrt", [], directive=d)
        inc("empty-file", "empty.pbrt", [file("empty.pbrt", "")], directive=d, note=f"{d} of an empty file")
        inc("binary-file", "checker.png", [file("checker.png", A.checker_png())], directive=d)
        inc("gz-valid", "part.pbrt.gz", [file("part.pbrt.gz", A.gz(A.FLOOR))], directive=d, expect=RENDERED)
        inc("gz-truncated", "part.pbrt.gz", [file("part.pbrt.gz", lambda: A.gz(A.FLOOR * 20)[:60])], directive=d)
        inc("gz-empty", "part.pbrt.gz", [file("part.pbrt.gz", b"")], directive=d)
        inc("gz-bomb", "bomb.pbrt.gz", [file("bomb.pbrt.gz", lambda: A.gz_bomb())], directive=d, slow=True,
            note=f"{d} of a gzip bomb (3.2 GiB of zeros)")
        inc("gz-bomb-valid-prefix", "bomb.pbrt.gz", [file("bomb.pbrt.gz", lambda: A.gz_bomb(A.FLOOR))],
            directive=d, slow=True, note=f"{d} of valid text then 3.2 GiB of zeros")
        inc("parent-escape", "../../../../../../../../etc/passwd", [], directive=d)
        inc("world-inside", "w.pbrt", [file("w.pbrt", "WorldBegin\n")], directive=d,
            note=f"{d}d file says WorldBegin again")
        inc("unbalanced-inside", "u.pbrt", [file("u.pbrt", "AttributeBegin\n")], directive=d,
            note=f"{d}d file opens an attribute block")
    # A chain of 100 files, then one of 3000 (recursion depth).
    for depth in (100, 3000):
        entries = [file(f"inc{i}.pbrt", f'Include "inc{i + 1}.pbrt"\n') for i in range(depth)]
        entries.append(file(f"inc{depth}.pbrt", world))
        text = A.CAMERA + A.OPTIONS + 'WorldBegin\nInclude "inc0.pbrt"\n'
        cases.append(pb(f"include/chain-{depth}", text, entries=entries, names=["inc"],
                        note=f"a chain of {depth} Includes"))
    cases.append(pb("include/include-no-arg", A.BASE_PBRT + "Include\n", note="Include without a file"))
    long_name = "n" * 250 + "/" + "m" * 250 + "/" + "x" * 4000 + ".pbrt"
    cases.append(pb("include/include-long-name", A.pbrt_scene(world_head=f'Include "{long_name}"\n'),
                    names=["x" * 40], note="Include of a 4500-character path (ENAMETOOLONG)"))
    cases.append(pb("include/include-before-world", A.pbrt_scene(head='Include "cam.pbrt"\n', camera=""),
                    entries=[file("cam.pbrt", A.CAMERA)], expect=RENDERED, names=["cam.pbrt"],
                    note="the camera Included before WorldBegin"))
    return cases


# --------------------------------------------------------------------------
# 3. files as the scene argument

def files() -> list[Case]:
    cases = []
    json_too = {"fifo", "dev-zero", "dev-urandom", "dev-null", "directory", "missing", "gz-valid", "gz-empty",
                "gz-truncated", "gz-bomb"}
    for ext, valid in ((".pbrt", A.BASE_PBRT), (".json", A.BASE_JSON)):
        tag = ext[1:]

        def sc(name, entries, *, scene="x" + ext, note="", slow=False, expect=None):
            if ext == ".json" and name not in json_too:
                return
            cases.append(render_case(f"files/{tag}-{name}", scene, entries, note=note, slow=slow,
                                     expect=expect))

        sc("fifo", [fifo("x" + ext)], slow=True, note="the scene is a FIFO")
        sc("dev-zero", [symlink("x" + ext, "/dev/zero")], slow=True, note="the scene is /dev/zero")
        sc("dev-urandom", [symlink("x" + ext, "/dev/urandom")], slow=True, note="the scene is /dev/urandom")
        sc("dev-null", [symlink("x" + ext, "/dev/null")], note="the scene is /dev/null")
        sc("directory", [directory("x" + ext)], note="the scene is a directory")
        sc("missing", [], note="the scene does not exist")
        sc("dev-zero-abs", [], scene="/dev/zero", slow=True, note="/dev/zero itself (no extension)")
        sc("no-extension", [file("x", valid)], scene="x", note="no extension")
        sc("gz-valid", [file(f"x{ext}.gz", A.gz(valid))], scene=f"x{ext}.gz",
           expect=RENDERED if ext == ".pbrt" else None, note="a gzip-compressed scene")
        sc("gz-empty", [file(f"x{ext}.gz", b"")], scene=f"x{ext}.gz", note="an empty .gz scene")
        sc("gz-truncated", [file(f"x{ext}.gz", A.gz(valid * 10)[:80])], scene=f"x{ext}.gz",
           note="a truncated .gz scene")
        sc("gz-bad-crc", [file(f"x{ext}.gz", lambda v=valid: _bad_crc(A.gz(v)))], scene=f"x{ext}.gz",
           note="a .gz whose CRC is wrong")
        sc("gz-not-gzip", [file(f"x{ext}.gz", valid)], scene=f"x{ext}.gz", note="plain text named .gz")
        sc("gz-trailing-garbage", [file(f"x{ext}.gz", lambda v=valid: A.gz(v) + b"garbage!")],
           scene=f"x{ext}.gz", note="a .gz with garbage after it")
        sc("gz-bomb", [file(f"x{ext}.gz", lambda: A.gz_bomb())], scene=f"x{ext}.gz", slow=True,
           note="a gzip bomb (3.2 GiB of zeros)")
        sc("gz-bomb-valid-prefix", [file(f"x{ext}.gz", lambda v=valid: A.gz_bomb(v))], scene=f"x{ext}.gz",
           slow=True, note="a valid scene then 3.2 GiB of zeros")
        sc("dev-zero-gz", [symlink(f"x{ext}.gz", "/dev/zero")], scene=f"x{ext}.gz", slow=True,
           note="/dev/zero named .gz")
    cases.append(render_case("files/empty-argument", "", [], note="the scene argument is ''"))
    cases.append(render_case("files/pbrt-sparse-8g", "x.pbrt", [sparse("x.pbrt", A.BASE_PBRT, 8 << 30)], slow=True,
                             note="a valid scene followed by an 8 GiB hole of zeros (a sparse file)"))
    # A file name with a newline: a refusal must still be one line.
    cases.append(render_case("files/newline-in-name-missing", "bad\nname.pbrt", [],
                             note="a missing scene whose name holds a newline (the refusal must stay one line)"))
    cases.append(render_case("files/newline-in-name-valid", "bad\nname.pbrt", [file("bad\nname.pbrt", A.BASE_PBRT)],
                             expect=RENDERED, note="a valid scene whose name holds a newline"))
    cases.append(render_case("files/pbrt-symlink-loop", "x.pbrt", [symlink("x.pbrt", "y.pbrt"),
                                                                   symlink("y.pbrt", "x.pbrt")],
                             note="x.pbrt -> y.pbrt -> x.pbrt"))
    cases.append(render_case("files/space-in-name", "my scene.pbrt", [file("my scene.pbrt", A.BASE_PBRT)],
                             expect=RENDERED, note="a space in the scene's name"))
    cases.append(render_case("files/dash-name", "./-x.pbrt", [file("-x.pbrt", A.BASE_PBRT)], expect=RENDERED,
                             note="a scene name that starts with '-' (as ./-x.pbrt)"))
    return cases


def _bad_crc(data: bytes) -> bytes:
    return data[:-8] + bytes(b ^ 0xFF for b in data[-8:-4]) + data[-4:]


# --------------------------------------------------------------------------
# 4. camera and transforms

def camera() -> list[Case]:
    f = "camera/"
    cam = A.CAMERA
    # The projective term lands in the matrix's last row (column-major text:
    # the 4th number of the first column).
    projective = "[ 1 0 0 0.5  0 1 0 0  0 0 1 0  0 0 0 1 ]"
    cases = [
        pb(f + "scale-000", scene_with(camera="Scale 0 0 0\n" + cam), note="Scale 0 0 0 before the camera"),
        pb(f + "scale-110", scene_with(camera="Scale 1 1 0\n" + cam), note="Scale 1 1 0 before the camera"),
        pb(f + "scale-tiny-uniform", scene_with(camera="Scale 1e-30 1e-30 1e-30\n" + cam), expect=RENDERED,
           note="Scale 1e-30 (uniform) before the camera"),
        pb(f + "scale-huge-uniform", scene_with(camera="Scale 1e30 1e30 1e30\n" + cam),
           note="Scale 1e30 (uniform) before the camera"),
        pb(f + "scale-mirror", scene_with(camera="Scale -1 1 1\n" + cam), expect=RENDERED,
           note="Scale -1 1 1 before the camera"),
        pb(f + "transform-projective", scene_with(camera=cam.replace("LookAt", f"Transform {projective}\nLookAt",
                                                                     1)),
           note="a projective Transform before the camera"),
        pb(f + "concat-projective", scene_with(camera=f"ConcatTransform {projective}\n" + cam),
           note="a projective ConcatTransform before LookAt"),
        pb(f + "transform-projective-only", scene_with(camera=f"Transform {projective}\n"
                                                              'Camera "perspective"\n'),
           note="a projective Transform as the camera"),
        pb(f + "transform-1e300", scene_with(camera="Transform [ 1e300 0 0 0  0 1e300 0 0  0 0 1e300 0  0 0 0 1 ]\n"
                                                    'Camera "perspective"\n'),
           note="Transform with 1e300 entries"),
        pb(f + "transform-zero", scene_with(camera="Transform [ " + "0 " * 16 + "]\n" + 'Camera "perspective"\n'),
           note="Transform of zeros"),
        pb(f + "transform-15", scene_with(camera="Transform [ " + "1 " * 15 + "]\n" + cam),
           note="Transform of 15 numbers"),
        pb(f + "lookat-eye-is-target", scene_with(camera='LookAt 0 1 -4  0 1 -4  0 1 0\nCamera "perspective"\n'),
           note="LookAt with eye == target"),
        pb(f + "lookat-up-parallel", scene_with(camera='LookAt 0 1 -4  0 0.5 0  0 -0.5 4\nCamera "perspective"\n'),
           note="LookAt with up parallel to the view"),
        pb(f + "lookat-up-zero", scene_with(camera='LookAt 0 1 -4  0 0.5 0  0 0 0\nCamera "perspective"\n'),
           note="LookAt with up = 0"),
        pb(f + "lookat-far", scene_with(camera='LookAt 1e38 1e38 1e38  0 0 0  0 1 0\nCamera "perspective"\n'),
           note="LookAt from 1e38"),
        pb(f + "lookat-1e39", scene_with(camera='LookAt 1e39 0 0  0 0 0  0 1 0\nCamera "perspective"\n'),
           note="LookAt from 1e39 (not a float)"),
        pb(f + "rotate-zero-axis", scene_with(camera="Rotate 30 0 0 0\n" + cam), note="Rotate about a zero axis"),
        pb(f + "no-camera", scene_with(camera=""), note="no Camera (pbrt's default)"),
        pb(f + "orthographic", scene_with(camera=cam.replace("perspective", "orthographic")),
           note="orthographic camera (refused or rendered)"),
        pb(f + "camera-unknown", scene_with(camera=cam.replace("perspective", "fisheye")), note="unknown camera"),
        pb(f + "coordsys-undefined", scene_with(camera='CoordSysTransform "nowhere"\n' + cam),
           note="CoordSysTransform of an undefined name"),
    ]
    for fov in ("0", "180", "1e-30", "179.999", "-45", "1e30"):
        cases.append(pb(f + f"fov-{fov}", scene_with(camera=cam.replace("[ 45 ]", f"[ {fov} ]")),
                        note=f"fov {fov}"))
    windows = {"zero": "0 0 0 0", "inverted": "1 -1 1 -1", "huge": "-1e38 1e38 -1e38 1e38", "three": "-1 1 -1"}
    for name, w in windows.items():
        cases.append(pb(f + f"screenwindow-{name}",
                        scene_with(camera=cam.replace("[ 45 ]", f'[ 45 ] "float screenwindow" [ {w} ]')),
                        note=f"screenwindow [{w}]"))
    lens = {"lensradius-1e30": '"float lensradius" 1e30',
            "lensradius-neg": '"float lensradius" -1',
            "focaldistance-1e-30": '"float lensradius" 0.1 "float focaldistance" 1e-30',
            "focaldistance-0": '"float lensradius" 0.1 "float focaldistance" 0',
            "focaldistance-neg": '"float lensradius" 0.1 "float focaldistance" -5',
            "frameaspect-0": '"float frameaspectratio" 0',
            "frameaspect-huge": '"float frameaspectratio" 1e38'}
    for name, p in lens.items():
        cases.append(pb(f + name, scene_with(camera=cam.replace("[ 45 ]", "[ 45 ] " + p)), note=p))
    # After WorldBegin: transforms that collapse or break the geometry.
    for name, t in {"world-scale-tiny": "Scale 1e-30 1e-30 1e-30", "world-scale-zero": "Scale 0 0 0",
                    "world-scale-flat": "Scale 1 0 1", "world-scale-huge": "Scale 1e30 1e30 1e30",
                    "world-projective": f"ConcatTransform {projective}",
                    "world-transform-1e300": "Transform [ 1e300 0 0 0  0 1e300 0 0  0 0 1e300 0  0 0 0 1 ]",
                    "world-mirror": "Scale 1 -1 1"}.items():
        cases.append(pb(f + name, A.pbrt_scene(world_head=t + "\n"), note=f"{t} on every shape"))
    return cases


# --------------------------------------------------------------------------
# 5. geometry values

def geometry() -> list[Case]:
    f = "geometry/"
    cases = []

    def world(name, tail, *, expect=None, note="", floor=A.FLOOR, light=A.LIGHT):
        # Parts may be callables (big meshes are built only when the case runs).
        def text(tail=tail, floor=floor, light=light):
            parts = [p() if callable(p) else p for p in (tail, floor, light)]
            return A.pbrt_scene(world_tail=parts[0], floor=parts[1], light=parts[2])
        cases.append(pb(f + name, text, expect=expect, note=note))

    world("fltmax-with-normals", A.tri_mesh([0, 0, 0, 1, 0, 0, "3.4028235e38", 1, 0], [0, 1, 2],
                                            ' "normal N" [ 0 1 0  0 1 0  0 1 0 ]'),
          expect=RENDERED, note="a vertex at FLT_MAX in a mesh with normals beside an ordinary mesh")
    world("fltmax-no-normals", A.tri_mesh([0, 0, 0, 1, 0, 0, "3.4028235e38", 1, 0], [0, 1, 2]),
          note="a vertex at FLT_MAX")
    for v in ("1e38", "-1e38", "1e39", "1e-45", "1e300"):
        world(f"vertex-{v}", A.tri_mesh([0, 0, 0, 1, 0, 0, v, v, v], [0, 1, 2]),
              expect=REFUSED if v.lstrip("-") in ("1e39", "1e300") else None,
              note=f"a vertex at {v}" + (" (not finite as a float: refused)" if "e39" in v or "e300" in v else ""))
    world("all-vertices-equal", A.tri_mesh([1, 1, 1] * 3, [0, 1, 2]), note="three equal vertices")
    world("zero-area-only", "", floor=A.tri_mesh([0, 0, 0, 1, 0, 0, 2, 0, 0], [0, 1, 2]),
          note="only zero-area triangles (and the light)")
    world("zero-area-light", "", light=A.light_with('"rgb L" [ 1 1 1 ]',
                                                    A.tri_mesh([0, 2, 0, 1, 2, 0, 2, 2, 0], [0, 1, 2])),
          note="a zero-area emitting triangle")
    world("tiny-light", "", light=A.light_with('"rgb L" [ 1 1 1 ]',
                                               A.tri_mesh([0, 2, 0, 1e-20, 2, 0, 0, 2, 1e-20], [0, 2, 1])),
          note="an emitting triangle of area 1e-40")
    world("huge-light", "", light=A.light_with('"rgb L" [ 1 1 1 ]',
                                               A.tri_mesh([-1e20, 2, -1e20, 1e20, 2, -1e20, 0, 2, 1e20], [0, 1, 2])),
          note="an emitting triangle of area 1e40 (overflows float)")
    world("identical-triangles-1e5", lambda: A.tri_mesh([-1, 0.5, -1, 1, 0.5, -1, 0, 0.5, 1], [0, 2, 1] * 100000),
          note="10^5 identical triangles")
    world("identical-light-triangles-1e4", "",
          light=lambda: A.light_with('"rgb L" [ 1 1 1 ]',
                                     A.tri_mesh([-1, 2, -1, 1, 2, -1, 0, 2, 1], [0, 1, 2] * 10000)),
          note="10^4 identical emitting triangles")
    for name, idx in {"index-out-of-range": [0, 1, 3], "index-negative": [0, 1, -1],
                      "index-2^31": [0, 1, 2147483648], "index-2^32": [0, 1, 4294967296],
                      "index-2^32+1": [0, 1, 4294967297], "index-2^64": [0, 1, 18446744073709551616],
                      "index-count-4": [0, 1, 2, 0], "index-count-2": [0, 1], "index-empty": []}.items():
        world(name, A.tri_mesh([0, 0, 0, 1, 0, 0, 0, 1, 0], idx), expect=REFUSED if name != "index-empty" else None,
              note=f"indices {idx}")
    world("index-huge-array", lambda: A.tri_mesh([0, 0, 0, 1, 0, 0, 0, 1, 0], [0, 1, 2] * 400000),
          note="1.2 million indices")
    world("no-indices-3-vertices", 'Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  0 1 0 ]\n',
          note="3 vertices and no indices (pbrt allows it)")
    world("no-P", 'Shape "trianglemesh" "integer indices" [ 0 1 2 ]\n', note="no P")
    world("P-count-7", 'Shape "trianglemesh" "point3 P" [ 0 0 0 1 0 0 0 ] "integer indices" [ 0 1 2 ]\n',
          note="P of 7 numbers")
    world("normals-zero", A.tri_mesh([0, 0, 0, 1, 0, 0, 0, 0, 1], [0, 2, 1], ' "normal N" [ 0 0 0  0 0 0  0 0 0 ]'),
          note="zero normals")
    world("normals-1e39", A.tri_mesh([0, 0, 0, 1, 0, 0, 0, 0, 1], [0, 2, 1], ' "normal N" [ 0 1e39 0 ' * 1 + " 0 1 0  0 1 0 ]"),
          note="a normal of 1e39")
    world("uv-1e38", A.tri_mesh([0, 0, 0, 1, 0, 0, 0, 0, 1], [0, 2, 1], ' "point2 uv" [ 1e38 1e38  0 0  1 1 ]'),
          note="uv of 1e38")
    world("tangents-S", A.tri_mesh([0, 0, 0, 1, 0, 0, 0, 0, 1], [0, 2, 1], ' "vector3 S" [ 1 0 0  1 0 0  1 0 0 ]'),
          note="shading tangents (refused unless supported)")
    for r in ("0", "-1", "1e38", "1e39"):
        world(f"sphere-radius-{r}", f'Shape "sphere" "float radius" {r}\n', note=f"sphere radius {r}")
        world(f"disk-radius-{r}", f'Shape "disk" "float radius" {r}\n', note=f"disk radius {r}")
    for r in ("0", "1e-30", "1e38"):
        world(f"emitting-sphere-radius-{r}", "", light=A.light_with('"rgb L" [ 1 1 1 ]',
                                                                     f'Translate 0 2 0 Shape "sphere" "float radius" {r}\n'),
              note=f"an emitting sphere of radius {r}")
        world(f"emitting-disk-radius-{r}", "", light=A.light_with('"rgb L" [ 1 1 1 ]',
                                                                   f'Translate 0 2 0 Rotate 90 1 0 0 '
                                                                   f'Shape "disk" "float radius" {r}\n'),
              note=f"an emitting disk of radius {r}")
    world("disk-innerradius", 'Shape "disk" "float innerradius" 0.5\n', note="disk innerradius (partial)")
    world("sphere-zmin", 'Shape "sphere" "float zmin" 0\n', note="partial sphere")
    world("bilinear-nonplanar", 'Shape "bilinearmesh" "point3 P" [ 0 0 0  1 0 0  0 0 1  1 1 1 ]\n',
          note="a non-planar bilinear patch")
    world("bilinear-bowtie", 'Shape "bilinearmesh" "point3 P" [ 0 0 0  1 0 0  1 0 1  0 0 1 ]\n',
          note="a self-intersecting (bow-tie) bilinear patch")
    world("unknown-shape", 'Shape "curve"\n', note="an unsupported shape")
    return cases


# --------------------------------------------------------------------------
# 6. lights and materials

def lights() -> list[Case]:
    f = "lights/"
    cases = []

    def light(name, params, *, expect=None, extra=None, note=""):
        cases.append(pb(f + name, A.pbrt_scene(light=A.light_with(params)), expect=expect, extra=extra,
                        note=note or params))

    light("scale-neg", '"rgb L" [ 1 1 1 ] "float scale" [ -1 ]', expect=REFUSED,
          note="negative light scale (must be refused)")
    light("scale-neg-twosided", '"rgb L" [ 1 1 1 ] "float scale" [ -1 ] "bool twosided" true', expect=REFUSED,
          note="negative scale on a two-sided light")
    # A negative light beside a positive one (a negative total power), under
    # every light selection.
    mixed = A.pbrt_scene(light=A.light_with('"rgb L" [ 1 1 1 ] "float scale" -1') + A.light_with(
        '"rgb L" [ 1 1 1 ]', 'Translate 0 0.5 0 Rotate 90 1 0 0 Shape "disk" "float radius" 0.5\n'))
    for i, sel in enumerate(LIGHT_SELECTS):
        cases.append(pb(f + f"scale-neg-mixed-{sel}", mixed, expect=REFUSED,
                        extra=["--light-select", sel, "--light-sampling", LIGHT_SAMPLINGS[(3 * i) % 6]],
                        note=f"a negative light beside a positive one, --light-select {sel}"))
    light("scale-1e38", '"rgb L" [ 1 1 1 ] "float scale" [ 1e38 ]')
    light("scale-1e39", '"rgb L" [ 1 1 1 ] "float scale" [ 1e39 ]', note="scale 1e39 (not a float)")
    light("L-1e38", '"rgb L" [ 1e38 1e38 1e38 ]', note="radiance 1e38")
    light("L-fltmax-scale-10", '"rgb L" [ 3.4028235e38 1 1 ] "float scale" 10', note="radiance overflows")
    light("L-neg", '"rgb L" [ -1 -1 -1 ]', note="negative radiance")
    for t in ("0", "-1", "1e9", "1e-30", "1e30"):
        light(f"blackbody-{t}", f'"blackbody L" [ {t} ]', note=f"blackbody {t} K")
    light("twosided", '"rgb L" [ 1 1 1 ] "bool twosided" true', expect=RENDERED, note="two-sided")
    light("spectrum-named", '"spectrum L" "stdillum-D65"', note="a named spectrum")
    light("spectrum-unknown", '"spectrum L" "nonexistent-spectrum"', note="an unknown named spectrum")
    light("power", '"rgb L" [ 1 1 1 ] "float power" 10', note="power (refused unless supported)")
    light("filename", '"rgb L" [ 1 1 1 ] "string filename" "missing.png"', note="an emission image")
    cases.append(pb(f + "unknown-arealight", A.pbrt_scene(light=A.LIGHT.replace('"diffuse"', '"bogus"')),
                    note="an unknown area light"))
    cases.append(pb(f + "lightsource-point", A.BASE_PBRT + 'LightSource "point" "rgb I" [ 1 1 1 ]\n',
                    note="a point light (refused unless supported)"))
    cases.append(pb(f + "no-lights", A.pbrt_scene(light=""), note="no light at all"))
    # Every light black: the image is black, and it MUST render, whatever the
    # light selection, strategy or integrator.
    black = A.pbrt_scene(light=A.light_with('"rgb L" [ 0 0 0 ]'))
    zero_scale = A.pbrt_scene(light=A.light_with('"rgb L" [ 1 1 1 ] "float scale" 0'))
    two_black = A.pbrt_scene(light=A.light_with('"rgb L" [ 0 0 0 ]') + A.light_with(
        '"rgb L" [ 0 0 0 ] "bool twosided" true', 'Translate 0 1 0 Shape "disk" "float radius" 0.5\n'))
    # Every light selection meets every integrator and every strategy at
    # least once (rotated rather than crossed, to keep the run short).
    for i, sel in enumerate(LIGHT_SELECTS):
        for j, (scene, tag) in enumerate(((black, "L0"), (two_black, "two-black"))):
            integ = INTEGRATORS[(i + j) % 3]
            strat = LIGHT_SAMPLINGS[(2 * i + j) % len(LIGHT_SAMPLINGS)]
            cases.append(pb(f + f"{tag}-{sel}", scene, expect=RENDERED,
                            extra=["--light-select", sel, "--integrator", integ, "--light-sampling", strat],
                            note=f"{tag}: every light black; --light-select {sel} --integrator {integ} "
                                 f"--light-sampling {strat}"))
    cases.append(pb(f + "scale0", zero_scale, expect=RENDERED, note="scale 0 on the only light"))
    cases.append(pb(f + "L0-auto-pbrt-bvh", two_black, expect=RENDERED,
                    extra=["--light-select", "pbrt-bvh", "--light-sampling", "auto"],
                    note="two black lights, auto strategy, pbrt-bvh selection"))
    # Stiff but valid lights, each under two strategies (rotated over all of
    # them): they MUST render, without non-finite samples.
    stiff = {
        "tiny-triangle": A.tri_mesh([0, 2, 0, 1e-6, 2, 0, 0, 2, 1e-6], [0, 1, 2]),
        "sliver-triangle": A.tri_mesh([-1, 2, 0, 1, 2, 0, 0, 2, 1e-7], [0, 1, 2]),
        "grazing-triangle": A.tri_mesh([-1, 0, 0, 1, 0, 0, 0, 1, 0], [0, 2, 1]),
        "tiny-disk": 'Translate 0 2 0 Rotate 90 1 0 0 Shape "disk" "float radius" 1e-6\n',
        "tiny-sphere": 'Translate 0 2 0 Shape "sphere" "float radius" 1e-6\n',
        "sphere-on-floor": 'Translate 0 1 0 Shape "sphere" "float radius" 1\n',
    }
    for i, (name, shape) in enumerate(stiff.items()):
        for strat in (LIGHT_SAMPLINGS[(2 * i) % 6], LIGHT_SAMPLINGS[(2 * i + 1) % 6]):
            cases.append(pb(f + f"stiff-{name}-{strat}", A.pbrt_scene(light=A.light_with('"rgb L" [ 1 1 1 ]', shape)),
                            expect=RENDERED, extra=["--light-sampling", strat, "--max-depth", "2"],
                            note=f"a stiff light ({name}) sampled by {strat}"))

    # Materials.
    def mat(name, material, *, expect=None, note=""):
        cases.append(pb(f + name, A.pbrt_scene(floor=material + "\n" + A.FLOOR.split("\n", 1)[1]),
                        expect=expect, note=note or material))

    for r in ("-1", "1e30", "nan", "0", "1e-45", "inf"):
        mat(f"conductor-roughness-{r}", f'Material "conductor" "float roughness" {r}')
        if r in ("-1", "1e30", "1e-45"):
            mat(f"dielectric-roughness-{r}", f'Material "dielectric" "float roughness" {r}')
    mat("conductor-aniso-extreme", 'Material "conductor" "float uroughness" 1e-30 "float vroughness" 1e30')
    for e in ("0", "-1", "1e30", "1", "1e-30"):
        mat(f"dielectric-eta-{e}", f'Material "dielectric" "float eta" {e}')
        mat(f"conductor-eta-{e}", f'Material "conductor" "rgb eta" [ {e} {e} {e} ] "rgb k" [ 0 0 0 ]')
    mat("dielectric-eta-named", 'Material "dielectric" "spectrum eta" "glass-BK7"', expect=RENDERED)
    for name, v in {"reflectance-2": "2 2 2", "reflectance-neg": "-1 -1 -1",
                    "reflectance-1e38": "1e38 1e38 1e38"}.items():
        mat(f"diffuse-{name}", f'Material "diffuse" "rgb reflectance" [ {v} ]')
        mat(f"conductor-{name}", f'Material "conductor" "rgb reflectance" [ {v} ]')
    # diffusetransmission: defaults, scale at the extremes (clamped at the hit
    # as pbrt-v4 clamps it), values beyond 1, a textured transmittance; and
    # what must be refused.
    for name, params in {"default": "", "scale-1e30": '"float scale" 1e30', "scale-neg": '"float scale" -1',
                         "scale-0": '"float scale" 0', "t-2": '"rgb transmittance" [ 2 2 2 ]',
                         "white": '"rgb reflectance" [ 1 1 1 ] "rgb transmittance" [ 1 1 1 ]',
                         "t-checker": '"texture transmittance" "checks"'}.items():
        pre = ('Texture "checks" "spectrum" "checkerboard" "float uscale" 1e30 "rgb tex1" [ 1 1 1 ] '
               '"rgb tex2" [ 0 0 0 ]\n') if "checker" in name else ""
        mat(f"diffusetransmission-{name}", pre + f'Material "diffusetransmission" {params}', expect=RENDERED)
    for name, params in {"r-neg": '"rgb reflectance" [ -1 -1 -1 ]', "scale-string": '"string scale" "x"',
                         "unknown-param": '"float sigma" 1', "t-no-texture": '"texture transmittance" "nope"',
                         "scale-1e39": '"float scale" 1e39'}.items():
        mat(f"diffusetransmission-{name}", f'Material "diffusetransmission" {params}', expect=REFUSED)
    for e in ("1", "1e30", "1e-30"):
        mat(f"thindielectric-eta-{e}", f'Material "thindielectric" "float eta" {e}', expect=RENDERED)
    mat("thindielectric-default", 'Material "thindielectric"', expect=RENDERED)
    mat("thindielectric-eta-named", 'Material "thindielectric" "spectrum eta" "glass-BAF10"', expect=RENDERED)
    for e in ("0", "-1"):
        mat(f"thindielectric-eta-{e}", f'Material "thindielectric" "float eta" {e}', expect=REFUSED)
    mat("thindielectric-roughness", 'Material "thindielectric" "float roughness" 0.1', expect=REFUSED)
    mat("interface-floor", 'Material "interface"', expect=RENDERED, note="the floor no surface")
    mat("none-floor", 'Material "none"', expect=RENDERED, note="the deprecated name of interface")
    mat("interface-param", 'Material "interface" "float eta" 1.33', expect=REFUSED)
    cases.append(pb(f + "interface-light", A.pbrt_scene(
        light='AttributeBegin\nMaterial "interface"\nAreaLightSource "diffuse" "rgb L" [ 1 1 1 ]\n' + A.LIGHT_MESH +
              'AttributeEnd\n'), expect=REFUSED, note="an area light on an interface shape"))
    # coateddiffuse and coatedconductor: defaults, every parameter at its
    # extremes (a slab of 0 and 1e30, g at +-1 and beyond, a white medium,
    # walks of 0 and 1000 events, 1000 walks), textured parameters; and what
    # must be refused.
    pre_tex = ('Texture "checks" "spectrum" "checkerboard" "float uscale" 1e30 "rgb tex1" [ 1 1 1 ] '
               '"rgb tex2" [ 0 0 0 ]\nTexture "fchecks" "float" "checkerboard" "float tex1" 0 "float tex2" 1e30\n')
    for name, params in {"default": "", "thickness-0": '"float thickness" 0', "thickness-1e30": '"float thickness" 1e30',
                         "thickness-1e-45": '"float thickness" 1e-45',
                         "slab-white": '"rgb albedo" [ 1 1 1 ] "float thickness" 5 "float g" 0.9',
                         "g-1": '"rgb albedo" [ 0.5 0.5 0.5 ] "float g" 1', "g-neg-5": '"rgb albedo" [ 0.5 0.5 0.5 ] "float g" -5',
                         "maxdepth-0": '"integer maxdepth" 0', "maxdepth-1000": '"integer maxdepth" 1000 "rgb albedo" [ 1 1 1 ]',
                         "nsamples-16": '"integer nsamples" 16', "eta-1": '"float eta" 1', "eta-1e30": '"float eta" 1e30',
                         "eta-1e-30": '"float eta" 1e-30', "eta-named": '"spectrum eta" "glass-BK7"',
                         "rough-extreme": '"float uroughness" 1e-30 "float vroughness" 1e30',
                         "reflectance-2": '"rgb reflectance" [ 2 2 2 ]', "albedo-2": '"rgb albedo" [ 2 2 2 ]',
                         "textured": '"texture reflectance" "checks" "texture albedo" "checks" "texture thickness" "fchecks" '
                                     '"texture g" "fchecks" "texture roughness" "fchecks"'}.items():
        mat(f"coateddiffuse-{name}", (pre_tex if "textured" in name else "") + f'Material "coateddiffuse" {params}',
            expect=RENDERED)
    for name, params in {"default": "", "smooth-smooth": '"float interface.roughness" 0 "float conductor.roughness" 0',
                         "rough-rough": '"float interface.roughness" 0.3 "float conductor.roughness" 0.5 "rgb albedo" [ 0.5 0.5 0.5 ]',
                         "reflectance": '"rgb reflectance" [ 0.9 0.6 0.3 ]', "reflectance-1": '"rgb reflectance" [ 1 1 1 ]',
                         "gold": '"spectrum conductor.eta" "metal-Au-eta" "spectrum conductor.k" "metal-Au-k"',
                         "ieta-1e30": '"float interface.eta" 1e30', "ieta-1": '"float interface.eta" 1',
                         "k-0": '"rgb conductor.eta" [ 1.5 1.5 1.5 ] "rgb conductor.k" [ 0 0 0 ]'}.items():
        mat(f"coatedconductor-{name}", f'Material "coatedconductor" {params}', expect=RENDERED)
    for name, params in {"nsamples-0": '"integer nsamples" 0', "nsamples-1001": '"integer nsamples" 1001',
                         "maxdepth-neg": '"integer maxdepth" -1', "maxdepth-float": '"float maxdepth" 3',
                         "thickness-neg": '"float thickness" -1', "eta-0": '"float eta" 0', "eta-texture": '"texture eta" "checks"',
                         "albedo-neg": '"rgb albedo" [ -1 0 0 ]', "roughness-neg": '"float roughness" -0.1',
                         "unknown-param": '"float sigma" 1', "conductor-param": '"float conductor.roughness" 0.1'}.items():
        mat(f"coateddiffuse-{name}", f'Material "coateddiffuse" {params}', expect=REFUSED)
    for name, params in {"both-ior": '"rgb reflectance" [ 0.5 0.5 0.5 ] "rgb conductor.eta" [ 1 1 1 ]',
                         "k-neg": '"rgb conductor.k" [ -1 -1 -1 ]', "ieta-neg": '"float interface.eta" -1',
                         "bare-roughness": '"float roughness" 0.1', "bare-eta": '"float eta" 1.5'}.items():
        mat(f"coatedconductor-{name}", f'Material "coatedconductor" {params}', expect=REFUSED)
    # mix: amounts at and beyond the ends, a textured amount, a mix of
    # mixes; a missing or interface material, one material, refused.
    named = ('MakeNamedMaterial "a" "string type" "diffuse"\nMakeNamedMaterial "b" "string type" "coateddiffuse"\n'
             'MakeNamedMaterial "i" "string type" "interface"\n')
    for name, params in {"default": "", "amount-0": '"float amount" 0', "amount-1": '"float amount" 1',
                         "amount-neg": '"float amount" -5', "amount-nan-ish": '"float amount" 1e30',
                         "textured": '"texture amount" "fchecks"'}.items():
        mat(f"mix-{name}", (pre_tex if "textured" in name else "") + named +
            f'Material "mix" "string materials" [ "a" "b" ] {params}', expect=RENDERED)
    mat("mix-of-mix", named + 'MakeNamedMaterial "m" "string type" "mix" "string materials" [ "a" "b" ]\n'
        'Material "mix" "string materials" [ "m" "a" ] "float amount" 0.3', expect=RENDERED)
    for name, params in {"missing": '"string materials" [ "a" "nope" ]', "interface": '"string materials" [ "a" "i" ]',
                         "one": '"string materials" [ "a" ]', "three": '"string materials" [ "a" "b" "a" ]',
                         "none": '', "not-string": '"float materials" [ 1 2 ]',
                         "bad-amount": '"string materials" [ "a" "b" ] "string amount" "x"'}.items():
        mat(f"mix-{name}", named + f'Material "mix" {params}', expect=REFUSED)
    mat("unknown-material", 'Material "subsurface"', note="an unsupported material")
    # pbrt-v4's integrators: those that converge to path's image render
    # (with mis), the others and the visualisations are refused.
    for name, integ in {"bdpt": '"bdpt"', "mlt": '"mlt" "integer mutationsperpixel" 4', "sppm": '"sppm" "float radius" 0.1',
                        "simplepath": '"simplepath" "bool samplelights" false', "simplevolpath": '"simplevolpath"'}.items():
        cases.append(pb(f + f"integrator-{name}", A.pbrt_scene().replace("WorldBegin", f"Integrator {integ}\nWorldBegin", 1),
                        expect=RENDERED, note=f"Integrator {name}, rendered by mis"))
    for name, integ in {"randomwalk": '"randomwalk"', "lightpath": '"lightpath"', "ao": '"ambientocclusion"',
                        "function": '"function"', "bdpt-vis": '"bdpt" "bool visualizeweights" true',
                        "simplepath-nobsdf": '"simplepath" "bool samplebsdf" false', "mlt-sigma": '"mlt" "float sigma" -1',
                        "sppm-bogus": '"sppm" "integer iterations" 64'}.items():
        cases.append(pb(f + f"integrator-{name}", A.pbrt_scene().replace("WorldBegin", f"Integrator {integ}\nWorldBegin", 1),
                        expect=REFUSED, note=f"Integrator {name}"))
    mat("named-undefined", 'NamedMaterial "nope"', note="NamedMaterial of nothing")
    mat("makenamed-no-type", 'MakeNamedMaterial "m"\nNamedMaterial "m"', note="MakeNamedMaterial without a type")
    # An emitter whose own material reflects hugely, under a huge light.
    cases.append(pb(f + "emitter-reflects-1e30", A.pbrt_scene(
        light='AttributeBegin\nMaterial "diffuse" "rgb reflectance" [ 1e30 1e30 1e30 ]\n'
              'AreaLightSource "diffuse" "rgb L" [ 1e30 1e30 1e30 ]\n' + A.LIGHT_MESH + 'AttributeEnd\n',
        floor='Material "diffuse" "rgb reflectance" [ 1e30 1e30 1e30 ]\n' + A.FLOOR.split("\n", 1)[1]),
        extra=["--max-depth", "8"], note="reflectance 1e30 everywhere under L 1e30 (radiance overflows)"))
    return cases


# --------------------------------------------------------------------------
# 7. PLY files that lie

def ply() -> list[Case]:
    f = "ply/"
    cases = []
    V, F = A.QUAD_V, A.QUAD_F

    def mesh(name, data, *, fname="m.ply", expect=None, note="", slow=False, entries=None):
        text = A.pbrt_scene(floor='Material "diffuse"\n' + A.ply_shape(fname))
        ents = entries if entries is not None else [file(fname, data)]
        cases.append(pb(f + name, text, entries=ents, names=[fname], expect=expect, note=note, slow=slow))

    def head(vn=4, fn=2, fmt="ascii", props=("float x", "float y", "float z"),
             face="property list uchar int vertex_indices", extra=()) -> str:
        lines = ["ply", f"format {fmt} 1.0", f"element vertex {vn}"]
        lines += [f"property {p}" for p in props]
        lines += [f"element face {fn}", face, *extra, "end_header"]
        return "\n".join(lines) + "\n"

    body_v = "".join(f"{x} {y} {z}\n" for x, y, z in V)
    body_f = "".join("3 " + " ".join(map(str, t)) + "\n" for t in F)
    mesh("valid-ascii", A.ply_ascii(V, F), expect=RENDERED, note="a valid ASCII PLY")
    mesh("valid-binary-le", A.ply_binary(V, F), expect=RENDERED, note="a valid little-endian PLY")
    mesh("valid-binary-be", A.ply_binary(V, F, big_endian=True), expect=RENDERED, note="a valid big-endian PLY")
    mesh("valid-gz", A.gz(A.ply_ascii(V, F)), fname="m.ply.gz", expect=RENDERED, note="a valid .ply.gz")
    mesh("valid-quad", A.ply_ascii(V, [(0, 3, 2, 1)]), expect=RENDERED, note="a planar quad")
    mesh("extra-properties", head(props=("float x", "float y", "float z", "uchar red"))
         + "".join(f"{x} {y} {z} 255\n" for x, y, z in V) + body_f, note="an extra vertex property")
    mesh("count-larger-ascii", head(vn=10) + body_v + body_f, note="vertex count larger than the file holds")
    mesh("face-count-larger-ascii", head(fn=10) + body_v + body_f, note="face count larger than the file holds")
    for c in ("1000000000000000000", "-1", "abc", "4294967300", "2147483648", "18446744073709551620", "4.5"):
        if c in ("1000000000000000000", "-1", "abc", "4294967300"):
            mesh(f"vertex-count-{c}", head(vn=c) + body_v + body_f, note=f"ASCII vertex count {c}")
        if c in ("abc", "4.5"):
            continue
        mesh(f"binary-vertex-count-{c}", lambda c=c: A.ply_binary(V, F).replace(b"element vertex 4",
                                                                                   f"element vertex {c}".encode()),
             note=f"binary vertex count {c}")
    mesh("face-count-1e18-binary", lambda: A.ply_binary(V, F).replace(b"element face 2",
                                                                       b"element face 1000000000000000000"),
         note="binary face count 10^18")
    mesh("unknown-property-type", head(props=("quaternion x", "float y", "float z")) + body_v + body_f,
         note="unknown property type")
    mesh("list-count-float", head(face="property list float int vertex_indices") + body_v + body_f,
         note="list count of float type")
    mesh("list-count-negative", head(face="property list int int vertex_indices") + body_v + "-3 0 1 2\n3 0 3 2\n",
         note="a negative list count")
    mesh("list-count-huge-binary", lambda: _ply_face_count_huge(), note="binary list count 2^31-1")
    mesh("no-x", head(props=("float y", "float z")) + "".join(f"{y} {z}\n" for _, y, z in V) + body_f,
         note="a vertex element without x")
    mesh("face-before-vertex", "ply\nformat ascii 1.0\nelement face 2\nproperty list uchar int vertex_indices\n"
                               "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
         + body_f + body_v, note="face element before the vertex element")
    mesh("index-out-of-range", head() + body_v + "3 0 1 4\n3 0 3 2\n", expect=REFUSED, note="index 4 of 4 vertices")
    mesh("index-negative", head() + body_v + "3 0 -1 2\n3 0 3 2\n", expect=REFUSED, note="index -1")
    mesh("index-2^31", head(face="property list uchar uint vertex_indices") + body_v + "3 0 2147483648 2\n3 0 3 2\n",
         expect=REFUSED, note="index 2^31 as uint")
    mesh("no-end-header", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                          "property float z\n" + body_v, note="no end_header")
    mesh("bad-magic", "plx\n" + (head() + body_v + body_f)[4:], note="'plx' magic")
    mesh("empty-file", b"", note="an empty PLY")
    mesh("format-unknown", head(fmt="binary_middle_endian") + body_v + body_f, note="unknown format")
    mesh("header-line-1MB", head().replace("end_header", "comment " + "x" * (1 << 20) + "\nend_header")
         + body_v + body_f, note="a 1 MB header line")
    mesh("binary-labelled-ascii", lambda: A.ply_binary(V, F, label="ascii"), note="binary data labelled ascii")
    mesh("ascii-labelled-binary", head(fmt="binary_little_endian") + body_v + body_f,
         note="ASCII data labelled binary")
    mesh("wrong-endianness", lambda: A.ply_binary(V, F, label="binary_big_endian"),
         note="little-endian data labelled big-endian")
    mesh("truncated-ascii", (head() + body_v + body_f)[:-12], note="ASCII body cut short")
    mesh("truncated-binary", lambda: A.ply_binary(V, F)[:-10], note="binary body cut short")
    mesh("truncated-binary-half", lambda: _cut_body(A.ply_binary(V, F)), note="binary body cut in half")
    mesh("ascii-1e39", head() + body_v.replace("-1 0 -1", "-1 1e39 -1") + body_f, note="1e39 in an ASCII PLY")
    # Non-finite values: all of them must be refused cleanly.
    for prop, props in (("x", "x y z"), ("nx", "x y z nx ny nz"), ("u", "x y z u v")):
        for bad in ("nan", "inf"):
            if bad == "inf" and prop != "x":
                continue
            expect = REFUSED
            more = {"nx": [0.0, 1.0, 0.0], "u": [0.5, 0.5], "x": []}[prop]
            bad_v = [list(v) + more for v in V]
            bad_v[1][props.split().index(prop)] = float(bad)
            bad_v = [tuple(v) for v in bad_v]
            mesh(f"{bad}-in-{prop}-binary", lambda bv=bad_v, p=props: A.ply_binary(bv, F, props=p), expect=expect,
                 note=f"{bad} in {prop} (binary): must be refused")
            mesh(f"{bad}-in-{prop}-ascii", lambda bv=bad_v, p=props: A.ply_ascii(bv, F, props=p), expect=expect,
                 note=f"{bad} in {prop} (ASCII): must be refused")
    mesh("normals-zero", lambda: A.ply_binary([tuple(list(v) + [0, 0, 0]) for v in V], F, props="x y z nx ny nz"),
         note="zero vertex normals")
    mesh("gz-bomb", lambda: A.gz_bomb(head()), fname="m.ply.gz", slow=True,
         note="a PLY header then 3.2 GiB of zeros (gzip bomb)")
    mesh("sparse-huge", None, entries=[sparse("m.ply", head(vn=700_000_000, fn=1, fmt="binary_little_endian"),
                                              (700_000_000 * 12) + (1 << 20))], slow=True,
         note="a binary PLY of 7e8 vertices that the (sparse) file really holds: 8.4 GB")
    mesh("gz-truncated", lambda: A.gz(A.ply_ascii(V, F) * 20)[:100], fname="m.ply.gz", note="a truncated .ply.gz")
    mesh("gz-not-gzip", A.ply_ascii(V, F), fname="m.ply.gz", note="a plain PLY named .ply.gz")
    mesh("dev-zero", None, entries=[symlink("m.ply", "/dev/zero")], slow=True, note="/dev/zero as the PLY")
    mesh("dev-urandom", None, entries=[symlink("m.ply", "/dev/urandom")], slow=True, note="/dev/urandom as the PLY")
    mesh("fifo", None, entries=[fifo("m.ply")], slow=True, note="a FIFO as the PLY")
    mesh("directory", None, entries=[directory("m.ply")], note="a directory as the PLY")
    mesh("missing", None, entries=[], note="a missing PLY")
    for n in (0, 1, 2, 5, 255):
        face = (n,) + tuple(i % 4 for i in range(n))
        mesh(f"face-of-{n}", head(fn=1) + body_v + " ".join(map(str, face)) + "\n",
             note=f"a face of {n} vertices")
    mesh("quad-nonplanar", head(fn=1) + body_v.replace("1 0 1", "1 1 1") + "4 0 3 2 1\n",
         note="a non-planar quad (refused unless patches are supported)")
    mesh("vertices-no-faces", head(fn=0) + body_v, note="vertices and no faces")
    return cases


def _ply_face_count_huge() -> bytes:
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack("<3f", *v) for v in A.QUAD_V)
    return head + body + struct.pack("<i", 2 ** 31 - 1) + struct.pack("<3i", 0, 1, 2)


def _cut_body(data: bytes) -> bytes:
    i = data.index(b"end_header\n") + len(b"end_header\n")
    return data[: i + (len(data) - i) // 2]


# --------------------------------------------------------------------------
# 8. textures

def texture() -> list[Case]:
    f = "texture/"
    cases = []
    uses = 'Material "diffuse" "texture reflectance" "t"\n'

    def tex(name, fname, entries, *, params="", expect=None, note="", slow=False, kind="spectrum", use=uses):
        decl = f'Texture "t" "{kind}" "imagemap" "string filename" "{fname}" {params}\n'
        text = A.pbrt_scene(world_head=decl, floor=use + A.FLOOR.split("\n", 1)[1])
        cases.append(pb(f + name, text, entries=entries, names=[fname], expect=expect, note=note, slow=slow))

    checker = A.checker_png
    tex("valid", "t.png", [file("t.png", checker)], expect=RENDERED, note="the shipped checker.png")
    tex("dev-zero", "t.png", [symlink("t.png", "/dev/zero")], slow=True, note="/dev/zero as the image")
    tex("dev-zero-exr", "t.exr", [symlink("t.exr", "/dev/zero")], slow=True, note="/dev/zero named .exr")
    tex("dev-urandom", "t.png", [symlink("t.png", "/dev/urandom")], slow=True, note="/dev/urandom as the image")
    tex("dev-null", "t.png", [symlink("t.png", "/dev/null")], note="/dev/null as the image")
    tex("fifo", "t.png", [fifo("t.png")], slow=True, note="a FIFO as the image")
    tex("directory", "t.png", [directory("t.png")], note="a directory as the image")
    tex("missing", "t.png", [], note="a missing image")
    tex("empty-name", "", [], note='filename ""')
    tex("zero-byte-png", "t.png", [file("t.png", b"")], note="a zero-byte .png")
    tex("truncated-png", "t.png", [file("t.png", lambda: checker()[: len(checker()) // 2])],
        note="checker.png cut in half")
    tex("text-named-png", "t.png", [file("t.png", "this is not an image\n")], note="a text file named .png")
    tex("bad-crc-png", "t.png", [file("t.png", lambda: _flip_crc(A.png(2, 2)))], note="a PNG with a bad CRC")
    tex("corrupt-idat", "t.png", [file("t.png", lambda: _corrupt_idat(A.png(4, 4)))], note="corrupt IDAT data")
    for w, h in ((100000, 100000), (16384, 16384), (1, 2 ** 31 - 1), (0, 0)):
        tex(f"ihdr-lies-{w}x{h}", "t.png", [file("t.png", lambda w=w, h=h: A.png_lying_size(w, h))], slow=True,
            note=f"a PNG whose IHDR claims {w} x {h}")
    tex("png-1x1", "t.png", [file("t.png", A.png(1, 1))], expect=RENDERED, note="a 1x1 PNG")
    tex("png-16bit", "t.png", [file("t.png", A.png(3, 2, bit_depth=16))], expect=RENDERED, note="a 16-bit PNG")
    tex("png-gray", "t.png", [file("t.png", A.png(3, 2, color_type=0))], expect=RENDERED, note="a grayscale PNG")
    tex("png-gray16", "t.png", [file("t.png", A.png(3, 2, color_type=0, bit_depth=16))], expect=RENDERED,
        note="a 16-bit grayscale PNG")
    tex("png-rgba", "t.png", [file("t.png", A.png(3, 2, color_type=6))], expect=RENDERED, note="an RGBA PNG")
    nan, inf = float("nan"), float("inf")
    for ext, make in (("pfm", A.pfm), ("exr", A.exr)):
        tex(f"{ext}-valid", f"t.{ext}", [file(f"t.{ext}", make(2, 2, [0.5]))], expect=RENDERED,
            note=f"a valid {ext.upper()}")
        for name, vals in (("nan", [nan, 0.5, 0.5]), ("inf", [inf, 0.5, 0.5]), ("neg", [-1.0, -0.5, -2.0]),
                           ("huge", [3.4e38, 3.4e38, 3.4e38])):
            if ext == "pfm" and name in ("neg", "huge"):
                continue
            tex(f"{ext}-{name}", f"t.{ext}", [file(f"t.{ext}", make(2, 2, vals))],
                note=f"a {ext.upper()} with {name} texels")
        tex(f"{ext}-nan-roughness", f"t.{ext}", [file(f"t.{ext}", make(2, 2, [nan]))], kind="float",
            use='Material "conductor" "texture roughness" "t"\n', note=f"NaN {ext.upper()} as a roughness")
    tex("pfm-sparse-huge", "t.pfm", [sparse("t.pfm", b"PF\n40000 40000\n-1.0\n", 40000 * 40000 * 12 + 64)],
        slow=True, note="a 40000 x 40000 PFM that the (sparse) file really holds: 19 GB")
    tex("pfm-truncated", "t.pfm", [file("t.pfm", lambda: A.pfm(4, 4, [0.5])[:30])], note="a truncated PFM")
    tex("pfm-size-lies", "t.pfm", [file("t.pfm", lambda: A.pfm(2, 2, [0.5]).replace(b"2 2", b"99999 99999"))],
        slow=True, note="a PFM header claiming 99999 x 99999")
    tex("exr-truncated", "t.exr", [file("t.exr", lambda: A.exr(4, 4, [0.5])[:-40])], note="a truncated EXR")
    for enc in ("gamma abc", "gamma 0", "gamma 1e39", "bogus"):
        tex(f"encoding-{enc.replace(' ', '-')}", "t.png", [file("t.png", checker)],
            params=f'"string encoding" "{enc}"', note=f'encoding "{enc}"')
    for name, p in {"scale-1e38": '"float scale" 1e38', "scale-neg": '"float scale" -1',
                    "uscale-0": '"float uscale" 0', "uscale-1e38": '"float uscale" 1e38',
                    "udelta-1e38": '"float udelta" 1e38', "wrap-bogus": '"string wrap" "bogus"',
                    "invert": '"bool invert" true'}.items():
        tex(name, "t.png", [file("t.png", checker)], params=p, note=p)
    # Texture declarations that are wrong in themselves.
    decls = {
        "class-unknown": 'Texture "t" "spectrum" "ptex" "string filename" "t.ptx"\n',
        "scale-of-undefined": 'Texture "t" "spectrum" "scale" "texture tex" "nope"\n',
        "self-reference": 'Texture "t" "spectrum" "scale" "texture tex" "t"\n',
        "float-as-spectrum": 'Texture "t" "float" "constant" "float value" 0.5\n',
        "checkerboard-uscale-1e38": 'Texture "t" "spectrum" "checkerboard" "float uscale" 1e38\n',
        "constant-nan": 'Texture "t" "spectrum" "constant" "rgb value" [ nan 0 0 ]\n',
    }
    for name, d in decls.items():
        text = A.pbrt_scene(world_head=d, floor=uses + A.FLOOR.split("\n", 1)[1])
        cases.append(pb(f + name, text, note=d.strip()))
    cases.append(pb(f + "material-uses-undefined", A.pbrt_scene(floor=uses + A.FLOOR.split("\n", 1)[1]),
                    note="a material using an undefined texture"))
    return cases


def _flip_crc(data: bytes) -> bytes:
    # The IHDR CRC sits right after the 8-byte signature, 8-byte chunk head and 13 data bytes.
    i = 8 + 8 + 13
    return data[:i] + bytes(b ^ 0x55 for b in data[i:i + 4]) + data[i + 4:]


def _corrupt_idat(data: bytes) -> bytes:
    i = data.index(b"IDAT") + 6
    body = bytearray(data)
    for k in range(i, min(i + 8, len(body) - 16)):
        body[k] ^= 0xA5
    # Re-make the CRC so that only the zlib data is wrong.
    start = data.index(b"IDAT") - 4
    (n,) = struct.unpack(">I", data[start:start + 4])
    chunk = bytes(body[start + 4:start + 8 + n])
    body[start + 8 + n:start + 12 + n] = struct.pack(">I", zlib.crc32(chunk))
    return bytes(body)


# --------------------------------------------------------------------------
# 9. command line

def flags() -> list[Case]:
    f = "flags/"
    cases = []
    base = [file("scene.pbrt", A.BASE_PBRT)]
    film = 'Film "rgb" "integer xresolution" [ {x} ] "integer yresolution" [ 8 ]\n'
    quick = ["--spp", "1", "--threads", "1", "--quiet"]
    for x in ("0", "-1", "16385", "1000000000", "16384.5"):
        text = A.pbrt_scene(options=film.format(x=x) + A.OPTIONS.split("\n", 1)[1])
        cases.append(pb(f + f"film-xres-{x}", text, flags=quick, expect=REFUSED, names=["xresolution"],
                        note=f"Film xresolution {x} (no --width)"))

    def render(name, args, *, expect=None, names=(), note="", entries=None, flags_=None, out=None):
        # A refusal of a command line names the flag (any flag of the case).
        names = list(names) or [a for a in args if a.startswith("-") and a not in small]
        c = render_case(f + name, "scene.pbrt", list(entries if entries is not None else base),
                        flags=flags_ if flags_ is not None else ["--threads", "1", "--quiet"],
                        extra=args, names=names, expect=expect, note=note or " ".join(args))
        if out is not None:  # another output image than out.png
            i = c.argv.index("-o")
            c.argv[i + 1] = out
            c.outputs = [out if o == "out.png" else o for o in c.outputs]
            c.image = out
            c.names += [out, "-o", "--output"]
        cases.append(c)

    small = ["--width", "8", "--height", "8", "--spp", "1"]
    for w in ("0", "-1", "100000", "8.5", "", "99999999999999999999"):
        render(f"width-{w or 'empty'}", ["--width", w, "--height", "8", "--spp", "1"], expect=REFUSED,
               names=["--width", "width"])
    render("height-0", ["--width", "8", "--height", "0", "--spp", "1"], expect=REFUSED, names=["--height"])
    render("size-max", ["--width", "16384", "--height", "1", "--spp", "1", "--max-depth", "0"], expect=RENDERED,
           note="the largest width (one row, depth 0)")
    for s in ("0", "-1", "10000000000", "1048577"):
        render(f"spp-{s}", ["--width", "8", "--height", "8", "--spp", s], expect=REFUSED, names=["--spp"])
    for d in ("-1", "1000000000"):
        render(f"max-depth-{d}", small + ["--max-depth", d], expect=REFUSED, names=["--max-depth"])
    render("max-depth-0", small + ["--max-depth", "0"], expect=RENDERED)
    render("max-depth-100000", small + ["--max-depth", "100000"], expect=RENDERED)
    for r in ("-1", "1000000000"):
        render(f"rr-depth-{r}", small + ["--rr-depth", r], expect=REFUSED)
    render("threads-0", ["--width", "8", "--height", "8", "--spp", "1", "--threads", "0"], flags_=["--quiet"],
           expect=REFUSED, names=["--threads"])
    render("threads-1e6", ["--width", "8", "--height", "8", "--spp", "1", "--threads", "1000000"],
           flags_=["--quiet"], note="--threads 10^6")
    # A seed that an unsigned 64-bit integer cannot hold is a bad command line:
    # accepting it silently renders with another seed than asked.
    for s in ("-1", "18446744073709551616", "99999999999999999999999"):
        render(f"seed-{s}", small + ["--seed", s], expect=REFUSED, names=["--seed"],
               note=f"--seed {s} (not a 64-bit unsigned value)")
    # Output paths.
    stats_dir = [*base, directory("statsdir")]
    c = render_case(f + "stats-directory", "scene.pbrt", stats_dir, flags=["--threads", "1", "--quiet"] + small,
                    names=["statsdir", "--stats"], expect=REFUSED, note="--stats to a directory")
    c.argv[c.argv.index("--stats") + 1] = "statsdir"
    c.outputs.remove("stats.json")
    c.stats = None
    cases.append(c)
    c = render_case(f + "stats-nonexistent-dir", "scene.pbrt", list(base), flags=["--threads", "1", "--quiet"] + small,
                    names=["/nonexistent/x.json", "--stats"], expect=REFUSED, note="--stats /nonexistent/x.json")
    c.argv[c.argv.index("--stats") + 1] = "/nonexistent/x.json"
    c.outputs.remove("stats.json")
    c.stats = None
    cases.append(c)
    render("output-directory", small, entries=[*base, directory("outdir.png")], out="outdir.png", expect=REFUSED,
           note="-o to a directory")
    render("output-unknown-ext", small, out="out.tiff", expect=REFUSED, note="-o out.tiff")
    render("output-exr", small, out="out.exr", expect=RENDERED, note="-o out.exr")
    render("output-ppm", small, out="out.ppm", expect=RENDERED, note="-o out.ppm")
    render("output-nonexistent-dir", small, out="/nonexistent/out.png", expect=REFUSED, note="-o /nonexistent/out.png")
    render("output-is-scene", small, out="scene.pbrt", expect=REFUSED, note="-o the scene itself (not an image name)")
    render("output-empty", small, out="", expect=REFUSED, note="-o ''")
    # A name of 250 characters is valid; its temporary name beside it must be too.
    render("output-long-name-250", small, out="o" * 246 + ".png", expect=RENDERED, note="-o a 250-character name")
    render("output-long-name-300", small, out="o" * 296 + ".png", expect=REFUSED, note="-o a 300-character name")
    render("output-newline-tiff", small, out="out\n.tiff", expect=REFUSED,
           note="-o a name with a newline and an unknown extension (the refusal must stay one line)")
    c = render_case(f + "stats-long-name-250", "scene.pbrt", list(base), flags=["--threads", "1", "--quiet"] + small,
                    expect=RENDERED, note="--stats a 250-character name")
    c.argv[c.argv.index("--stats") + 1] = c.stats = "s" * 245 + ".json"
    c.outputs = ["out.png", c.stats]
    c.names.append(c.stats)
    cases.append(c)
    render("output-parent-is-file", small, out="scene.pbrt/out.png", expect=REFUSED,
           note="-o under a path whose parent is a file")
    # Unknown or malformed flags.
    for name, args in {"unknown": ["--bogus"], "unknown-value": ["--bogus", "1"], "single-dash": ["-spp", "1"],
                       "spp-missing-value": ["--spp"], "spp-twice": ["--spp", "1", "--spp", "2"],
                       "light-sampling-bogus": ["--light-sampling", "ltc"],
                       "light-select-bogus": ["--light-select", "random"],
                       "integrator-bogus": ["--integrator", "bdpt"],
                       "sampler-bogus": ["--sampler", "halton"],
                       "two-scenes": ["scene.pbrt"],
                       "auto-rest-cost-neg": ["--light-sampling", "auto", "--auto-rest-cost", "-1"],
                       "auto-rest-variance-nan": ["--light-sampling", "auto", "--auto-rest-variance", "nan"],
                       "auto-rest-variance-inf": ["--light-sampling", "auto", "--auto-rest-variance", "inf"],
                       "auto-rest-cost-1e308": ["--light-sampling", "auto", "--auto-rest-cost", "1e308"],
                       "ellipse-map-bogus": ["--ellipse-map", "square"]}.items():
        render(name, small + args, names=[a for a in args if a.startswith("-")] or args,
               expect=REFUSED if name not in ("spp-twice", "auto-rest-cost-1e308", "auto-rest-cost-neg") else None)
    # Every strategy, light selection, integrator and sampler on the base scene.
    # (integrators and samplers rotated over the strategies and selections)
    for i, s in enumerate(LIGHT_SAMPLINGS):
        render(f"light-sampling-{s}", small + ["--light-sampling", s, "--integrator", INTEGRATORS[i % 3],
                                               "--sampler", SAMPLERS[i // 2 % 3]], expect=RENDERED)
    for i, s in enumerate(LIGHT_SELECTS):
        render(f"light-select-{s}", small + ["--light-select", s, "--integrator", INTEGRATORS[(i + 1) % 3],
                                             "--sampler", SAMPLERS[i % 3]], expect=RENDERED)
    # Other subcommands and none.
    for name, argv in {"no-command": [], "unknown-command": ["paint", "scene.pbrt"],
                       "render-no-scene": ["render"]}.items():
        cases.append(Case(f + name, list(base), argv, kind="other", names=["mcrt", *argv],
                          expect=REFUSED, note="mcrt " + " ".join(argv)))
    # mcrt samples.
    smp = ["--light", "0", "--from", "0,0,0", "--normal", "0,1,0", "--n", "16"]

    def samples(name, args, *, expect=REFUSED, names=(), scene="scene.pbrt", entries=None):
        cases.append(samples_case(f + "samples-" + name, scene, list(entries if entries is not None else base), args,
                                  names=list(names), expect=expect, note="samples " + " ".join(args)))

    samples("valid", smp, expect=RENDERED)
    samples("valid-json", smp, expect=RENDERED, scene="scene.json", entries=[file("scene.json", A.BASE_JSON)])
    for s in ("solid-angle", "projected-solid-angle", "auto"):
        samples(f"strategy-{s}", smp + ["--light-sampling", s], expect=RENDERED)
    for k in ("2", "-1", "2147483648", "1000"):
        samples(f"light-{k}", ["--light", k] + smp[2:], names=["--light"])
    samples("from-1e39", ["--light", "0", "--from", "1e39,0,0", "--normal", "0,1,0", "--n", "16"], names=["--from"])
    samples("from-nan", ["--light", "0", "--from", "nan,0,0", "--normal", "0,1,0", "--n", "16"], names=["--from"])
    samples("from-two", ["--light", "0", "--from", "0,0", "--normal", "0,1,0", "--n", "16"], names=["--from"])
    samples("from-on-light", ["--light", "0", "--from", "0,2,0", "--normal", "0,-1,0", "--n", "16"], expect=None)
    samples("normal-zero", ["--light", "0", "--from", "0,0,0", "--normal", "0,0,0", "--n", "16"], names=["--normal"])
    samples("normal-1e39", ["--light", "0", "--from", "0,0,0", "--normal", "0,1e39,0", "--n", "16"],
            names=["--normal"])
    for n in ("0", "-1", "1000000000000"):
        samples(f"n-{n}", smp[:6] + ["--n", n], names=["--n"])
    samples("no-lights", smp, names=["--light", "light"],
            entries=[file("scene.pbrt", A.pbrt_scene(light=""))])
    # Stiff receivers for each light shape: on the light's plane, just below
    # it, far away, inside a sphere light.  Any ok class, but every CSV value
    # must be finite.  (Strategies rotated.)
    obj = A.json_scene_obj()
    obj["objects"][1:] = [
        {"type": "xz_rect", "x0": -1, "x1": 1, "z0": -1, "z1": 1, "k": 2, "material": "light", "flip": True},
        {"type": "ellipse", "center": [-3, 2, 0], "axis1": [1, 0, 0], "axis2": [0, 0, 0.5], "material": "light",
         "flip": True},
        {"type": "sphere", "center": [3, 1, 0], "radius": 0.5, "material": "light"}]
    lights_json = [file("scene.json", A.json_text(obj))]
    receivers = {
        0: {"in-plane": ("0,2,0", "0,1,0"), "just-below": ("0.3,1.9999999,0.2", "0,1,0"),
            "far": ("0,-1e30,0", "0,1,0"), "grazing": ("5,0,0", "-1,0,0")},
        1: {"in-plane": ("-3,2,0", "0,-1,0"), "edge": ("-2,2,0", "0,1,0"), "far": ("1e30,2,0", "-1,0,0")},
        2: {"center": ("3,1,0", "0,1,0"), "surface": ("3,1.5,0", "0,1,0"), "near": ("3,1.5000001,0", "0,-1,0"),
            "far": ("3,1e30,0", "0,-1,0")},
    }
    k = 0
    for light, points in receivers.items():
        for name, (pt, nrm) in points.items():
            strat = LIGHT_SAMPLINGS[k % 6]
            k += 1
            samples(f"stiff-{['rect', 'ellipse', 'sphere'][light]}-{name}-{strat}",
                    ["--light", str(light), "--from", pt, "--normal", nrm, "--n", "64", "--light-sampling", strat],
                    expect=None, scene="scene.json", entries=lights_json)
    # mcrt diff.
    good = A.png(8, 8)

    def diff(name, a, b, entries, *, expect=REFUSED, slow=False, allow_nonfinite=False):
        cases.append(diff_case(f + "diff-" + name, a, b, entries, expect=expect, slow=slow,
                               allow_nonfinite=allow_nonfinite, note=f"diff {a} {b}"))

    diff("valid", "a.png", "b.png", [file("a.png", good), file("b.png", A.png(8, 8, pixel=b"\x10\x20\x30"))],
         expect=RENDERED)
    diff("valid-exr", "a.exr", "b.exr", [file("a.exr", A.exr(4, 4, [0.5])), file("b.exr", A.exr(4, 4, [0.25]))],
         expect=RENDERED)
    diff("truncated-png", "a.png", "b.png", [file("a.png", lambda: A.checker_png()[:80]), file("b.png", good)])
    diff("other-size", "a.png", "b.png", [file("a.png", good), file("b.png", A.png(4, 8))])
    diff("directory", "a.png", "b.png", [directory("a.png"), file("b.png", good)])
    diff("dev-zero", "a.png", "b.png", [symlink("a.png", "/dev/zero"), file("b.png", good)], slow=True)
    diff("dev-zero-exr", "a.exr", "b.png", [symlink("a.exr", "/dev/zero"), file("b.png", good)], slow=True)
    diff("fifo", "a.png", "b.png", [fifo("a.png"), file("b.png", good)], slow=True)
    diff("missing", "a.png", "b.png", [file("b.png", good)])
    diff("text-named-exr", "a.exr", "b.png", [file("a.exr", "not an image\n"), file("b.png", good)])
    diff("ihdr-lies", "a.png", "b.png", [file("a.png", lambda: A.png_lying_size(100000, 100000)),
                                         file("b.png", good)], slow=True)
    diff("nan-exr", "a.exr", "b.exr", [file("a.exr", A.exr(4, 4, [float("nan")])),
                                       file("b.exr", A.exr(4, 4, [0.5]))], expect=None, allow_nonfinite=True)
    cases.append(Case(f + "diff-json", [file("a.png", good), file("b.png", good)], ["diff", "a.png", "b.png", "--json"],
                      kind="diff", names=["a.png"], expect=RENDERED, note="diff --json"))
    cases.append(Case(f + "diff-one-arg", [file("a.png", good)], ["diff", "a.png"], kind="diff",
                      names=["reference", "a.png"], expect=REFUSED, note="diff with one image"))
    return cases


# --------------------------------------------------------------------------
# 10. JSON scenes

def json_scenes() -> list[Case]:
    f = "json/"
    cases = []

    def js(name, text, *, expect=None, note="", extra=None, slow=False, flags=None):
        cases.append(render_case(f + name, "scene.json", [file("scene.json", text)], extra=extra, expect=expect,
                                 note=note, slow=slow, flags=flags))

    def edit(name, fn, *, expect=None, note="", extra=None, raw=None, flags=None):
        """A case made by editing the base scene's object with fn(obj)."""
        obj = A.json_scene_obj()
        fn(obj)
        text = A.json_text(obj)
        for key, value in (raw or {}).items():  # numbers JSON writers cannot write
            text = text.replace(f'"{key}"', value)
        js(name, text, expect=expect, note=note or name, extra=extra, flags=flags)

    js("valid", A.BASE_JSON, expect=RENDERED, note="the base JSON scene")
    js("empty", "", note="empty file")
    js("whitespace", " \n\t ", note="whitespace only")
    js("bom", "\ufeff" + A.BASE_JSON, note="a UTF-8 BOM")
    js("not-object-array", "[]", note="an array")
    js("not-object-number", "42", note="a number")
    js("nested-arrays", "[" * 100000 + "]" * 100000, note="10^5 nested arrays")
    js("nested-unclosed", "[" * 100000, note="10^5 [ unclosed")
    js("truncated", A.BASE_JSON[: len(A.BASE_JSON) // 2], note="cut in half")
    js("trailing-garbage", A.BASE_JSON + "garbage", note="garbage after the object")
    js("nul-in-file", A.BASE_JSON.replace('"camera"', '"cam\0era"'), note="a raw NUL in a key")
    js("control-char", A.BASE_JSON.replace("{", "{\x01", 1), note="a raw control character between tokens")
    js("escape-sequence-in-type", A.BASE_JSON.replace('"lambertian"', '"\\u001b[2Jvelvet"'),
       note="an unknown material type holding a terminal escape sequence (\\u001b)")
    js("nul-escaped", A.BASE_JSON.replace('"white"', '"wh\\u0000ite"'), note="\\u0000 in a material name")
    js("crlf", A.BASE_JSON.replace("\n", "\r\n"), expect=RENDERED, note="CRLF line endings")
    js("nan-token", A.BASE_JSON.replace('"vfov": 45', '"vfov": NaN'), note="NaN as a number")
    js("huge-string", lambda: A.BASE_JSON.replace('"white"', '"' + "w" * (16 << 20) + '"'),
       note="a 16 MB material name (the refusal line must stay short)")
    js("huge-number-digits", A.BASE_JSON.replace('"vfov": 45', '"vfov": ' + "4" * 100000),
       note="a 100000-digit number")
    js("duplicate-keys", A.BASE_JSON.replace('"vfov": 45', '"vfov": 45, "vfov": 0'), note="duplicate keys")
    for key, raw in {"1e999": "1e999", "-1e999": "-1e999", "1e39": "1e39", "-0": "-0", "1e-400": "1e-400",
                     "big-int": "1" + "0" * 400}.items():
        edit(f"vfov-{key}", lambda o: o["camera"].__setitem__("vfov", "RAW"), raw={"RAW": raw},
             expect=REFUSED if key in ("1e999", "-1e999", "big-int", "1e39") else None,
             note=f"vfov {raw}")
        edit(f"radius-{key}", lambda o: o["objects"][2].__setitem__("radius", "RAW"), raw={"RAW": raw},
             expect=REFUSED if key in ("1e999", "-1e999", "-0", "1e-400") else None,
             note=f"sphere radius {raw}")
        if key in ("1e999", "1e39"):
            edit(f"k-{key}", lambda o: o["objects"][0].__setitem__("k", "RAW"), raw={"RAW": raw},
                 expect=REFUSED if key == "1e999" else None, note=f"floor k {raw}")
            edit(f"emit-{key}", lambda o: o["materials"]["light"].__setitem__("emit", ["RAW", 1, 1]),
                 raw={"RAW": raw}, expect=REFUSED if key == "1e999" else None, note=f"emit {raw}")
    for part in ("camera", "render", "materials", "objects"):
        edit(f"missing-{part}", lambda o, p=part: o.pop(p), note=f"no {part}")
    for key in ("lookfrom", "vfov", "width"):
        edit(f"missing-camera-{key}", lambda o, k=key: o["camera"].pop(k), note=f"no camera.{key}")
    edit("missing-object-type", lambda o: o["objects"][0].pop("type"), expect=REFUSED)
    edit("missing-object-material", lambda o: o["objects"][0].pop("material"), expect=REFUSED)
    edit("unknown-top-field", lambda o: o.__setitem__("foo", 1), note="an unknown top-level field")
    edit("unknown-object-type", lambda o: o["objects"][0].__setitem__("type", "torus"), expect=REFUSED)
    edit("unknown-material-type", lambda o: o["materials"]["white"].__setitem__("type", "velvet"), expect=REFUSED)
    edit("undefined-material", lambda o: o["objects"][0].__setitem__("material", "nope"), expect=REFUSED)
    edit("radius-neg", lambda o: o["objects"][2].__setitem__("radius", -1), expect=REFUSED)
    edit("radius-zero", lambda o: o["objects"][2].__setitem__("radius", 0), expect=REFUSED)
    # Without --spp, so that the scene's own value is used.
    no_spp = ["--width", "8", "--height", "8", "--threads", "1", "--quiet"]
    edit("spp-1e10", lambda o: o["render"].__setitem__("spp", 10 ** 10), expect=REFUSED, flags=no_spp,
         note="render.spp 10^10 (no --spp)")
    edit("spp-0", lambda o: o["render"].__setitem__("spp", 0), expect=REFUSED, flags=no_spp,
         note="render.spp 0 (no --spp)")
    edit("max-depth-1e9", lambda o: o["render"].__setitem__("max_depth", 10 ** 9))
    edit("width-0", lambda o: o["camera"].__setitem__("width", 0))
    edit("width-huge", lambda o: o["camera"].__setitem__("width", 10 ** 12))
    for v in (0, 180, -1, 1e-30):
        edit(f"vfov-{v}", lambda o, v=v: o["camera"].__setitem__("vfov", v), note=f"vfov {v}")
    edit("lookfrom-is-lookat", lambda o: o["camera"].__setitem__("lookat", [0, 1, -4]))
    edit("vup-parallel", lambda o: o["camera"].__setitem__("vup", [0, -0.5, 4]))
    edit("vup-zero", lambda o: o["camera"].__setitem__("vup", [0, 0, 0]))
    edit("camera-array", lambda o: o.__setitem__("camera", [1, 2, 3]), expect=REFUSED)
    edit("albedo-string", lambda o: o["materials"]["white"].__setitem__("albedo", "white"), expect=REFUSED)
    edit("albedo-two", lambda o: o["materials"]["white"].__setitem__("albedo", [0.5, 0.5]), expect=REFUSED)
    edit("emit-1e38", lambda o: o["materials"]["light"].__setitem__("emit", [1e38, 1e38, 1e38]))
    edit("fuzz-2", lambda o: o["materials"].__setitem__("white", {"type": "metal", "albedo": [1, 1, 1], "fuzz": 2}))
    edit("ior-0", lambda o: o["materials"].__setitem__("white", {"type": "dielectric", "ior": 0}), expect=REFUSED)
    edit("ior-neg", lambda o: o["materials"].__setitem__("white", {"type": "dielectric", "ior": -1}), expect=REFUSED)
    edit("zero-area-light", lambda o: o["objects"][1].__setitem__("x1", -1), expect=REFUSED,
         note="a zero-area light (refused by the contract)")
    edit("inverted-rect-light", lambda o: o["objects"][1].update({"x0": 1, "x1": -1}), note="x0 > x1 on the light")
    edit("rect-nonorthogonal", lambda o: o["objects"].append(
        {"type": "rect", "corner": [0, 1, 0], "edge1": [1, 0, 0], "edge2": [1, 0, 1], "material": "light"}),
         expect=REFUSED, note="a rect with non-orthogonal edges")
    edit("ellipse-zero-axis", lambda o: o["objects"].append(
        {"type": "ellipse", "center": [0, 1.5, 0], "axis1": [0, 0, 0], "axis2": [0, 0, 1], "material": "light"}),
         expect=REFUSED, note="an ellipse light with a zero axis")
    edit("ellipse-sa-tiny", lambda o: o["objects"].append(
        {"type": "ellipse_sa", "center": [0, 1.5, 0], "axis1": [1e-20, 0, 0], "axis2": [0, 0, 1e-20],
         "material": "light"}), note="a 1e-20 ellipse light sampled by solid angle")
    edit("sphere-light-tiny", lambda o: o["objects"].append(
        {"type": "sphere", "center": [0, 1.5, 0], "radius": 1e-30, "material": "light"}),
         note="a sphere light of radius 1e-30")
    edit("sampling-bogus", lambda o: o["objects"][1].__setitem__("sampling", "bogus"), expect=REFUSED)
    edit("sample-on-light", lambda o: o["objects"][1].__setitem__("sample", True))
    edit("background-short", lambda o: o["render"].__setitem__("background", [0]), expect=REFUSED)
    # Every light black: MUST render whatever the light selection or strategy.
    # (selections, strategies and integrators rotated)
    for i, strat in enumerate(LIGHT_SAMPLINGS):
        sel, integ = LIGHT_SELECTS[i % 4], INTEGRATORS[i % 3]
        edit(f"emit-0-{strat}", lambda o: o["materials"]["light"].__setitem__("emit", [0, 0, 0]), expect=RENDERED,
             extra=["--light-select", sel, "--light-sampling", strat, "--integrator", integ],
             note=f"every light black, --light-select {sel} --light-sampling {strat} --integrator {integ}")
    edit("no-lights", lambda o: o["objects"].pop(1), note="no light at all")
    # Stiff but valid lights under two strategies each (rotated): MUST render.
    stiff = {
        "tiny-rect-sa": {"type": "xz_rect_sa", "x0": -1e-6, "x1": 1e-6, "z0": -1e-6, "z1": 1e-6, "k": 2,
                         "material": "light", "flip": True},
        "sliver-rect": {"type": "xz_rect", "x0": -1, "x1": 1, "z0": 0, "z1": 1e-7, "k": 2, "material": "light",
                        "flip": True},
        "grazing-rect": {"type": "xy_rect", "x0": -1, "x1": 1, "y0": 0, "y1": 1, "k": 0, "material": "light",
                         "flip": True},
        "sphere-on-floor": {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "light"},
        "thin-ellipse-sa": {"type": "ellipse_sa", "center": [0, 1.5, 0], "axis1": [1, 0, 0], "axis2": [0, 0, 1e-7],
                            "material": "light", "flip": True},
    }
    for i, (name, light) in enumerate(stiff.items()):
        for strat in (LIGHT_SAMPLINGS[(2 * i) % 6], LIGHT_SAMPLINGS[(2 * i + 1) % 6]):
            edit(f"stiff-{name}-{strat}", lambda o, l=light: o["objects"].__setitem__(1, dict(l)), expect=RENDERED,
                 extra=["--light-sampling", strat, "--max-depth", "2"],
                 note=f"a stiff light ({name}) sampled by {strat}")
    for name in sorted(p.name for p in A.SCENES.glob("*.json")):
        js(f"shipped-{name[:-5]}", (A.SCENES / name).read_text(), expect=RENDERED, note=f"scenes/{name}")
    return cases


FAMILIES = {
    "syntax": syntax, "include": include, "files": files, "camera": camera, "geometry": geometry,
    "lights": lights, "ply": ply, "texture": texture, "flags": flags, "json": json_scenes,
}


def all_cases() -> list[Case]:
    out = []
    for fam in FAMILIES.values():
        out.extend(fam())
    ids = [c.id for c in out]
    dup = {i for i in ids if ids.count(i) > 1}
    assert not dup, f"duplicate case ids: {sorted(dup)}"
    return out
