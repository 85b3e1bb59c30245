"""python3 -m bench.pbrt_v4 FILE.pbrt [options] | corpus DIR [options]: see README.md.

Re-runs itself with the repository's .venv (scripts/setup.sh --python makes
it: numpy; EXR files are read by scripts/mcrt_study/exr.py); builds
pbrt-v4 with build.sh when --pbrt is not given and it is not built.
"""
import argparse
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def bootstrap():
    venv = ROOT / ".venv" / "bin" / "python"
    if Path(sys.prefix).resolve() != (ROOT / ".venv").resolve():
        if not venv.exists():
            subprocess.run(["bash", str(ROOT / "scripts" / "setup.sh"), "--python"], check=True)
        os.execv(str(venv), [str(venv), "-m", "bench.pbrt_v4", *sys.argv[1:]])


def parse_corpus(argv):
    ap = argparse.ArgumentParser(prog="python3 -m bench.pbrt_v4 corpus",
                                 description="every scene file under DIR, tried by mcrt and pbrt-v4")
    ap.add_argument("dir", type=Path, help="a local copy of the scenes (e.g. of gonsolo/bitterli)")
    ap.add_argument("--stand-ins", action="store_true", help="a stand-in for every absent file a scene names")
    ap.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"))
    ap.add_argument("--pbrt", help="pbrt-v4's executable (default: build/pbrt-v4/build/pbrt, built on demand)")
    ap.add_argument("--out", default=str(ROOT / "build" / "pbrt-v4-compare"))
    return ap.parse_args(argv)


def parse(argv):
    ap = argparse.ArgumentParser(prog="python3 -m bench.pbrt_v4", description=__doc__.splitlines()[0])
    ap.add_argument("file", type=Path, help="a pbrt-v4 scene file both renderers accept")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel of each measured run")
    ap.add_argument("--ref-spp", type=int, default=1024, help="samples per pixel of each converged image")
    ap.add_argument("--max-depth", type=int, default=5, help="pbrt-v4's maxdepth (mcrt's --max-depth)")
    ap.add_argument("--integrator", choices=("path", "volpath", "bsdf-only"), default="path",
                    help="the Integrator of the settings copy (mcrt renders each with mis); bsdf-only: pbrt-v4's "
                    "simplepath without light samples, whose only estimate is its BSDFs' sampled weight (the "
                    "reference for its layered BSDFs, whose f() path's light samples use is biased)")
    ap.add_argument("--seeds", type=int, default=8, help="measured runs per renderer (seeds 1..K)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--grey-lights", action="store_true", help="every rgb L of the top-level file's lights made "
                    "grey of the same luminance (spectral and RGB rendering then agree)")
    ap.add_argument("--tolerance", type=float, help="X: pass when every channel mean is within X %% and "
                    "|z| < 4 on >= 99 %% of the 8x8 blocks")
    ap.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"))
    ap.add_argument("--pbrt", help="pbrt-v4's executable (default: build/pbrt-v4/build/pbrt, built on demand)")
    ap.add_argument("--out", default=str(ROOT / "build" / "pbrt-v4-compare"))
    args = ap.parse_args(argv)
    if args.seeds < 2:
        ap.error("--seeds must be at least 2 (the block z-scores need each renderer's spread)")
    return args


def main():
    bootstrap()
    corpus = sys.argv[1:2] == ["corpus"]
    args = parse_corpus(sys.argv[2:]) if corpus else parse(sys.argv[1:])
    if args.pbrt is None:
        args.pbrt = subprocess.run(["bash", str(ROOT / "bench" / "pbrt_v4" / "build.sh")], check=True,
                                   capture_output=True, text=True).stdout.split()[-1]
        args.pbrt = str(ROOT / args.pbrt)
    from . import compare, corpus as corpus_mod, renderers, scene_copy
    try:
        return corpus_mod.run(args) if corpus else compare.run(args)
    except (scene_copy.SceneError, renderers.RenderError) as e:
        print(f"bench.pbrt_v4: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
