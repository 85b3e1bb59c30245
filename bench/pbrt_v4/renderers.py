"""Running the two renderers on a settings copy, and reading their images.

Each run is timed by the wall clock around the whole process (parsing, the
acceleration structures and writing the image included), the same for
both: neither renderer's own timer covers the same span as the other's.
"""
import os
import sys
import subprocess
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))


class RenderError(Exception):
    pass


def read_exr(path):
    """The RGB channels of an EXR as float64, (height, width, 3), by the
    study package's reader (scripts/mcrt_study/exr.py: numpy and zlib; it
    reads both renderers' files)."""
    from mcrt_study.exr import read_rgb
    return np.asarray(read_rgb(path), dtype=np.float64)


def _run(cmd, out):
    if out.exists():
        out.unlink()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if p.returncode != 0 or not out.exists():
        last = (p.stderr.strip() or p.stdout.strip()).splitlines()[-1:] or ["(no message)"]
        raise RenderError(f"{Path(cmd[0]).name} exit {p.returncode}: {last[0]}")
    return seconds


def mcrt(binary, scene, out, spp, seed, threads):
    cmd = [str(binary), "render", str(scene), "-o", str(out), "--spp", str(spp), "--seed", str(seed),
           "--threads", str(threads), "--quiet"]
    return _run(cmd, Path(out))


def pbrt(binary, scene, out, spp, seed, threads):
    cmd = [str(binary), "--nthreads", str(threads), "--quiet", "--seed", str(seed), "--spp", str(spp),
           "--outfile", str(out), str(scene)]
    return _run(cmd, Path(out))


RUNNERS = {"mcrt": mcrt, "pbrt-v4": pbrt}
