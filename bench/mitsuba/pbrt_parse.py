"""pbrt-v4 scene files -> a flat list of directives (syntax only).

A directive is `Directive(name, args, type, params, loc)`:
- `args`: the positional values (numbers of Translate, the name of a
  MakeNamedMaterial, the three strings of Texture, ...);
- `type`: the quoted class of Shape, Material, Camera, ... ('' if none);
- `params`: {name: Param(type, name, values)} of the parameter list;
- `loc`: "FILE:LINE" for error messages.

`Include` and `Import` are expanded in place (the same thing here: no
instancing of named objects). Relative file names are resolved against the
directory of the top-level file, as pbrt-v4 does. `.gz` files are read
through gzip.
"""
import gzip
import re
from dataclasses import dataclass, field
from pathlib import Path


class PbrtError(Exception):
    """A file the translation cannot take: one line, with FILE:LINE."""


@dataclass
class Param:
    type: str
    name: str
    values: list


@dataclass
class Directive:
    name: str
    args: list
    type: str = ""
    params: dict = field(default_factory=dict)
    loc: str = ""


# Directives with positional arguments: how many numbers, or strings.
NUMBERS = {"Translate": 3, "Scale": 3, "Rotate": 4, "LookAt": 9, "Transform": 16, "ConcatTransform": 16}
STRINGS = {"CoordinateSystem": 1, "CoordSysTransform": 1, "NamedMaterial": 1, "MakeNamedMaterial": 1,
           "Texture": 3, "ColorSpace": 1, "MakeNamedMedium": 1, "ObjectBegin": 1, "ObjectInstance": 1,
           "Attribute": 1}
TYPED = {"Shape", "Material", "Camera", "Film", "PixelFilter", "Sampler", "Integrator", "Accelerator",
         "AreaLightSource", "LightSource"}
BARE = {"WorldBegin", "WorldEnd", "AttributeBegin", "AttributeEnd", "TransformBegin", "TransformEnd",
        "ReverseOrientation", "Identity", "ObjectEnd"}
WITH_PARAMS = TYPED | {"MakeNamedMaterial", "Texture", "Attribute", "Option", "MakeNamedMedium"}

_TOKEN = re.compile(r'\s+|#[^\n]*|"[^"]*"|\[|\]|[^\s\[\]"#]+')


def _tokens(text, fname):
    line = 1
    for m in _TOKEN.finditer(text):
        t = m.group(0)
        if t[0] == '"':
            yield ("str", t[1:-1], f"{fname}:{line}")
        elif t[0] == "[" or t[0] == "]":
            yield (t, t, f"{fname}:{line}")
        elif not t[0].isspace() and t[0] != "#":
            yield ("word", t, f"{fname}:{line}")
        line += t.count("\n")
    if sum(len(m.group(0)) for m in _TOKEN.finditer(text)) != len(text):
        raise PbrtError(f"{fname}: unterminated string")


def _number(tok):
    kind, val, loc = tok
    try:
        return float(val) if kind == "word" else None
    except ValueError:
        return None


def _read(path):
    data = Path(path).read_bytes()
    if str(path).endswith(".gz"):
        data = gzip.decompress(data)
    return data.decode("utf-8", errors="replace")


def parse_file(path, base_dir=None, _depth=0):
    """The directives of `path`, Include/Import expanded."""
    path = Path(path)
    base_dir = Path(base_dir) if base_dir else path.resolve().parent
    if _depth > 32:
        raise PbrtError(f"{path}: Include nested more than 32 deep")
    try:
        toks = list(_tokens(_read(path), path.name))
    except OSError as e:
        raise PbrtError(f"{path}: {e.strerror or e}") from None
    out, i = [], 0

    def value_list(j):
        """Values starting at toks[j]: [ ... ] or one value; (values, next j)."""
        if j >= len(toks):
            raise PbrtError(f"{toks[-1][2]}: a parameter without a value")
        if toks[j][0] == "[":
            vals, j = [], j + 1
            while j < len(toks) and toks[j][0] != "]":
                vals.append(toks[j])
                j += 1
            if j >= len(toks):
                raise PbrtError(f"{toks[-1][2]}: '[' without ']'")
            return vals, j + 1
        return [toks[j]], j + 1

    while i < len(toks):
        kind, name, loc = toks[i]
        if kind != "word":
            raise PbrtError(f"{loc}: expected a directive, found {name!r}")
        i += 1
        if name in ("Include", "Import"):
            if i >= len(toks) or toks[i][0] != "str":
                raise PbrtError(f"{loc}: {name} needs a file name")
            inc = Path(toks[i][1])
            i += 1
            out += parse_file(inc if inc.is_absolute() else base_dir / inc, base_dir, _depth + 1)
            continue
        d = Directive(name, [], loc=loc)
        if name in NUMBERS:
            if name in ("Transform", "ConcatTransform") and i < len(toks) and toks[i][0] == "[":
                vals, i = value_list(i)
            else:
                vals, i = toks[i:i + NUMBERS[name]], i + NUMBERS[name]
            nums = [_number(t) for t in vals]
            if len(nums) != NUMBERS[name] or any(n is None for n in nums):
                raise PbrtError(f"{loc}: {name} takes {NUMBERS[name]} numbers")
            d.args = nums
        elif name in STRINGS:
            for _ in range(STRINGS[name]):
                if i >= len(toks) or toks[i][0] != "str":
                    raise PbrtError(f"{loc}: {name} takes {STRINGS[name]} quoted string(s)")
                d.args.append(toks[i][1])
                i += 1
        elif name in TYPED:
            if i >= len(toks) or toks[i][0] != "str":
                raise PbrtError(f"{loc}: {name} needs a quoted type")
            d.type = toks[i][1]
            i += 1
        elif name == "MediumInterface":
            while i < len(toks) and toks[i][0] == "str" and " " not in toks[i][1]:
                d.args.append(toks[i][1])
                i += 1
            out.append(d)
            continue
        elif name not in BARE and name != "Option":
            raise PbrtError(f"{loc}: unknown directive {name!r}")
        if name in WITH_PARAMS:
            while i < len(toks) and toks[i][0] == "str":
                decl = toks[i][1].split()
                if len(decl) != 2:
                    raise PbrtError(f"{toks[i][2]}: bad parameter declaration {toks[i][1]!r}")
                vals, i = value_list(i + 1)
                ptype, pname = decl
                d.params[pname] = Param(ptype, pname, _values(ptype, vals, toks[i - 1][2]))
        out.append(d)
    return out


def _values(ptype, vals, loc):
    if ptype in ("string", "texture"):
        if any(k != "str" for k, _, _ in vals):
            raise PbrtError(f"{loc}: {ptype} values must be quoted")
        return [v for _, v, _ in vals]
    if ptype == "bool":
        out = []
        for _, v, _ in vals:
            if v not in ("true", "false"):
                raise PbrtError(f"{loc}: bool values are true or false, not {v!r}")
            out.append(v == "true")
        return out
    if ptype == "spectrum" and vals and vals[0][0] == "str":
        return [v for _, v, _ in vals]  # a named spectrum (or a file, refused later)
    nums = [_number(t) for t in vals]
    if any(n is None for n in nums):
        raise PbrtError(f"{loc}: {ptype} values must be numbers")
    return nums
