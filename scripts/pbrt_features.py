#!/usr/bin/env python3
"""Summarise which pbrt-v4 scene-description features a set of scenes uses.

Usage:
    python3 scripts/pbrt_features.py ROOT [ROOT ...] > features.json

Each ROOT is a .pbrt file or a directory; a directory is searched for scene
files (by default files named ``scene-v4.pbrt`` or ``*.pbrt`` directly inside a
``pbrt/`` folder; ``--glob`` chooses another pattern). For every scene the
script reads the file, follows ``Include`` and ``Import`` (names resolved
against the directory of the top-level scene file, as pbrt-v4 does; ``.gz``
files are decompressed, ``.xz`` files are read too and flagged, since pbrt-v4
cannot read them) and prints one JSON object: camera, sampler, integrator,
filter, film, shapes, materials, textures, lights, media, instancing, every
directive with its count, the files the scene refers to and which of them are
missing, and whether the scene stays inside a small core subset
(``core_subset``; see CORE below). ``features_incomplete`` is set where an
included file is missing or a file did not parse, so that the summary cannot
be complete; ``files_complete`` tells whether every referenced file exists.

Python 3 standard library only. The tokenizer knows pbrt's comments (``#`` to
the end of the line), double-quoted strings (with backslash escapes), ``[``
and ``]``, and bare words/numbers; it does not evaluate transforms.
"""

import argparse
import fnmatch
import gzip
import json
import lzma
import os
import re
import sys

PARAM_TYPES = {
    "integer", "float", "point2", "vector2", "point3", "vector3", "normal",
    "normal3", "point", "vector", "color", "rgb", "spectrum", "blackbody",
    "bool", "string", "texture",
}

# Directives whose leading quoted strings are positional arguments, and how
# many of them there are.
POSITIONAL = {
    "Camera": 1, "Sampler": 1, "Integrator": 1, "PixelFilter": 1, "Film": 1,
    "Shape": 1, "Material": 1, "LightSource": 1, "AreaLightSource": 1,
    "Accelerator": 1, "ColorSpace": 1, "MakeNamedMaterial": 1,
    "NamedMaterial": 1, "Texture": 3, "MakeNamedMedium": 1,
    "MediumInterface": 2, "ObjectBegin": 1, "ObjectInstance": 1,
    "CoordinateSystem": 1, "CoordSysTransform": 1, "Include": 1, "Import": 1,
    "Attribute": 1, "ActiveTransform": 0, "Option": 0,
}

# The subset a renderer with a basic pbrt-v4 reader handles.
CORE = {
    "shapes": {"trianglemesh", "plymesh", "sphere", "disk", "bilinearmesh"},
    "materials": {"diffuse", "conductor", "dielectric"},
    "textures": {"imagemap", "constant", "scale", "checkerboard"},
    "area_lights": {"diffuse"},
    "cameras": {"perspective"},
}

MAX_VALUES = 8  # distinct values kept per parameter
MAX_NAMES = 20  # referenced file names listed per kind (all are counted)


class ParseError(Exception):
    pass


def read_text(path):
    """Return (text, note) for a scene file, decompressing .gz and .xz."""
    if path.endswith(".gz"):
        with gzip.open(path, "rt", encoding="utf-8", errors="replace") as f:
            return f.read(), None
    if path.endswith(".xz"):
        with lzma.open(path, "rt", encoding="utf-8", errors="replace") as f:
            return f.read(), "xz-compressed (pbrt-v4 reads only .gz)"
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        return f.read(), None


def tokenize(text):
    """Yield (kind, value, line). kind: 'str', '[', ']', 'word'."""
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif c in " \t\r\f\v":
            i += 1
        elif c == "#":
            while i < n and text[i] != "\n":
                i += 1
        elif c == '"':
            j, out, start_line = i + 1, [], line
            while j < n and text[j] != '"':
                if text[j] == "\\" and j + 1 < n:
                    j += 1
                    out.append({"n": "\n", "t": "\t", "b": "\b", "f": "\f",
                                "r": "\r"}.get(text[j], text[j]))
                else:
                    if text[j] == "\n":
                        line += 1
                    out.append(text[j])
                j += 1
            if j >= n:
                raise ParseError("line %d: unterminated string" % start_line)
            yield ("str", "".join(out), start_line)
            i = j + 1
        elif c in "[]":
            yield (c, c, line)
            i += 1
        else:
            j = i
            while j < n and text[j] not in ' \t\r\n\f\v"[]#':
                j += 1
            yield ("word", text[i:j], line)
            i = j


