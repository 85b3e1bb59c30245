"""python -m bench.mitsuba [SCENE.json ...] [options]   (from the repository root)
   python -m bench.mitsuba --pbrt FILE.pbrt [--pbrt ...] [--size W --spp N --max-depth D]
   python -m bench.mitsuba --pbrt-throughput [--triangles N --size W --spp N --rounds R --ref-spp N]

Compares mcrt's efficiency, 1 / (MSE x render seconds), with Mitsuba 3's path
tracer on the same scenes. Runs itself with .venv/bin/python (creating .venv
with scripts/setup.sh --python if absent) and installs Mitsuba 3 there on first use
(`pip install mitsuba`); Mitsuba is needed by this bench only.
"""
import argparse
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
VENV = ROOT / ".venv"
DEFAULT_SCENES = ["scenes/cornell_rect.json", "scenes/cornell_disk_large.json"]
ALL_SCENES = ["scenes/cornell_rect.json", "scenes/cornell_rect_large.json",
              "scenes/cornell_disk.json", "scenes/cornell_disk_large.json"]


def bootstrap():
    py = VENV / "bin" / "python"
    if not py.exists():
        print("bench.mitsuba: no .venv, running scripts/setup.sh", file=sys.stderr)
        subprocess.run(["bash", str(ROOT / "scripts" / "setup.sh"), "--python"], check=True)
    if Path(sys.prefix).resolve() != VENV.resolve():
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
        os.execve(str(py), [str(py), "-m", "bench.mitsuba", *sys.argv[1:]], env)
    if importlib.util.find_spec("mitsuba") is None:
        print("bench.mitsuba: installing Mitsuba 3 into .venv (pip install mitsuba)", file=sys.stderr)
        subprocess.run([str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check", "mitsuba"],
                       check=True)


def parse(argv):
    p = argparse.ArgumentParser(prog="python -m bench.mitsuba", description=__doc__.split("\n\n")[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="*", help=f"scene files (default: {' '.join(DEFAULT_SCENES)})")
    p.add_argument("--all", action="store_true", help="the four Cornell scenes: " + " ".join(ALL_SCENES))
    p.add_argument("--quick", action="store_true",
                   help="check the pipeline in about a minute: 32x32, spp 4,16, 2 seeds, 512-spp references")
    p.add_argument("--out", help="output and reference cache directory (default build/mitsuba-compare, "
                                 "build/mitsuba-compare/quick with --quick)")
    p.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"), help="the mcrt executable (default build/mcrt)")
    p.add_argument("--mcrt-config", action="append", default=[], metavar='NAME="FLAGS"',
                   help='an mcrt configuration to measure, e.g. mis="--integrator mis --sampler sobol"; repeatable')
    p.add_argument("--mcrt-args", metavar='"FLAGS"', help='shorthand for --mcrt-config mcrt="FLAGS"')
    p.add_argument("--mcrt-ref-args", default="", metavar='"FLAGS"',
                   help="mcrt flags of mcrt's own converged reference (default: none)")
    p.add_argument("--mitsuba-samplers", default="independent,stratified,multijitter,ldsampler",
                   help="Mitsuba samplers to measure (default: %(default)s)")
    p.add_argument("--mitsuba-ref-sampler", default="multijitter",
                   help="sampler of Mitsuba's reference (default %(default)s: 5-10x less noise than "
                        "independent in these scenes, still unbiased, independent halves)")
    p.add_argument("--spp", help="comma-separated spp of the measurements (default 16,64,256)")
    p.add_argument("--seeds", type=int, help="seeds per spp and renderer (default 3)")
    p.add_argument("--ref-spp", type=int, help="spp of both converged references (default 8192)")
    p.add_argument("--size", type=int, help="image width; height follows the scene's aspect (default 200)")
    p.add_argument("--threads", type=int, default=2, help="threads of both renderers (default 2)")
    p.add_argument("--max-depth", type=int, help="mcrt max depth (default: the scene's); Mitsuba gets it + 1")
    p.add_argument("--xml", action="store_true", help="only write the Mitsuba XML of the scenes to OUT/xml")
    g = p.add_argument_group("pbrt-v4 files (side-by-side comparison, see README.md#pbrt-v4-files-side-by-side)")
    g.add_argument("--pbrt", action="append", metavar="FILE.pbrt",
                   help="render this pbrt-v4 file with mcrt and, translated, with Mitsuba; repeatable. "
                        "--size, --spp (one value), --max-depth (pbrt's maxdepth) override the file")
    g.add_argument("--named-spectra", choices=("mitsuba", "pbrt"), default="mitsuba",
                   help="named metals: Mitsuba's presets (default) or pbrt-v4's tables as mcrt converts them")
    g.add_argument("--variant", default="scalar_rgb",
                   help="Mitsuba variant, here and for the Cornell scenes (default %(default)s; "
                        "llvm_ad_rgb is its fastest on a CPU)")
    g.add_argument("--reference", help="an EXR whose mean both images are compared with (e.g. TungstenRender.exr)")
    g.add_argument("--png-width", type=int, default=256, help="width of each of the PNG's three panels")
    t = p.add_argument_group("throughput on a >= 1M-triangle mesh against Mitsuba's llvm_ad_rgb "
                             "(see README.md#throughput-on-a-mesh-of-over-10⁶-triangles)")
    t.add_argument("--pbrt-throughput", action="store_true",
                   help="generate the mesh scene into OUT (default build/mitsuba-throughput) and measure "
                        "samples/s and efficiency of mcrt and Mitsuba llvm_ad_rgb (and scalar_rgb), interleaved")
    t.add_argument("--triangles", type=int, default=1_300_000,
                   help="at least this many mesh triangles (an icosphere: 20 * 4^level; default %(default)s)")
    t.add_argument("--throughput-scene", metavar="FILE.pbrt",
                   help="a pbrt-v4 file instead of the generated mesh scene (e.g. bench/many_lights.py's); "
                        "--mcrt-config then names mcrt's configurations")
    t.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default %(default)s)")
    t.add_argument("--ref-pass-spp", type=int, default=64,
                   help="spp of each pass of Mitsuba's reference (default %(default)s)")
    t.add_argument("--no-scalar", action="store_true", help="leave out Mitsuba's scalar_rgb")
    t.add_argument("--no-profile", action="store_true", help="leave out the perf profile of mcrt")
    t.add_argument("--profile-spp", type=int, default=64, help="spp of the profiled mcrt render (default %(default)s)")
    t.add_argument("--perf-freq", type=int, default=499, help="perf sampling frequency, Hz (default %(default)s)")
    t.add_argument("--wait-idle", type=float, default=0, metavar="MIN",
                   help="before the rounds, wait up to MIN minutes for the 1-minute load average to fall "
                        "below --idle-load (default: no wait)")
    t.add_argument("--idle-load", type=float, default=0.7, help="the load average --wait-idle waits for")
    a = p.parse_args(argv)
    if a.pbrt_throughput:
        a.spp = int(a.spp or 16)
        a.size = a.size or 256
        a.ref_spp = a.ref_spp or 4096
        a.max_depth = 5 if a.max_depth is None else a.max_depth
        a.out = Path(a.out).resolve() if a.out else ROOT / "build" / "mitsuba-throughput"
        a.mcrt = Path(a.mcrt).resolve()
        a.throughput_scene = Path(a.throughput_scene).resolve() if a.throughput_scene else None
        configs = [c.split("=", 1) for c in a.mcrt_config]
        if any(len(c) != 2 or not c[0] for c in configs):
            p.error('--mcrt-config takes NAME="FLAGS"')
        a.configs = [(n, f.split()) for n, f in configs]
        if a.ref_spp % (2 * a.ref_pass_spp):
            p.error("--ref-spp must be a multiple of 2 x --ref-pass-spp (two halves of whole passes)")
        return a
    if a.pbrt:
        a.spp_given = a.spp is not None
        a.spp = [int(x) for x in (a.spp or "16").split(",")]
        a.out = Path(a.out).resolve() if a.out else ROOT / "build" / "mitsuba-compare" / "pbrt"
        a.mcrt = Path(a.mcrt).resolve()
        return a
    q = a.quick
    a.spp = [int(x) for x in (a.spp or ("4,16" if q else "16,64,256")).split(",")]
    a.seeds = a.seeds or (2 if q else 3)
    a.ref_spp = a.ref_spp or (512 if q else 8192)  # halves of 256 / 4096 spp: squares for multijitter
    a.size = a.size or (32 if q else 200)
    default_out = ROOT / "build" / "mitsuba-compare"
    a.out = Path(a.out).resolve() if a.out else default_out / "quick" if q else default_out
    a.scenes = ([Path(s).resolve() for s in a.scenes] if a.scenes else
                [ROOT / s for s in (ALL_SCENES if a.all else DEFAULT_SCENES)])
    a.mcrt = Path(a.mcrt).resolve()
    a.samplers = [s for s in a.mitsuba_samplers.split(",") if s]
    configs = [c.split("=", 1) for c in a.mcrt_config]
    if any(len(c) != 2 or not c[0] for c in configs):
        p.error('--mcrt-config takes NAME="FLAGS"')
    if a.mcrt_args is not None:
        configs.append(["mcrt", a.mcrt_args])
    a.configs = configs or [["default", ""]]
    if len({c[0] for c in a.configs}) != len(a.configs):
        p.error("--mcrt-config names must differ")
    return a


if __name__ == "__main__":
    bootstrap()
    args = parse(sys.argv[1:])
    if args.pbrt_throughput:
        from . import pbrt_throughput
        pbrt_throughput.main(args)
    elif args.pbrt:
        from . import pbrt_compare
        pbrt_compare.main(args)
    else:
        from . import run
        run.main(args, sys.argv[1:])
