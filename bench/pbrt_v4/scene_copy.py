"""A copy of a pbrt-v4 file with the render settings both renderers use.

The copy is written beside the original (relative Include, PLY and texture
names resolve against the top-level file's directory in both renderers) and
replaces, in the top-level file, the statements that set what a comparison
fixes:

- `Film`: its kind and parameters, with `xresolution`/`yresolution` set,
  `filename` dropped (each renderer is given its output) and `savefp16`
  false (pbrt-v4 writes half floats by default);
- `Sampler`: kept with `pixelsamples` set (both renderers also take --spp);
- `Integrator`: `"path"` (or `"volpath"`) with `maxdepth` set, whatever the
  file asked for (its other parameters dropped; `regularize` is not kept).

Every line keeps its number, so that a renderer's message about the copy
names the original's line.

Missing statements are added before `WorldBegin`. A Film, Sampler or
Integrator set in an included file is not seen: refused with one line.
"""
import re
from pathlib import Path

_TOKEN = re.compile(r'\s+|#[^\n]*|"[^"]*"|\[|\]|[^\s\[\]"#]+')


class SceneError(Exception):
    """A file this comparison cannot take: one line, FILE:LINE: reason."""


def _statements(text):
    """(keyword, start, end, tokens) for each top-level statement of the file."""
    out, cur, line = [], None, 1
    for m in _TOKEN.finditer(text):
        t = m.group(0)
        if t[0].isspace() or t[0] == "#":
            line += t.count("\n")
            continue
        if t[0] not in '"[]' and re.match(r"[A-Z][A-Za-z]*$", t):
            if cur:
                out.append(cur)
            cur = [t, m.start(), m.end(), [], line]
        elif cur:
            cur[2] = m.end()
            cur[3].append(t)
        line += t.count("\n")
    if cur:
        out.append(cur)
    return out


def _params(tokens):
    """The statement's quoted kind (if first) and its parameter list as
    [(declaration, [value tokens])], in order."""
    kind, i, params = None, 0, []
    if tokens and tokens[0].startswith('"') and len(tokens[0][1:-1].split()) == 1:
        kind, i = tokens[0], 1
    while i < len(tokens):
        decl = tokens[i]
        i += 1
        vals = []
        if i < len(tokens) and tokens[i] == "[":
            j = tokens.index("]", i)
            vals = tokens[i + 1:j]
            i = j + 1
        elif i < len(tokens):
            vals = [tokens[i]]
            i += 1
        params.append((decl, vals))
    return kind, params


def _name(decl):
    return decl[1:-1].split()[-1]


def _render(keyword, kind, params):
    body = " ".join(f'{d} [ {" ".join(v)} ]' for d, v in params)
    return f"{keyword} {kind} {body}".rstrip()


def _grey(tokens):
    """A light's parameter tokens with each `rgb L` made grey of the same
    luminance (Rec. 709 / sRGB weights), and whether any was."""
    kind, params = _params(tokens)
    changed = False
    for i, (d, v) in enumerate(params):
        if d[1:-1].split() == ["rgb", "L"] and len(v) == 3:
            y = 0.2126 * float(v[0]) + 0.7152 * float(v[1]) + 0.0722 * float(v[2])
            params[i] = ('"rgb L"', [f"{y:.9g}"] * 3)
            changed = True
    return kind, params, changed


def settings_copy(path, width, height, spp, max_depth, integrator="path", grey_lights=False):
    """Writes the copy beside `path` and returns its Path. The caller
    removes it. grey_lights: every `rgb L` of the top-level file's
    AreaLightSource and LightSource statements made grey of the same
    luminance (lights in included files are not touched)."""
    path = Path(path)
    if path.suffix == ".gz":
        raise SceneError(f"{path}:1: a compressed top-level file (unpack it first)")
    text = path.read_text()
    stmts = _statements(text)
    world = next((s for s in stmts if s[0] == "WorldBegin"), None)
    if world is None:
        raise SceneError(f"{path}:1: no WorldBegin in the top-level file")
    found = {}
    for s in stmts:
        if s[0] in ("Film", "Sampler", "Integrator"):
            if s[1] > world[1]:
                raise SceneError(f"{path}:{s[4]}: {s[0]} after WorldBegin")
            found[s[0]] = s
    film_kind, film = '"rgb"', []
    if "Film" in found:
        film_kind, film = _params(found["Film"][3])
        if film_kind not in ('"rgb"', None):
            raise SceneError(f"{path}:{found['Film'][4]}: Film {film_kind}: only \"rgb\" films are compared")
        film_kind = '"rgb"'
    film = [(d, v) for d, v in film if _name(d) not in ("xresolution", "yresolution", "filename", "savefp16")]
    film += [('"integer xresolution"', [str(width)]), ('"integer yresolution"', [str(height)]),
             ('"bool savefp16"', ["false"])]
    sampler_kind, sampler = '"zsobol"', []
    if "Sampler" in found:
        sampler_kind, sampler = _params(found["Sampler"][3])
    sampler = [(d, v) for d, v in sampler if _name(d) != "pixelsamples"]
    sampler += [('"integer pixelsamples"', [str(spp)])]
    new = {"Film": _render("Film", film_kind, film),
           "Sampler": _render("Sampler", sampler_kind, sampler),
           "Integrator": _render("Integrator", '"simplepath"', [('"integer maxdepth"', [str(max_depth)]),
                                                              ('"bool samplelights"', ["false"])])
           if integrator == "bsdf-only" else
           _render("Integrator", f'"{integrator}"', [('"integer maxdepth"', [str(max_depth)])])}
    # Replace back to front so that earlier offsets stay valid.
    edits = [(s[1], s[2], new.pop(k)) for k, s in found.items()]
    if grey_lights:
        for s in stmts:
            if s[0] in ("AreaLightSource", "LightSource"):
                kind, params, changed = _grey(s[3])
                if changed:
                    edits.append((s[1], s[2], _render(s[0], kind, params)))
    edits.sort(reverse=True)
    # Each statement replaced on its first line, the lines it spanned kept
    # empty, and missing ones put on WorldBegin's line: every line keeps
    # its number, so that messages about the copy name the original's lines.
    for start, end, repl in edits:
        text = text[:start] + repl + "\n" * text.count("\n", start, end) + text[end:]
    world_at = next(s[1] for s in _statements(text) if s[0] == "WorldBegin")
    text = text[:world_at] + "".join(v + " " for v in new.values()) + text[world_at:]
    out = path.with_name(f".compare-{path.stem}-{width}x{height}-{spp}-{max_depth}{path.suffix}")
    out.write_text(text)
    return out


def sampler_kind(path):
    """The top-level file's Sampler kind, or None."""
    for s in _statements(Path(path).read_text()):
        if s[0] == "Sampler":
            return _params(s[3])[0]
    return None
