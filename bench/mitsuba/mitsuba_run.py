"""Running Mitsuba 3 (PyPI package `mitsuba`, variant scalar_rgb) in this process.

Threads: in scalar variants Mitsuba renders with dr::parallel_for on the
nanothread pool and uses pool_size() + 1 threads (src/render/integrator.cpp;
the `mitsuba -t N` command does pool_set_size(N - 1)). From Python the pool is
sized by drjit.set_thread_count(N) ("N - 1 worker threads" plus the calling
thread). Observed with Mitsuba 3.9.1: after set_thread_count(N) exactly N
threads accumulate CPU time during mi.render (Mitsuba's own log line says
"N + 1 threads"). The bench records, per render, the process CPU time and how
many of the process's threads were busy (/proc/self/task, Linux).
"""
import glob
import os
import time

import numpy as np

from . import writers

VARIANT = "scalar_rgb"


class Mitsuba:
    def __init__(self, threads, variant=VARIANT):
        if variant.startswith("llvm"):  # Debian's libLLVM (apt-get install libllvm19) unless set
            os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
        import drjit as dr
        import mitsuba as mi
        mi.set_variant(variant)
        self.variant = variant
        mi.set_log_level(mi.LogLevel.Warn)  # no progress bar in timed renders
        dr.set_thread_count(threads)
        self.mi, self.dr = mi, dr
        self.threads = dr.thread_count()
        self.version = mi.__version__
        self.drjit_version = dr.__version__
        self._scenes = {}

    def load(self, desc, key):
        """mi.load_dict of a translated scene, cached under `key` (not timed)."""
        if key not in self._scenes:
            self._scenes[key] = self.mi.load_dict(writers.to_dict(desc, self.mi))
        return self._scenes[key]

    def load_xml(self, text):
        return self.mi.load_string(text)

    def render(self, scene, spp, seed, busy=None):
        """(image HxWx3 float32, wall seconds of mi.render alone, process CPU seconds);
        `busy`, a dict, gets the number of threads busy > 10 % of the wall time."""
        before = _thread_cpu() if busy is not None else None
        c0, t0 = time.process_time(), time.perf_counter()
        img = self.mi.render(scene, spp=spp, seed=seed)
        self.dr.eval(img)  # LLVM variants evaluate lazily: the rendering happens here
        self.dr.sync_thread()
        t1, c1 = time.perf_counter(), time.process_time()
        if busy is not None:
            after = _thread_cpu()
            busy["busy_threads"] = sum(after[k] - before.get(k, 0) > 0.1 * (t1 - t0) for k in after)
        arr = np.array(img, dtype=np.float32)
        got = scene.sensors()[0].sampler().sample_count()
        if got != spp:  # stratified/ldsampler round spp to a square / power of two
            raise RuntimeError(f"Mitsuba rendered {got} spp instead of {spp}: "
                               "use squares of powers of two (16, 64, 256...)")
        return arr[..., :3], t1 - t0, c1 - c0

    @staticmethod
    def call_text(sampler, spp, seed, variant=VARIANT):
        return (f"mi.render(mi.load_dict(scene with sampler {sampler!r}), spp={spp}, seed={seed})"
                f"  [variant {variant}]")


def _thread_cpu():
    """CPU seconds of each thread of this process (Linux; {} elsewhere)."""
    out, tick = {}, os.sysconf("SC_CLK_TCK")
    for path in glob.glob("/proc/self/task/*/stat"):
        try:
            f = open(path).read().rsplit(")", 1)[1].split()
            out[path] = (int(f[11]) + int(f[12])) / tick
        except (OSError, IndexError, ValueError):
            pass
    return out
