"""Float images: EXR I/O, MSE exactly as `mcrt diff` (mean over pixels and the
3 channels of (v - r)^2), and the converged references, cached on disk.

A reference is the mean of two half-spp renders with seeds the measurements
never use; the two halves A, B give its own noise without any assumption on
the convergence rate: per pixel and channel Var((A+B)/2) = E[(A-B)^2]/4.
"""
import hashlib
import json
import os
import time
from pathlib import Path

import numpy as np

REF_SEEDS = (1000001, 1000002)

try:
    import OpenImageIO as _oiio
except ImportError:
    _oiio = None

READER = "OpenImageIO" if _oiio else "mitsuba.Bitmap"


def read_exr(path):
    if _oiio:
        arr = _oiio.ImageBuf(str(path)).get_pixels(_oiio.FLOAT)
    else:
        import mitsuba as mi
        arr = np.array(mi.Bitmap(str(path)), dtype=np.float32)
    return np.ascontiguousarray(arr[..., :3], dtype=np.float32)


def write_exr(path, arr):
    import mitsuba as mi
    path = Path(path)
    tmp = path.with_name(path.stem + ".tmp.exr")
    mi.Bitmap(np.ascontiguousarray(arr, dtype=np.float32)).write(str(tmp))
    os.replace(tmp, path)


def mse(img, ref):
    return float(np.mean((img.astype(np.float64) - ref.astype(np.float64)) ** 2))


def key_of(fields):
    return hashlib.sha256(json.dumps(fields, sort_keys=True).encode()).hexdigest()[:16]


def reference(out_dir, name, fields, spp, render_half, log):
    """The cached reference `name` for `fields` (scene content, resolution, spp,
    renderer version and flags): (image, exr path, meta, per-pixel noise map).
    render_half(seed, spp) returns (image, seconds)."""
    key = key_of(fields)
    path = Path(out_dir) / "refs" / f"{name}-{key}.exr"
    meta_path, noise_path = path.with_suffix(".json"), path.with_suffix(".noise.exr")
    if path.exists() and meta_path.exists() and noise_path.exists():
        log(f"reference {path.name}: cached")
        return read_exr(path), path, json.loads(meta_path.read_text()), read_exr(noise_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    log(f"reference {path.name}: rendering 2 x {spp // 2} spp ...")
    t0 = time.time()
    (a, ta), (b, tb) = (render_half(s, spp // 2) for s in REF_SEEDS)
    a64, b64 = a.astype(np.float64), b.astype(np.float64)
    ref = ((a64 + b64) / 2).astype(np.float32)
    n = ref.shape[0] * ref.shape[1] * 3
    meta = {
        "key": key, "fields": fields, "spp": spp, "seeds": list(REF_SEEDS),
        "render_seconds": [ta, tb], "wall_seconds": time.time() - t0,
        "mean": float(ref.astype(np.float64).mean()),
        # MSE the reference's own noise adds to any image's MSE against it
        "noise_mse": float(np.mean((a64 - b64) ** 2) / 4),
        # variance of the reference's mean over pixels and channels
        "var_of_mean": float(np.sum((a64 - b64).sum(axis=2) ** 2) / 4 / n ** 2),
    }
    noise = ((a64 - b64) ** 2 / 4).astype(np.float32)  # Var of each pixel and channel of ref
    write_exr(noise_path, noise)
    write_exr(path, ref)
    meta_path.write_text(json.dumps(meta, indent=1))
    log(f"reference {path.name}: done in {meta['wall_seconds']:.0f} s")
    return ref, path, meta, noise


def red_side(img):
    """Which side of the image the red wall is on: 'left' or 'right'."""
    w = max(1, img.shape[1] // 10)
    redness = [float(img[:, s, 0].mean() / max(img[:, s, 1].mean(), 1e-12))
               for s in (slice(0, w), slice(-w, None))]
    return "left" if redness[0] > redness[1] else "right"