def is_number(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def group_statements(tokens):
    """Group tokens into (directive, args, line); args keep brackets as lists."""
    stmt = None
    stack = []
    for kind, val, line in tokens:
        if kind == "word" and not stack and not is_number(val) \
                and val not in ("true", "false"):
            if stmt is not None:
                yield stmt
            stmt = (val, [], line)
            continue
        if stmt is None:
            raise ParseError("line %d: value %r before any directive" % (line, val))
        if kind == "[":
            stack.append([])
        elif kind == "]":
            if not stack:
                raise ParseError("line %d: unbalanced ']'" % line)
            done = stack.pop()
            (stack[-1] if stack else stmt[1]).append(done)
        else:
            item = val if kind == "str" else _word_value(val)
            (stack[-1] if stack else stmt[1]).append(item)
    if stack:
        raise ParseError("unbalanced '['")
    if stmt is not None:
        yield stmt


def _word_value(w):
    if w == "true":
        return True
    if w == "false":
        return False
    try:
        return int(w)
    except ValueError:
        return float(w)


def split_args(directive, args):
    """Return (positional, params) where params is a list of (type, name, values)."""
    npos = POSITIONAL.get(directive)
    positional, params = [], []
    i = 0
    if npos is None:  # transforms and the like: all positional
        return args, params
    while i < len(args) and len(positional) < npos and isinstance(args[i], str) \
            and not _is_decl(args[i], args, i):
        positional.append(args[i])
        i += 1
    while i < len(args):
        decl = args[i]
        if not isinstance(decl, str):
            raise ParseError("%s: expected a parameter declaration, got %r" % (directive, decl))
        parts = decl.split()
        if len(parts) != 2:
            raise ParseError("%s: bad parameter declaration %r" % (directive, decl))
        if i + 1 >= len(args):
            raise ParseError("%s: parameter %r has no value" % (directive, decl))
        val = args[i + 1]
        params.append((parts[0], parts[1], val if isinstance(val, list) else [val]))
        i += 2
    return positional, params


def _is_decl(s, args, i):
    parts = s.split()
    return len(parts) == 2 and parts[0] in PARAM_TYPES and i + 1 < len(args)


class Scene:
    def __init__(self, path, absent=()):
        self.path = os.path.abspath(path)
        self.absent = absent
        self.base = os.path.dirname(self.path)
        self.files_parsed = []
        self.notes = []
        self.errors = []
        self.directives = {}
        self.camera = []
        self.sampler = []
        self.integrator = []
        self.filter = []
        self.film = []
        self.accelerator = []
        self.colorspace = []
        self.options = []
        self.shapes = {}
        self.materials = {}
        self.textures = {}
        self.lights = {}
        self.area_lights = {}
        self.emissive_shapes = {}
        self.media = {}
        self.medium_interfaces = 0
        self.media_used = set()
        self.objects_defined = 0
        self.object_instances = 0
        self.referenced = {}  # kind -> set of relative names
        self.attr_stack = []
        self.area = None
        self.in_object = False

    # -- helpers --------------------------------------------------------
    def resolve(self, name):
        return name if os.path.isabs(name) else os.path.join(self.base, name)

    def ref(self, kind, name):
        self.referenced.setdefault(kind, set()).add(name)

    @staticmethod
    def describe(positional, params):
        d = {"type": positional[0] if positional else None}
        for t, n, v in params:
            d[n] = v[0] if len(v) == 1 else v
        return d

    @staticmethod
    def add_params(entry, params):
        for t, n, v in params:
            p = entry["params"].setdefault(n, {"types": [], "values": []})
            if t not in p["types"]:
                p["types"].append(t)
            if t in ("texture", "string", "spectrum", "bool", "float", "integer",
                     "blackbody") and len(v) == 1:
                val = v[0]
                if val not in p["values"] and len(p["values"]) < MAX_VALUES:
                    p["values"].append(val)

    def kind_entry(self, table, key):
        return table.setdefault(key, {"count": 0, "params": {}})

    # -- parsing --------------------------------------------------------
    def parse_file(self, path, depth=0):
        if depth > 32:
            self.errors.append("include depth exceeded at %s" % path)
            return
        rel = os.path.relpath(path, self.base)
        if not os.path.exists(path):
            return  # listed under missing_files["include"]
        try:
            text, note = read_text(path)
        except (OSError, EOFError, lzma.LZMAError) as e:
            self.errors.append("unreadable %s: %s" % (rel, e))
            return
        if note:
            self.notes.append("%s: %s" % (rel, note))
        self.files_parsed.append(rel)
        try:
            for directive, args, line in group_statements(tokenize(text)):
                self.statement(directive, args, "%s:%d" % (rel, line), depth)
        except ParseError as e:
            self.errors.append("%s: %s" % (rel, e))

    def statement(self, d, args, where, depth):
        self.directives[d] = self.directives.get(d, 0) + 1
        try:
            pos, params = split_args(d, args)
        except ParseError as e:
            self.errors.append("%s: %s" % (where, e))
            return
        if d in ("Include", "Import"):
            name = pos[0] if pos else None
            if not name:
                self.errors.append("%s: %s without a file name" % (where, d))
                return
            self.ref("include", name)
            self.parse_file(self.resolve(name), depth + 1)
        elif d == "Camera":
            self.camera.append(self.describe(pos, params))
        elif d == "Sampler":
            self.sampler.append(self.describe(pos, params))
        elif d == "Integrator":
            self.integrator.append(self.describe(pos, params))
        elif d == "PixelFilter":
            self.filter.append(self.describe(pos, params))
        elif d == "Film":
            self.film.append(self.describe(pos, params))
        elif d == "Accelerator":
            self.accelerator.append(self.describe(pos, params))
        elif d == "ColorSpace":
            self.colorspace.append(pos[0] if pos else None)
        elif d == "Option":
            self.options.append(self.describe([], params))
        elif d in ("AttributeBegin", "TransformBegin"):
            self.attr_stack.append(self.area)
        elif d in ("AttributeEnd", "TransformEnd"):
            if self.attr_stack:
                area = self.attr_stack.pop()
                if d == "AttributeEnd":
                    self.area = area
            else:
                self.errors.append("%s: unbalanced %s" % (where, d))
        elif d == "AreaLightSource":
            kind = pos[0] if pos else None
            e = self.kind_entry(self.area_lights, kind)
            e["count"] += 1
            self.add_params(e, params)
            self.area = kind
        elif d == "LightSource":
            kind = pos[0] if pos else None
            e = self.kind_entry(self.lights, kind)
            e["count"] += 1
            self.add_params(e, params)
            for t, n, v in params:
                if n == "filename":
                    self.ref("light_image", v[0])
        elif d == "Shape":
            kind = pos[0] if pos else None
            e = self.kind_entry(self.shapes, kind)
            e["count"] += 1
            for t, n, v in params:
                if n not in e["params"]:
                    e["params"][n] = {"types": [t], "values": []}
                elif t not in e["params"][n]["types"]:
                    e["params"][n]["types"].append(t)
                if n == "filename":
                    self.ref("mesh", v[0])
                if n == "alpha" and t == "texture":
                    vals = e["params"][n]["values"]
                    if v[0] not in vals and len(vals) < MAX_VALUES:
                        vals.append(v[0])
            if self.area:
                key = "%s:%s" % (self.area, kind)
                self.emissive_shapes[key] = self.emissive_shapes.get(key, 0) + 1
            if self.in_object:
                e["in_object"] = e.get("in_object", 0) + 1
        elif d in ("Material", "MakeNamedMaterial"):
            if d == "Material":
                kind = pos[0] if pos else None
                rest = params
            else:
                kind = None
                rest = []
                for t, n, v in params:
                    if n == "type":
                        kind = v[0]
                    else:
                        rest.append((t, n, v))
            e = self.kind_entry(self.materials, kind)
            e["count"] += 1
            self.add_params(e, rest)
            for t, n, v in rest:
                if t == "string" and n in ("normalmap", "bumpmap"):
                    self.ref("texture_image", v[0])
        elif d == "Texture":
            if len(pos) < 3:
                self.errors.append("%s: Texture needs name, type and class" % where)
                return
            _, ttype, tclass = pos[:3]
            e = self.kind_entry(self.textures, tclass)
            e["count"] += 1
            e.setdefault("value_types", [])
            if ttype not in e["value_types"]:
                e["value_types"].append(ttype)
            self.add_params(e, params)
            for t, n, v in params:
                if n == "filename":
                    self.ref("texture_image", v[0])
        elif d == "MakeNamedMedium":
            kind = None
            for t, n, v in params:
                if n == "type":
                    kind = v[0]
            e = self.kind_entry(self.media, kind)
            e["count"] += 1
            self.add_params(e, [p for p in params if p[1] != "type"])
            for t, n, v in params:
                if n == "filename":
                    self.ref("medium_data", v[0])
        elif d == "MediumInterface":
            self.medium_interfaces += 1
            for m in pos:
                if m:
                    self.media_used.add(m)
        elif d == "ObjectBegin":
            self.objects_defined += 1
            self.in_object = True
            self.attr_stack.append(self.area)
        elif d == "ObjectEnd":
            self.in_object = False
            if self.attr_stack:
                self.area = self.attr_stack.pop()
        elif d == "ObjectInstance":
            self.object_instances += 1

    @staticmethod
    def compact(table):
        """Drop empty value lists, so that the JSON stays readable."""
        for e in table.values():
            for p in e["params"].values():
                if not p["values"]:
                    del p["values"]
        return table

    def why_missing(self, name, root):
        """Classify a referenced file that is not on disk."""
        full = os.path.normpath(self.resolve(name))
        rel = os.path.relpath(full, os.path.abspath(root))
        if rel in self.absent:
            return "in the source, absent from this copy"
        for ext in (".xz", ".gz"):
            if os.path.exists(full + ext) or rel + ext in self.absent:
                return "only %s-compressed in the source (%s%s)" % (ext[1:], name, ext)
        if os.path.basename(name).startswith("."):
            return "no such file in the source (file name looks truncated)"
        return "no such file in the source"

    # -- result ---------------------------------------------------------
    def summary(self, root):
        refs = {}
        missing = {}
        missing_why = {}
        for kind, names in sorted(self.referenced.items()):
            refs[kind] = {"count": len(names)}
            if len(names) <= MAX_NAMES:
                refs[kind]["names"] = sorted(names)
            miss = sorted(n for n in names if not os.path.exists(self.resolve(n)))
            if miss:
                missing[kind] = miss
            for n in miss:
                missing_why[n] = self.why_missing(n, root)
        exts = {}
        for kind in ("mesh", "texture_image", "light_image"):
            for n in self.referenced.get(kind, ()):
                m = re.search(r"(\.[A-Za-z0-9]+(\.(gz|xz))?)$", n)
                ext = m.group(1).lower() if m else "(none)"
                exts.setdefault(kind, {})
                exts[kind][ext] = exts[kind].get(ext, 0) + 1
        cam_lens = [c for c in self.camera
                    if isinstance(c.get("lensradius"), (int, float)) and c["lensradius"] > 0]
        core_reasons = []
        for c in self.camera:
            if c.get("type") not in CORE["cameras"]:
                core_reasons.append("camera %s" % c.get("type"))
        for k in self.shapes:
            if k not in CORE["shapes"]:
                core_reasons.append("shape %s" % k)
        for k in self.materials:
            if k not in CORE["materials"]:
                core_reasons.append("material %s" % k)
        for k in self.textures:
            if k not in CORE["textures"]:
                core_reasons.append("texture %s" % k)
        for k in self.area_lights:
            if k not in CORE["area_lights"]:
                core_reasons.append("area light %s" % k)
        for k in self.lights:
            core_reasons.append("LightSource %s" % k)
        if self.media or self.medium_interfaces:
            core_reasons.append("participating media")
        if self.objects_defined or self.object_instances:
            core_reasons.append("object instancing")
        for s in self.shapes.values():
            if "alpha" in s["params"]:
                core_reasons.append("alpha-cut shapes")
                break
        for m in self.materials.values():
            for pname in ("displacement", "normalmap"):
                if pname in m["params"]:
                    core_reasons.append("material %s" % pname)
        sdir = os.path.dirname(self.path)
        size, nfiles = dir_size(sdir)
        scene_dir = os.path.relpath(sdir, root)
        if os.path.basename(sdir) == "pbrt":
            whole = os.path.dirname(sdir)
        else:
            whole = sdir
        whole_size, whole_files = dir_size(whole)
        return {
            "scene": scene_name(self.path, root),
            "file": os.path.relpath(self.path, root),
            "scene_dir": scene_dir,
            "scene_dir_bytes": size,
            "scene_dir_files": nfiles,
            "scene_root": os.path.relpath(whole, root),
            "scene_root_bytes": whole_size,
            "scene_root_files": whole_files,
            "files_parsed": self.files_parsed,
            "camera": self.camera,
            "camera_lensradius_set": bool(cam_lens),
            "sampler": self.sampler,
            "integrator": self.integrator,
            "pixel_filter": self.filter,
            "film": self.film,
            "accelerator": self.accelerator,
            "color_space": self.colorspace,
            "options": self.options,
            "shapes": self.compact(self.shapes),
            "materials": self.compact(self.materials),
            "textures": self.compact(self.textures),
            "light_sources": self.compact(self.lights),
            "area_lights": self.compact(self.area_lights),
            "emissive_shapes": self.emissive_shapes,
            "media": self.compact(self.media),
            "medium_interfaces": self.medium_interfaces,
            "media_referenced": sorted(self.media_used),
            "objects_defined": self.objects_defined,
            "object_instances": self.object_instances,
            "directives": dict(sorted(self.directives.items())),
            "referenced_files": refs,
            "referenced_extensions": exts,
            "missing_files": missing,
            "missing_reason": missing_why,
            "core_subset": not core_reasons,
            "features_incomplete": bool(missing.get("include")) or bool(self.errors),
            "files_complete": not missing,
            "outside_core_subset": sorted(set(core_reasons)),
            "notes": self.notes,
            "errors": self.errors,
        }


def dir_size(d):
    total, count = 0, 0
    for dp, dn, fn in os.walk(d):
        for f in fn:
            p = os.path.join(dp, f)
            if os.path.isfile(p) and not os.path.islink(p):
                total += os.path.getsize(p)
                count += 1
    return total, count


def scene_name(path, root):
    rel = os.path.relpath(path, root)
    parts = rel.split(os.sep)
    if len(parts) >= 3 and parts[-2] == "pbrt":
        return parts[-3]
    if len(parts) >= 2:
        return "/".join(parts[:-1])
    return os.path.splitext(parts[0])[0]


def find_scenes(root, pattern):
    found = []
    for dp, dn, fn in os.walk(root):
        dn.sort()
        for f in sorted(fn):
            rel = os.path.relpath(os.path.join(dp, f), root)
            if fnmatch.fnmatch(rel, pattern):
                found.append(os.path.join(dp, f))
    return found


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("roots", nargs="+", help="scene files or directories")
    ap.add_argument("--glob", default="*/pbrt/scene-v4.pbrt",
                    help="pattern (relative to a directory root) of the scene "
                         "files to read; default: %(default)s")
    ap.add_argument("--absent-list", metavar="FILE",
                    help="file listing paths (relative to the directory root, "
                         "one a line) known to exist in the source but absent "
                         "from the local copy; used to explain missing files")
    ap.add_argument("--source", help="free text recorded as the output's "
                    "\"source\" (e.g. repository and commit)")
    ap.add_argument("--indent", type=int, default=1)
    a = ap.parse_args(argv)
    out = {}
    if a.source:
        out["source"] = a.source
    out["core_subset_definition"] = {k: sorted(v) for k, v in CORE.items()}
    absent = set()
    if a.absent_list:
        with open(a.absent_list, encoding="utf-8") as f:
            absent = {l.rstrip("\n") for l in f if l.strip()}
    out["core_subset_definition"]["also_required"] = [
        "no LightSource (infinite, distant, point, ...)", "no media",
        "no object instancing", "no alpha textures",
        "no displacement or normalmap on materials"]
    out["scenes"] = []
    for root in a.roots:
        if os.path.isdir(root):
            paths = find_scenes(root, a.glob)
            base = root
        else:
            paths = [root]
            d = os.path.dirname(os.path.abspath(root))
            base = os.path.dirname(d)
            if os.path.basename(d) == "pbrt":
                base = os.path.dirname(base)
        for p in paths:
            s = Scene(p, absent)
            s.parse_file(s.path)
            out["scenes"].append(s.summary(base))
    json.dump(out, sys.stdout, indent=a.indent, sort_keys=False, default=str)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
