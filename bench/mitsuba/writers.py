"""The neutral description of translate.describe -> Mitsuba 3 dict (mi.load_dict)
or XML (mi.load_string / the `mitsuba` command). Both are loaded and rendered
by the bench's validation, which checks that they give the same image."""
from xml.sax.saxutils import quoteattr

BLACK = {"type": "diffuse", "reflectance": ("rgb", [0.0, 0.0, 0.0])}


def _integrator(d):
    # rr_depth: Mitsuba's default (5); hide_emitters: false (Mitsuba's default, stated).
    return {"type": "path", "max_depth": ("integer", d["max_depth"]),
            "hide_emitters": ("boolean", False)}


def _sensor(d):
    c = d["camera"]
    return {"type": "perspective", "fov": ("float", c["fov"]), "fov_axis": ("string", "y"),
            "far_clip": ("float", 1e7),
            "to_world": ("lookat", (c["origin"], c["target"], c["up"])),
            "sampler": {"type": d["sampler"], "sample_count": ("integer", d["spp"])},
            "film": {"type": "hdrfilm", "width": ("integer", c["width"]),
                     "height": ("integer", c["height"]), "pixel_format": ("string", "rgb"),
                     "component_format": ("string", "float32"), "rfilter": {"type": "box"}}}


def _shape(s):
    out = {"type": s["type"]}
    if s["to_world"] is not None:
        out["to_world"] = ("matrix", s["to_world"])
    for k, v in s["params"].items():
        if k == "center":
            out[k] = ("point", v)
        elif isinstance(v, bool):
            if v:
                out[k] = ("boolean", v)
        else:
            out[k] = ("float", v)
    if "emit" in s:
        out["bsdf"] = BLACK  # a light does not scatter (mcrt's diffuse_light)
        out["emitter"] = {"type": "area", "radiance": ("rgb", s["emit"])}
    else:
        out["bsdf"] = ("ref", s["bsdf_ref"])
    return out


def tree(d):
    """Ordered (name, node) pairs of the whole scene."""
    items = [("integrator", _integrator(d)), ("sensor", _sensor(d))]
    items += [(k, v) for k, v in d["bsdfs"].items()]
    items += [(s["id"], _shape(s)) for s in d["shapes"]]
    if any(x > 0 for x in d["background"]):
        items.append(("background", {"type": "constant", "radiance": ("rgb", d["background"])}))
    return items


# ---- dict ------------------------------------------------------------------
def _to_dict_value(v, mi):
    if isinstance(v, dict):
        return {k: _to_dict_value(x, mi) for k, x in v.items()}
    if isinstance(v, str):
        return v
    kind, val = v
    if kind == "rgb":
        return {"type": "rgb", "value": [float(x) for x in val]}
    if kind == "ref":
        return {"type": "ref", "id": val}
    if kind == "matrix":
        return mi.ScalarTransform4f(val.tolist())
    if kind == "matrix3":  # a texture's to_uv
        return mi.ScalarTransform3f(val.tolist())
    if kind == "lookat":
        o, t, u = val
        return mi.ScalarTransform4f().look_at(origin=o, target=t, up=u)
    if kind == "point":
        return mi.ScalarPoint3f(val)
    return val


def to_dict(d, mi):
    out = {"type": "scene"}
    for name, node in tree(d):
        out[name] = _to_dict_value(node, mi)
    return out


# ---- XML -------------------------------------------------------------------
def _num(x):
    return repr(float(x))


PLUGIN_TAGS = {"sampler", "film", "rfilter", "emitter", "bsdf"}


def _xml_node(tag, node, id_, ind, name=None):
    pad = "    " * ind
    lines = [f'{pad}<{tag} type="{node["type"]}"' + (f' name={quoteattr(name)}' if name else "")
             + (f' id={quoteattr(id_)}>' if id_ else ">")]
    for k, v in node.items():
        if k == "type":
            continue
        if isinstance(v, dict):  # nested plugin: sampler, film, rfilter, emitter, bsdf, or a texture
            if k in PLUGIN_TAGS:
                lines += _xml_node(k, v, None, ind + 1)
            else:
                lines += _xml_node("texture", v, None, ind + 1, name=k)
            continue
        kind, val = v
        p = pad + "    "
        if kind == "rgb":
            lines.append(f'{p}<rgb name="{k}" value="{", ".join(_num(x) for x in val)}"/>')
        elif kind == "ref":
            lines.append(f'{p}<ref id={quoteattr(val)}/>')
        elif kind in ("matrix", "matrix3"):
            vals = " ".join(_num(x) for x in val.reshape(-1))
            lines.append(f'{p}<transform name="{k}"><matrix value="{vals}"/></transform>')
        elif kind == "lookat":
            o, t, u = (", ".join(_num(x) for x in w) for w in val)
            lines.append(f'{p}<transform name="{k}"><lookat origin="{o}" target="{t}" up="{u}"/></transform>')
        elif kind == "point":
            lines.append(f'{p}<point name="{k}" x="{_num(val[0])}" y="{_num(val[1])}" z="{_num(val[2])}"/>')
        elif kind == "boolean":
            lines.append(f'{p}<boolean name="{k}" value="{"true" if val else "false"}"/>')
        elif kind == "float":
            lines.append(f'{p}<float name="{k}" value="{_num(val)}"/>')
        else:
            lines.append(f'{p}<{kind} name="{k}" value="{val}"/>')
    lines.append(f"{pad}</{tag}>")
    return lines


def to_xml(d, comment=""):
    ids = set(d["bsdfs"])
    lines = ['<?xml version="1.0" encoding="utf-8"?>']
    if comment:
        lines.append(f"<!-- {comment} -->")
    lines.append('<scene version="3.0.0">')
    for name, node in tree(d):
        tag = ("integrator" if name == "integrator" else "sensor" if name == "sensor"
               else "bsdf" if name in ids else "emitter" if name == "background" else "shape")
        lines += _xml_node(tag, node, name if tag in ("bsdf", "shape") else None, 1)
    lines.append("</scene>")
    return "\n".join(lines) + "\n"
