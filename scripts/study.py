#!/usr/bin/env python3
"""Error against run time of the renderer's configurations.

Runs the whole study with one command: for every Cornell scene, every
configuration of the renderer — light-sampling strategy (``area``,
``solid-angle``) × integrator (``mixture``: Shirley's mixture pdf, ``nee``:
next-event estimation, ``mis``: NEE with multiple importance sampling) ×
sample generator (``independent``, ``stratified``, ``sobol``) — and both
light-transport modes (``global``: the scene's max depth; ``direct``: max
depth 1), it renders a sweep of sample counts with several seeds, measures the
render time (``render_seconds`` from ``mcrt render --stats``: the rendering
alone, no process start, no I/O) and the error against a reference image
(``rmse``, ``mse``, ``relmse`` from ``mcrt diff --json``), then writes a CSV,
markdown tables, plots and a report.

Usage (from the repository root, with the virtual environment made by
scripts/setup.sh)::

    .venv/bin/python scripts/study.py                 # full study -> bench/results/
    .venv/bin/python scripts/study.py --quick         # a few minutes -> build/study-quick/
    .venv/bin/python scripts/study.py --quick --check # and verify the outputs

    # choose what to run: every axis has its option
    .venv/bin/python scripts/study.py --scenes cornell_rect cornell_disk \\
        --strategies area solid-angle --integrators mixture mis \\
        --samplers independent sobol --depths global direct \\
        --spp 4 16 64 --seeds 1 2 3 --ref-spp 4096 --width 300 --height 300 \\
        --threads 2 --mcrt build/mcrt --out /tmp/study

Defaults (the full study): scenes cornell_rect, cornell_rect_large,
cornell_disk, cornell_disk_large (add cornell_materials with --scenes); both
strategies, all three integrators, all three samplers, both depth modes
(36 configurations and modes per scene, 144 over the four scenes); spp 8,
32, 128; seeds 1, 2, 3 (9 renders per configuration and mode: 1296 renders and
as many diffs); half the scenes' width and height (300x300 for the Cornell
scenes' 600x600: the same samples per pixel at a quarter of the cost;
``--width 600 --height 600`` for their own); the scenes' max depth
(``--max-depth`` overrides it for the global mode); a 4096 spp reference per
scene and depth mode (8 in all) rendered with seed 7919; all hardware threads.
About an hour on a 2-core machine that is otherwise idle (renders ~25 min,
references ~20 min, mcrt process start-up and image I/O ~10 min).
``--quick``: 48x48, spp 4, 8, 16, 32, one seed, integrators mixture and mis,
samplers independent and sobol, both depth modes, 1024 spp references, output
in build/study-quick (ignored by git); each of these can still be overridden.

Reference images. One reference per scene and depth mode (max depth), shared
by every strategy, integrator and sampler since they all converge to the same
image, rendered by the reference configuration: ``--ref-integrator`` (default
mis), ``--ref-sampler`` (default sobol) and ``--ref-strategy`` (default:
solid-angle when the mcrt binary supports it for that scene, else area) at
``--ref-spp``. References are cached in OUT/references/ under a key made of the
scene file's content, the resolution, spp, max depth, seed, strategy,
integrator and sampler (``--ref-key-binary`` adds a hash of the mcrt binary),
so they are rendered once; a reference made by mixture + independent has the
key of the earlier, single-integrator study, whose cache stays valid.

Resuming. Every finished point is appended to OUT/results.csv at once; a run
skips the points already there (a point is scene, strategy, integrator,
sampler, max depth, spp, seed). OUT/study_state.json remembers, per scene and
max depth, the settings the points were made with (scene content, resolution,
max depth, reference): when those change, the points of that scene and depth
are dropped and run again. ``--fresh`` discards all previous points
(references stay cached). A results.csv of the earlier format
(scene,strategy,spp,seed,seconds,rmse,mse,relmse) is read as integrator
mixture, sampler independent and the scene's max depth (how it was made) and
rewritten in the new format; a study_state.json of the earlier version is
carried over likewise.

Sweep order. For every seed and spp, every depth mode and configuration is
rendered in turn (the order of the configurations rotated from one point to
the next), so that a drift of the machine's speed affects all configurations
alike.

Unavailable strategies. A configuration that mcrt rejects as "not available
in this build" (exit status 2) is skipped for that scene and named in the
report; the study goes on, and picks it up unchanged once mcrt supports it (a
reference that fell back to area sampling is then rendered again with
solid-angle sampling, and the points of its scene and depth with it). Any
other mcrt failure is reported too and makes the exit status 1.

Progress is shown on stderr as a plain-text bar with an estimate of the time
left. ``--report-only`` rebuilds tables, plots and report from the CSV
without rendering (without --spp or --seeds, for the spp values and seeds the
CSV holds). ``python scripts/study.py --help`` lists every option.

Analysis. The efficiency of a render is 1/(MSE × seconds); a configuration's
efficiency is the geometric mean of its renders' efficiencies over every spp
and seed of the sweep, compared with the baseline (area, mixture, independent)
of the same scene and depth mode. The tables give, per scene and depth mode,
the efficiency of every configuration and its ratio to the baseline (the best
marked), the MSE of every configuration interpolated at a few equal time
budgets, and the log-log slope of RMSE against spp (−0.5 for Monte Carlo;
steeper for a quasi-Monte-Carlo sampler where the integrand is smooth enough,
e.g. direct lighting). The earlier area-vs-solid-angle tables and plots are
kept for the slice integrator mixture, sampler independent, global depth (or
the first selected integrator, sampler and mode when those are not run).

Outputs (in OUT):
    results.csv          scene,strategy,integrator,sampler,max_depth,spp,seed,
                         seconds,rmse,mse,relmse (max_depth: the value passed
                         to mcrt, 1 in the direct mode)
    tables.md            the markdown tables
    README.md            the report: machine, commit, command line, date,
                         tables, sampler costs and the plots
    efficiency_global.png, efficiency_direct.png  (efficiency per configuration
                         and scene, grouped bars, log scale)
    rmse_vs_spp.png, time_vs_spp.png, rmse_vs_time.png, efficiency.png,
    rmse_diff_SCENE.png  (the area-vs-solid-angle slice; RMSE area - RMSE
                         solid-angle per spp)
    samplers.json        raw output of mcrt_bench_samplers
    references/          cached reference images (EXR) and their metadata

``--check`` verifies the outputs afterwards (files exist, CSV columns, every
configuration has its points in every scene and depth mode, RMSE decreasing
with spp: negative log-log slope per scene, depth mode and configuration,
efficiency tables and plots present) and exits 1 when a check fails; the test
suite runs ``--quick --check``.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import datetime
import hashlib
import itertools
import json
import math
import os
import platform
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

REPO_ROOT = Path(__file__).resolve().parent.parent
SCENES_DIR = REPO_ROOT / "scenes"

CSV_COLUMNS = ["scene", "strategy", "integrator", "sampler", "max_depth", "spp", "seed",
               "seconds", "rmse", "mse", "relmse"]
# The CSV of the earlier, single-integrator study: read, then rewritten as CSV_COLUMNS.
OLD_CSV_COLUMNS = ["scene", "strategy", "spp", "seed", "seconds", "rmse", "mse", "relmse"]
STRATEGIES = ["area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle"]
# The default sweep (the committed report); the others by --strategies.
DEFAULT_STRATEGIES = ["area", "solid-angle"]
# References with --ref-strategy auto: the first this mcrt has for the scene.
REF_STRATEGY_PREFERENCE = ["solid-angle", "area"]
INTEGRATORS = ["mixture", "nee", "mis"]
SAMPLERS = ["independent", "stratified", "sobol"]
DEPTH_MODES = ["global", "direct"]
DIRECT_MAX_DEPTH = 1
# What mcrt uses when a scene file gives no max_depth (src/scene_loader.hpp).
MCRT_DEFAULT_MAX_DEPTH = 50
# How the earlier study rendered: its points and references are these.
LEGACY_INTEGRATOR = "mixture"
LEGACY_SAMPLER = "independent"

DEFAULT_SCENES = ["cornell_rect", "cornell_rect_large", "cornell_disk", "cornell_disk_large"]
DEFAULT_SPP = [8, 32, 128]
DEFAULT_SEEDS = [1, 2, 3]
# The full study renders at this fraction of the scenes' own resolution (same spp).
DEFAULT_SCALE = 0.5
DEFAULT_REF_SPP = 4096
DEFAULT_REF_SEED = 7919
DEFAULT_REF_INTEGRATOR = "mis"
DEFAULT_REF_SAMPLER = "sobol"
DEFAULT_OUT = REPO_ROOT / "bench" / "results"

QUICK_SPP = [4, 8, 16, 32]
QUICK_SEEDS = [1]
QUICK_REF_SPP = 1024
QUICK_SIZE = 48
QUICK_INTEGRATORS = ["mixture", "mis"]
QUICK_SAMPLERS = ["independent", "sobol"]
QUICK_OUT = REPO_ROOT / "build" / "study-quick"

RESULTS_CSV = "results.csv"
STATE_JSON = "study_state.json"
TABLES_MD = "tables.md"
REPORT_MD = "README.md"
SAMPLERS_JSON = "samplers.json"
REFERENCES_DIR = "references"
STATE_VERSION = 2

# Files every complete run writes (the per-scene difference plots are added
# when both strategies have points, the efficiency plots per depth mode).
COMMON_PLOTS = ["rmse_vs_spp.png", "time_vs_spp.png", "rmse_vs_time.png", "efficiency.png"]

STRATEGY_STYLE = {
    "area": {"color": "tab:blue", "label": "area"},
    "solid-angle": {"color": "tab:orange", "label": "solid angle"},
    "projected-solid-angle": {"color": "tab:green", "label": "projected solid angle"},
    "bilinear-solid-angle": {"color": "tab:purple", "label": "bilinear solid angle"},
}

SAMPLER_DESCRIPTIONS = {
    "BM_SampleRectArea": "rectangle, by area",
    "BM_SampleRectSolidAngle": "rectangle, by solid angle (spherical rectangle)",
    "BM_SampleRectSolidAngleExact": "rectangle, by solid angle, exact path only",
    "BM_SampleEllipseArea": "disk/ellipse, by area",
    "BM_SampleEllipseSolidAngle": "disk/ellipse, by solid angle (parallel map, Newton)",
    "BM_SampleEllipseSolidAnglePolar": "disk/ellipse, by solid angle (polar map, Newton)",
    "BM_SampleEllipseSolidAngleBisectionSimpson": "disk/ellipse, by solid angle (parallel map, the seed's bisection + Simpson)",
}

NOT_AVAILABLE_MARKER = "not available in this build"

# For the progress bar's estimate only: the fixed cost of one mcrt process
# (start, scene set-up, image input/output), counted as this many samples of
# work, and rough relative costs per sample (mixture, global depth = 1).
PROCESS_OVERHEAD_SAMPLES = 1_000_000
INTEGRATOR_COST = {"mixture": 1.0, "nee": 1.8, "mis": 1.8}
STRATEGY_COST = {"area": 1.0, "solid-angle": 1.9, "projected-solid-angle": 2.5, "bilinear-solid-angle": 2.2}
DIRECT_COST = 0.55


# --------------------------------------------------------------------- types
@dataclass(frozen=True)
class Config:
    """One configuration of the renderer: light-sampling strategy, integrator, sample generator."""

    strategy: str
    integrator: str
    sampler: str

    @property
    def label(self) -> str:
        """Short name for logs and file names: integrator/sampler/strategy."""
        return f"{self.integrator}/{self.sampler}/{self.strategy}"


# The configuration every other is compared with: the earlier study's area sampling.
BASELINE = Config("area", LEGACY_INTEGRATOR, LEGACY_SAMPLER)


def config_of(row: dict) -> Config:
    """The configuration a CSV row was rendered with."""
    return Config(row["strategy"], row["integrator"], row["sampler"])


@dataclass(frozen=True)
class SceneInfo:
    """A scene of the study: its name, file, content hash, render size and global max depth."""

    name: str
    path: Path
    content_sha256: str
    width: int
    height: int
    max_depth: int  # the global mode's: --max-depth, else the scene's, else mcrt's default

    def depth(self, mode: str) -> int:
        """The max depth passed to mcrt in a depth mode (global or direct)."""
        return DIRECT_MAX_DEPTH if mode == "direct" else self.max_depth

    def depth_modes(self, modes: list[str]) -> list[tuple[str, int]]:
        """(mode, max depth) for the selected modes, without repeating a depth.

        When the global depth is 1 itself, direct is the same render and is
        left out.
        """
        pairs: list[tuple[str, int]] = []
        for mode in modes:
            if all(d != self.depth(mode) for _, d in pairs):
                pairs.append((mode, self.depth(mode)))
        return pairs


@dataclass
class Reference:
    """A cached reference image and how it was made."""

    scene: str
    mode: str
    max_depth: int
    path: Path
    key: str
    strategy: str
    integrator: str
    sampler: str
    spp: int
    seed: int
    seconds: float
    cached: bool


@dataclass
class Failure:
    """A (scene, configuration, max depth) that could not be run, and why."""

    scene: str
    strategy: str
    message: str
    unavailable: bool  # True: "not available in this build" (expected for now)
    integrator: str = LEGACY_INTEGRATOR
    sampler: str = LEGACY_SAMPLER
    max_depth: int | None = None  # None: every depth (failures recorded by the earlier study)


@dataclass
class Settings:
    """Everything a run needs, resolved from the command line."""

    mcrt: Path
    bench: Path | None
    out: Path
    scenes: list[str]
    strategies: list[str]
    integrators: list[str]
    samplers: list[str]
    depths: list[str]
    spp: list[int]
    seeds: list[int]
    ref_spp: int
    ref_seed: int
    ref_strategy: str
    ref_integrator: str
    ref_sampler: str
    ref_key_binary: bool
    width: int | None
    height: int | None
    max_depth: int | None
    threads: int | None
    budgets: list[float] | None
    bench_min_time: float
    bench_repetitions: int
    quick: bool
    fresh: bool
    report_only: bool
    check: bool
    command_line: str
    failures: list[Failure] = field(default_factory=list)

    @property
    def configs(self) -> list[Config]:
        """Every selected configuration, in table order (strategies of one integrator and sampler adjacent)."""
        axes = itertools.product(self.integrators, self.samplers, self.strategies)
        return [Config(s, i, m) for i, m, s in axes]


class McrtError(RuntimeError):
    """An mcrt invocation failed; ``unavailable`` marks a strategy this build lacks."""

    def __init__(self, message: str, returncode: int, unavailable: bool) -> None:
        super().__init__(message)
        self.returncode = returncode
        self.unavailable = unavailable


# ------------------------------------------------------------- command line
def parse_int_list(tokens: list[str]) -> list[int]:
    """Parse integers given as separate tokens, comma lists or A:B[:STEP] ranges (inclusive)."""
    values: list[int] = []
    for token in tokens:
        for part in token.split(","):
            part = part.strip()
            if not part:
                continue
            if ":" in part:
                bits = [int(b) for b in part.split(":")]
                if len(bits) not in (2, 3):
                    raise argparse.ArgumentTypeError(f"bad range {part!r}: use A:B or A:B:STEP")
                start, stop = bits[0], bits[1]
                step = bits[2] if len(bits) == 3 else 1
                if step <= 0:
                    raise argparse.ArgumentTypeError(f"bad range {part!r}: STEP must be positive")
                values.extend(range(start, stop + 1, step))
            else:
                values.append(int(part))
    return values


def build_parser() -> argparse.ArgumentParser:
    """The command-line interface."""
    p = argparse.ArgumentParser(
        prog="study.py",
        description="Error against run time of the renderer's configurations: light-sampling "
        "strategy x integrator x sampler x depth mode (references, RMSE/time sweeps, "
        "tables, plots, report).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="See the docstring at the top of scripts/study.py for details.",
    )
    p.add_argument("--quick", action="store_true",
                   help=f"tiny study: {QUICK_SIZE}x{QUICK_SIZE}, spp {','.join(map(str, QUICK_SPP))}, "
                   f"one seed, integrators {' '.join(QUICK_INTEGRATORS)}, samplers "
                   f"{' '.join(QUICK_SAMPLERS)}, {QUICK_REF_SPP} spp references, output in "
                   "build/study-quick (each of these can still be overridden)")
    p.add_argument("--mcrt", type=Path, default=REPO_ROOT / "build" / "mcrt",
                   help="mcrt executable (default: build/mcrt)")
    p.add_argument("--bench", type=Path, default=None,
                   help="mcrt_bench_samplers executable (default: beside the mcrt executable; "
                   "skipped if missing)")
    p.add_argument("--no-bench", action="store_true", help="do not run the sampler benchmark")
    p.add_argument("--out", type=Path, default=None,
                   help="output directory (default: bench/results, or build/study-quick with --quick)")
    p.add_argument("--scenes", nargs="+", default=None,
                   help="scene names in scenes/ or paths to scene files "
                   f"(default: {' '.join(DEFAULT_SCENES)})")
    p.add_argument("--strategies", nargs="+", choices=STRATEGIES, default=None,
                   help="light-sampling strategies (default: area solid-angle)")
    p.add_argument("--integrators", nargs="+", choices=INTEGRATORS, default=None,
                   help="integrators (default: all three; --quick: "
                   f"{' '.join(QUICK_INTEGRATORS)})")
    p.add_argument("--samplers", nargs="+", choices=SAMPLERS, default=None,
                   help="sample generators (default: all three; --quick: "
                   f"{' '.join(QUICK_SAMPLERS)})")
    p.add_argument("--depths", nargs="+", choices=DEPTH_MODES, default=None,
                   help="light-transport modes: global (the scene's max depth, or --max-depth) "
                   f"and direct (max depth {DIRECT_MAX_DEPTH}: direct lighting only) (default: both)")
    p.add_argument("--spp", nargs="+", default=None,
                   help="samples per pixel of the sweep: values, comma lists or A:B:STEP "
                   f"(default: {' '.join(map(str, DEFAULT_SPP))})")
    p.add_argument("--seeds", nargs="+", default=None,
                   help="seeds of the sweep, each spp is rendered once per seed (default: 1 2 3)")
    p.add_argument("--ref-spp", type=int, default=None,
                   help=f"samples per pixel of the references (default: {DEFAULT_REF_SPP})")
    p.add_argument("--ref-seed", type=int, default=DEFAULT_REF_SEED,
                   help=f"seed of the references, must differ from the sweep's (default: {DEFAULT_REF_SEED})")
    p.add_argument("--ref-strategy", choices=["auto", *STRATEGIES], default="auto",
                   help="strategy of the references; auto: solid-angle when available, else area")
    p.add_argument("--ref-integrator", choices=INTEGRATORS, default=DEFAULT_REF_INTEGRATOR,
                   help=f"integrator of the references (default: {DEFAULT_REF_INTEGRATOR})")
    p.add_argument("--ref-sampler", choices=SAMPLERS, default=DEFAULT_REF_SAMPLER,
                   help=f"sample generator of the references (default: {DEFAULT_REF_SAMPLER})")
    p.add_argument("--ref-key-binary", action="store_true",
                   help="include a hash of the mcrt binary in the reference cache key")
    p.add_argument("--width", type=int, default=None,
                   help=f"image width (default: the scene's x {DEFAULT_SCALE:g}, {QUICK_SIZE} with --quick)")
    p.add_argument("--height", type=int, default=None,
                   help=f"image height (default: the scene's x {DEFAULT_SCALE:g}, {QUICK_SIZE} with --quick)")
    p.add_argument("--max-depth", type=int, default=None,
                   help="path depth of the global mode (default: the scene's)")
    p.add_argument("--threads", type=int, default=None,
                   help="render threads passed to mcrt (default: all hardware threads)")
    p.add_argument("--budgets", nargs="+", type=float, default=None,
                   help="time budgets in seconds for the equal-time tables "
                   "(default: a few per scene and depth mode, spread over the times every "
                   "configuration reached)")
    p.add_argument("--bench-min-time", type=float, default=None,
                   help="--benchmark_min_time in seconds per sampler (default: 0.5, 0.05 with --quick)")
    p.add_argument("--bench-repetitions", type=int, default=None,
                   help="benchmark repetitions, the median is reported (default: 3, 1 with --quick)")
    p.add_argument("--fresh", action="store_true",
                   help="discard the points of previous runs (cached references are kept)")
    p.add_argument("--report-only", action="store_true",
                   help="render nothing: rebuild tables, plots and report from the CSV")
    p.add_argument("--check", action="store_true",
                   help="verify the outputs at the end; exit 1 if a check fails")
    return p


def resolve_settings(args: argparse.Namespace, argv: list[str]) -> Settings:
    """Apply the defaults (full or --quick) to the parsed arguments and validate them."""
    quick = args.quick
    mcrt = args.mcrt.resolve()
    bench: Path | None = None
    if not args.no_bench:
        bench = (args.bench or mcrt.parent / "mcrt_bench_samplers").resolve()
    size = QUICK_SIZE if quick else None
    settings = Settings(
        mcrt=mcrt,
        bench=bench,
        out=(args.out or (QUICK_OUT if quick else DEFAULT_OUT)).resolve(),
        scenes=args.scenes or list(DEFAULT_SCENES),
        strategies=args.strategies or list(DEFAULT_STRATEGIES),
        integrators=args.integrators or list(QUICK_INTEGRATORS if quick else INTEGRATORS),
        samplers=args.samplers or list(QUICK_SAMPLERS if quick else SAMPLERS),
        depths=args.depths or list(DEPTH_MODES),
        spp=parse_int_list(args.spp) if args.spp else list(QUICK_SPP if quick else DEFAULT_SPP),
        seeds=parse_int_list(args.seeds) if args.seeds else list(QUICK_SEEDS if quick else DEFAULT_SEEDS),
        ref_spp=args.ref_spp or (QUICK_REF_SPP if quick else DEFAULT_REF_SPP),
        ref_seed=args.ref_seed,
        ref_strategy=args.ref_strategy,
        ref_integrator=args.ref_integrator,
        ref_sampler=args.ref_sampler,
        ref_key_binary=args.ref_key_binary,
        width=args.width if args.width is not None else size,
        height=args.height if args.height is not None else size,
        max_depth=args.max_depth,
        threads=args.threads,
        budgets=args.budgets,
        bench_min_time=args.bench_min_time if args.bench_min_time is not None else (0.05 if quick else 0.5),
        bench_repetitions=args.bench_repetitions or (1 if quick else 3),
        quick=quick,
        fresh=args.fresh,
        report_only=args.report_only,
        check=args.check,
        command_line=shlex.join([repo_relative(sys.executable), repo_relative(argv[0]), *argv[1:]]),
    )
    # Keep each axis in its canonical order, without repeats.
    settings.strategies = [s for s in STRATEGIES if s in settings.strategies]
    settings.integrators = [s for s in INTEGRATORS if s in settings.integrators]
    settings.samplers = [s for s in SAMPLERS if s in settings.samplers]
    settings.depths = [s for s in DEPTH_MODES if s in settings.depths]
    settings.spp = sorted(set(settings.spp))
    settings.seeds = list(dict.fromkeys(settings.seeds))
    problems = []
    if not settings.spp or min(settings.spp) < 1:
        problems.append("--spp values must be positive")
    if not settings.seeds:
        problems.append("--seeds needs at least one seed")
    if settings.ref_seed in settings.seeds:
        problems.append(f"--ref-seed {settings.ref_seed} must differ from the sweep seeds")
    if settings.ref_spp < 1:
        problems.append("--ref-spp must be positive")
    for name, value in (("--width", settings.width), ("--height", settings.height),
                        ("--threads", settings.threads), ("--max-depth", settings.max_depth)):
        if value is not None and value < 1:
            problems.append(f"{name} must be positive")
    if settings.budgets and min(settings.budgets) <= 0:
        problems.append("--budgets must be positive")
    if not settings.report_only and not (settings.mcrt.is_file() and os.access(settings.mcrt, os.X_OK)):
        problems.append(f"mcrt executable not found: {settings.mcrt} (build it, or pass --mcrt)")
    if problems:
        raise SystemExit("study.py: " + "; ".join(problems))
    return settings


# -------------------------------------------------------------------- utils
def repo_relative(path: str) -> str:
    """A path relative to the repository root when it lies inside it, else as given."""
    try:
        return str(Path(os.path.abspath(path)).relative_to(REPO_ROOT))
    except ValueError:
        return path


def sha256_file(path: Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def sha256_json(obj: object) -> str:
    """Hex SHA-256 of a JSON value (sorted keys), used for cache keys."""
    return hashlib.sha256(json.dumps(obj, sort_keys=True).encode()).hexdigest()


def write_text_atomic(path: Path, text: str) -> None:
    """Write a text file through a temporary name so it is never half-written."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)


def log(message: str) -> None:
    """A message on stderr."""
    print(f"study: {message}", file=sys.stderr, flush=True)


def format_duration(seconds: float) -> str:
    """Seconds as H:MM:SS or M:SS."""
    seconds = max(0, int(round(seconds)))
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class Progress:
    """A plain-text progress bar on stderr, weighted by work (samples).

    On a terminal the bar is redrawn in place; otherwise (logs, ctest) one
    line is printed at most every few seconds and at the end.
    """

    def __init__(self, total_work: float, width: int = 30) -> None:
        self.total = max(total_work, 1e-9)
        self.done = 0.0
        self.width = width
        self.start = time.monotonic()
        self.tty = sys.stderr.isatty()
        self.last_print = 0.0
        self.last_len = 0

    def add_work(self, work: float) -> None:
        """Grow the total (work found on the way, e.g. a reference to render again)."""
        self.total += work

    def advance(self, work: float, label: str) -> None:
        """Count `work` as done and redraw with `label` (the point just finished)."""
        self.done = min(self.total, self.done + work)
        self.draw(label)

    def draw(self, label: str, force: bool = False) -> None:
        """Draw the bar now (on a terminal) or when enough time has passed (elsewhere)."""
        now = time.monotonic()
        frac = self.done / self.total
        elapsed = now - self.start
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        filled = int(round(frac * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        eta_text = format_duration(eta) if math.isfinite(eta) else "?"
        line = f"[{bar}] {frac * 100:5.1f}% elapsed {format_duration(elapsed)} eta {eta_text}  {label}"
        if self.tty:
            pad = " " * max(0, self.last_len - len(line))
            sys.stderr.write("\r" + line + pad)
            sys.stderr.flush()
            self.last_len = len(line)
        elif force or now - self.last_print >= 5.0 or self.done >= self.total:
            print(line, file=sys.stderr, flush=True)
            self.last_print = now

    def message(self, text: str) -> None:
        """Print a line without breaking the bar."""
        if self.tty and self.last_len:
            sys.stderr.write("\r" + " " * self.last_len + "\r")
            self.last_len = 0
        log(text)

    def finish(self) -> None:
        """End the bar's line."""
        if self.tty and self.last_len:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.last_len = 0


# ------------------------------------------------------------------- scenes
def scene_path(spec: str) -> Path:
    """A scene's file from its name (scenes/NAME.json) or path."""
    path = Path(spec)
    return SCENES_DIR / f"{spec}.json" if not path.suffix else path


def scene_file_max_depth(path: Path) -> int:
    """The max depth a scene file asks for (mcrt's default when it gives none)."""
    render = json.loads(path.read_text(encoding="utf-8")).get("render", {})
    return int(render.get("max_depth", MCRT_DEFAULT_MAX_DEPTH))


def load_scene(spec: str, settings: Settings) -> SceneInfo:
    """Find a scene by name or path, and read its size and depth (with the overrides applied)."""
    path = scene_path(spec)
    if not path.is_file():
        raise SystemExit(f"study.py: scene not found: {spec}")
    data = json.loads(path.read_text(encoding="utf-8"))
    camera = data.get("camera", {})
    width = settings.width or int(round(int(camera.get("width", 0)) * DEFAULT_SCALE))
    height = settings.height or int(round(int(camera.get("height", 0)) * DEFAULT_SCALE))
    if width <= 0 or height <= 0:
        raise SystemExit(f"study.py: {path}: no camera width/height; pass --width and --height")
    max_depth = settings.max_depth or scene_file_max_depth(path)
    return SceneInfo(name=path.stem, path=path.resolve(), content_sha256=sha256_file(path),
                     width=width, height=height, max_depth=max_depth)


# --------------------------------------------------------------------- mcrt
def run_mcrt(settings: Settings, args: list[str]) -> subprocess.CompletedProcess:
    """Run mcrt with arguments; raise McrtError with its message on failure."""
    cmd = [str(settings.mcrt), *args]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        message = proc.stderr.strip().splitlines()
        text = message[-1] if message else f"exit status {proc.returncode}"
        unavailable = proc.returncode == 2 and NOT_AVAILABLE_MARKER in proc.stderr
        raise McrtError(text, proc.returncode, unavailable)
    return proc


def render(settings: Settings, scene: SceneInfo, config: Config, max_depth: int, spp: int,
           seed: int, image: Path) -> float:
    """Render one image; return render_seconds from --stats.

    The integrator, sampler and max depth that --stats reports are checked
    against those asked for, so a binary that ignored one cannot go unnoticed.
    """
    stats = image.with_suffix(".stats.json")
    args = ["render", str(scene.path), "-o", str(image), "--spp", str(spp), "--seed", str(seed),
            "--width", str(scene.width), "--height", str(scene.height),
            "--max-depth", str(max_depth), "--light-sampling", config.strategy,
            "--integrator", config.integrator, "--sampler", config.sampler,
            "--stats", str(stats), "--quiet"]
    if settings.threads is not None:
        args += ["--threads", str(settings.threads)]
    run_mcrt(settings, args)
    data = json.loads(stats.read_text(encoding="utf-8"))
    stats.unlink(missing_ok=True)
    for name, asked in (("integrator", config.integrator), ("sampler", config.sampler),
                        ("max_depth", max_depth), ("light_sampling", config.strategy)):
        if name in data and data[name] != asked:
            raise McrtError(f"--stats reports {name} {data[name]!r}, asked for {asked!r}", 0, False)
    return float(data["render_seconds"])


def diff(settings: Settings, image: Path, reference: Path) -> dict[str, float]:
    """Error of an image against a reference (mcrt diff --json)."""
    proc = run_mcrt(settings, ["diff", str(image), str(reference), "--json"])
    data = json.loads(proc.stdout)
    return {k: float(data[k]) for k in ("rmse", "mse", "relmse")}


# --------------------------------------------------------------- references
def reference_strategies(settings: Settings) -> list[str]:
    """The strategies a reference may use, preferred first (auto: solid angle, then area)."""
    return list(REF_STRATEGY_PREFERENCE) if settings.ref_strategy == "auto" else [settings.ref_strategy]


def reference_key(settings: Settings, scene: SceneInfo, max_depth: int, strategy: str,
                  binary_hash: str) -> str:
    """Cache key of a reference: scene content, resolution, spp, depth, seed, strategy,
    integrator and sampler.

    Integrator and sampler enter the key only when they differ from the
    earlier study's (mixture, independent), so that the references it cached
    keep their keys.
    """
    key = {
        "scene_sha256": scene.content_sha256,
        "width": scene.width,
        "height": scene.height,
        "spp": settings.ref_spp,
        "max_depth": max_depth,
        "seed": settings.ref_seed,
        "strategy": strategy,
    }
    if (settings.ref_integrator, settings.ref_sampler) != (LEGACY_INTEGRATOR, LEGACY_SAMPLER):
        key["integrator"] = settings.ref_integrator
        key["sampler"] = settings.ref_sampler
    if settings.ref_key_binary:
        key["mcrt_sha256"] = binary_hash
    return sha256_json(key)[:16]


def find_cached_reference(settings: Settings, scene: SceneInfo, mode: str, binary_hash: str) -> Reference | None:
    """A cached reference for the scene and depth mode, if any matches the current settings.

    With --ref-strategy auto a solid-angle reference is preferred, then area.
    """
    max_depth = scene.depth(mode)
    for strategy in reference_strategies(settings):
        key = reference_key(settings, scene, max_depth, strategy, binary_hash)
        image = settings.out / REFERENCES_DIR / f"{scene.name}-{key}.exr"
        meta = image.with_suffix(".json")
        if image.is_file() and meta.is_file():
            info = json.loads(meta.read_text(encoding="utf-8"))
            return Reference(scene=scene.name, mode=mode, max_depth=max_depth, path=image, key=key,
                             strategy=strategy, integrator=settings.ref_integrator,
                             sampler=settings.ref_sampler, spp=settings.ref_spp, seed=settings.ref_seed,
                             seconds=float(info.get("render_seconds", float("nan"))), cached=True)
    return None


def make_reference(settings: Settings, scene: SceneInfo, mode: str, binary_hash: str,
                   progress: Progress | None) -> Reference:
    """Render (or find in the cache) the reference image of a scene in a depth mode.

    Solid-angle sampling is tried first with --ref-strategy auto; if this
    build lacks it for the scene, area sampling is used and the reason noted.
    """
    max_depth = scene.depth(mode)
    cached = find_cached_reference(settings, scene, mode, binary_hash)
    order = reference_strategies(settings)
    if cached is not None and (cached.strategy == order[0] or settings.report_only):
        return cached
    if settings.report_only:
        raise SystemExit(f"study.py: --report-only: no cached reference for {scene.name} ({mode})")
    refdir = settings.out / REFERENCES_DIR
    refdir.mkdir(parents=True, exist_ok=True)
    last_error: McrtError | None = None
    for strategy in order:
        if cached is not None and cached.strategy == strategy:
            return cached
        key = reference_key(settings, scene, max_depth, strategy, binary_hash)
        image = refdir / f"{scene.name}-{key}.exr"
        config = Config(strategy, settings.ref_integrator, settings.ref_sampler)
        say = progress.message if progress else log
        say(f"reference {scene.name} ({mode}, max depth {max_depth}): {settings.ref_spp} spp, "
            f"{scene.width}x{scene.height}, {config.label}, seed {settings.ref_seed}")
        try:
            seconds = render(settings, scene, config, max_depth, settings.ref_spp, settings.ref_seed, image)
        except McrtError as err:
            last_error = err
            if err.unavailable and strategy != order[-1]:
                say(f"reference {scene.name}: {strategy} unavailable ({err}); falling back")
                continue
            raise
        meta = {
            "scene": scene.name, "scene_file": str(scene.path), "scene_sha256": scene.content_sha256,
            "width": scene.width, "height": scene.height, "spp": settings.ref_spp, "mode": mode,
            "max_depth": max_depth, "seed": settings.ref_seed, "strategy": strategy,
            "integrator": config.integrator, "sampler": config.sampler,
            "render_seconds": seconds, "mcrt": str(settings.mcrt), "mcrt_sha256": binary_hash,
            "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        }
        write_text_atomic(image.with_suffix(".json"), json.dumps(meta, indent=2) + "\n")
        return Reference(scene=scene.name, mode=mode, max_depth=max_depth, path=image, key=key,
                         strategy=strategy, integrator=config.integrator, sampler=config.sampler,
                         spp=settings.ref_spp, seed=settings.ref_seed, seconds=seconds, cached=False)
    assert last_error is not None
    raise last_error


# ---------------------------------------------------------- CSV and state
def row_key(row: dict) -> tuple:
    """What identifies a point: scene, configuration, max depth, spp, seed."""
    return (row["scene"], row["strategy"], row["integrator"], row["sampler"], row["max_depth"],
            row["spp"], row["seed"])


def point_key(scene: str, config: Config, max_depth: int, spp: int, seed: int) -> tuple:
    """row_key of the point not rendered yet."""
    return (scene, config.strategy, config.integrator, config.sampler, max_depth, spp, seed)


def parse_row(r: dict) -> dict:
    """A CSV row with its fields typed."""
    return {"scene": r["scene"], "strategy": r["strategy"], "integrator": r["integrator"],
            "sampler": r["sampler"], "max_depth": int(r["max_depth"]), "spp": int(r["spp"]),
            "seed": int(r["seed"]), "seconds": float(r["seconds"]), "rmse": float(r["rmse"]),
            "mse": float(r["mse"]), "relmse": float(r["relmse"])}


def legacy_max_depths(settings: Settings, state_path: Path) -> Callable[[str], int]:
    """The max depth of the points of an earlier-format CSV, per scene name.

    The earlier study rendered at the scene's max depth (or its --max-depth),
    which its state file recorded; without that record, the scene file's.
    """
    recorded: dict[str, int] = {}
    try:
        raw = json.loads(state_path.read_text(encoding="utf-8"))
        if raw.get("version") == 1:
            recorded = {name: int(s["max_depth"]) for name, s in raw.get("scenes", {}).items()
                        if s.get("max_depth") is not None}
    except (OSError, ValueError, AttributeError):
        pass
    paths = {Path(s).stem: scene_path(s) for s in settings.scenes}

    def depth(name: str) -> int:
        if name in recorded:
            return recorded[name]
        path = paths.get(name, SCENES_DIR / f"{name}.json")
        return scene_file_max_depth(path) if path.is_file() else MCRT_DEFAULT_MAX_DEPTH
    return depth


def read_csv(path: Path, legacy_depth: Callable[[str], int]) -> list[dict]:
    """Rows of the results CSV, typed; [] if there is none.

    A CSV of the earlier format (no integrator, sampler, max_depth) is read as
    integrator mixture, sampler independent, max depth `legacy_depth(scene)`,
    and rewritten in the current format. Any other header is refused.
    """
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        header, raw = reader.fieldnames, list(reader)
    if header == CSV_COLUMNS:
        return [parse_row(r) for r in raw]
    if header == OLD_CSV_COLUMNS:
        rows = [parse_row({**r, "integrator": LEGACY_INTEGRATOR, "sampler": LEGACY_SAMPLER,
                           "max_depth": legacy_depth(r["scene"])}) for r in raw]
        write_csv(path, rows)
        log(f"{path.name}: {len(rows)} rows of the earlier format read as integrator "
            f"{LEGACY_INTEGRATOR}, sampler {LEGACY_SAMPLER}, the scene's max depth; rewritten "
            "with the columns " + ",".join(CSV_COLUMNS))
        return rows
    raise SystemExit(f"study.py: {path} has columns {header}, expected "
                     f"{CSV_COLUMNS}; move it away or pass --fresh")


def write_csv(path: Path, rows: list[dict]) -> None:
    """Write all rows (atomically)."""
    tmp = path.with_name(f".{path.name}.tmp")
    with tmp.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
        writer.writeheader()
        for r in rows:
            writer.writerow(format_row(r))
    tmp.replace(path)


def format_row(row: dict) -> dict:
    """A row with its numbers printed at full useful precision."""
    return {**{k: row[k] for k in ("scene", "strategy", "integrator", "sampler", "max_depth", "spp", "seed")},
            **{k: f"{row[k]:.9g}" for k in ("seconds", "rmse", "mse", "relmse")}}


def append_csv(path: Path, row: dict) -> None:
    """Append one finished point and flush it, so an interrupted run loses nothing."""
    new = not path.is_file()
    with path.open("a", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
        if new:
            writer.writeheader()
        writer.writerow(format_row(row))
        f.flush()
        os.fsync(f.fileno())


def empty_state() -> dict:
    """A state with no runs recorded."""
    return {"version": STATE_VERSION, "runs": {}, "failures": []}


def state_key(scene: str, max_depth: int) -> str:
    """The state file's key of a scene rendered at a max depth."""
    return f"{scene}@max_depth={max_depth}"


def read_state(path: Path) -> dict:
    """The state file (run keys per scene and max depth); an empty one if missing or unreadable.

    A state of the earlier version (one entry per scene, at its max depth,
    references by mixture + independent) is carried over.
    """
    try:
        state = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return empty_state()
    if state.get("version") == STATE_VERSION:
        return state
    if state.get("version") == 1:
        runs = {}
        for name, s in state.get("scenes", {}).items():
            if s.get("max_depth") is None:
                continue  # its run key cannot match any more: the scene's points are run again
            reference = {"integrator": LEGACY_INTEGRATOR, "sampler": LEGACY_SAMPLER, **s["reference"]}
            runs[state_key(name, s["max_depth"])] = {**s, "scene": name, "mode": "global",
                                                     "reference": reference}
        return {"version": STATE_VERSION, "runs": runs, "failures": state.get("failures", [])}
    return empty_state()


def scene_run_key(scene: SceneInfo, max_depth: int, reference: Reference) -> str:
    """What the points of a scene at a max depth depend on: content, resolution, depth, reference.

    The same formula as the earlier study's (whose depth was the scene's), so
    its points stay valid when nothing they depend on changed.
    """
    return sha256_json({"scene_sha256": scene.content_sha256, "width": scene.width,
                        "height": scene.height, "max_depth": max_depth,
                        "reference": reference.key})[:16]


# -------------------------------------------------------------------- sweep
def point_work(scene: SceneInfo, config: Config, max_depth: int, spp: int) -> float:
    """Estimated work of one sweep point, in samples: the render (weighted by rough relative
    costs) plus two mcrt processes."""
    cost = (INTEGRATOR_COST[config.integrator] * STRATEGY_COST[config.strategy]
            * (DIRECT_COST if max_depth == DIRECT_MAX_DEPTH else 1.0))
    return spp * scene.width * scene.height * cost + 2 * PROCESS_OVERHEAD_SAMPLES


def reference_work(settings: Settings, scene: SceneInfo, max_depth: int) -> float:
    """Estimated work of one reference, in samples."""
    config = Config(reference_strategies(settings)[0], settings.ref_integrator, settings.ref_sampler)
    return point_work(scene, config, max_depth, settings.ref_spp) - PROCESS_OVERHEAD_SAMPLES


@dataclass
class Sweep:
    """What a run changes as it goes: the points so far, the CSV, the state file, the progress bar."""

    settings: Settings
    rows: list[dict]
    done: set  # row_key of every point in rows
    csv_path: Path
    state: dict
    state_path: Path
    progress: Progress
    tmpdir: Path
    binary_hash: str

    def save_state(self) -> None:
        """Write the state file."""
        write_text_atomic(self.state_path, json.dumps(self.state, indent=2) + "\n")


def run_study(settings: Settings, scenes: list[SceneInfo]) -> list[dict]:
    """References and sweep for every scene, depth mode and configuration; returns all CSV rows."""
    out = settings.out
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / RESULTS_CSV
    state_path = out / STATE_JSON
    if settings.fresh and csv_path.exists():
        csv_path.unlink()
    rows = read_csv(csv_path, legacy_max_depths(settings, state_path))
    state = empty_state() if settings.fresh else read_state(state_path)
    binary_hash = sha256_file(settings.mcrt) if settings.mcrt.is_file() else ""
    done = {row_key(r) for r in rows}

    # Work left, to size the progress bar, in samples (spp x pixels x rough
    # cost plus a fixed cost per process): the remaining sweep points plus the
    # references not in the cache.
    total = 0.0
    pending_refs = set()
    preferred = reference_strategies(settings)[0]
    for scene in scenes:
        for mode, depth in scene.depth_modes(settings.depths):
            cached = find_cached_reference(settings, scene, mode, binary_hash)
            if cached is None or cached.strategy != preferred:
                total += reference_work(settings, scene, depth)
                pending_refs.add((scene.name, depth))
            total += sum(point_work(scene, config, depth, spp)
                         for config, spp, seed in itertools.product(settings.configs, settings.spp, settings.seeds)
                         if point_key(scene.name, config, depth, spp, seed) not in done)
    progress = Progress(total)
    tmpdir = Path(tempfile.mkdtemp(prefix=".sweep-", dir=out))
    sweep = Sweep(settings, rows, done, csv_path, state, state_path, progress, tmpdir, binary_hash)
    try:
        for scene in scenes:
            references: dict[int, Reference] = {}
            for mode, depth in scene.depth_modes(settings.depths):
                reference = prepare_depth(sweep, scene, mode, (scene.name, depth) in pending_refs)
                if reference is not None:
                    references[depth] = reference
            sweep_scene(sweep, scene, references)
    finally:
        progress.finish()
        shutil.rmtree(tmpdir, ignore_errors=True)
    # Remember what was skipped or failed, for --report-only.
    state["failures"] = [dataclasses.asdict(f) for f in settings.failures]
    sweep.save_state()
    return sweep.rows


def prepare_depth(sweep: Sweep, scene: SceneInfo, mode: str, counted: bool) -> Reference | None:
    """The reference of a scene in a depth mode, with the points already made checked against it.

    When the scene, the resolution, the depth or the reference changed since
    the points of this scene and depth were made, those points are dropped
    (and run again). Returns None, with a failure recorded for every
    configuration, when the reference cannot be rendered. `counted`: the
    reference's work is in the progress bar's total.
    """
    settings, progress = sweep.settings, sweep.progress
    depth = scene.depth(mode)
    work = reference_work(settings, scene, depth)
    try:
        reference = make_reference(settings, scene, mode, sweep.binary_hash, progress)
    except McrtError as err:
        progress.message(f"{scene.name} ({mode}): reference failed: {err}")
        for config in settings.configs:
            settings.failures.append(Failure(scene.name, config.strategy, f"reference: {err}", False,
                                             config.integrator, config.sampler, depth))
        left = sum(point_work(scene, config, depth, spp)
                   for config, spp, seed in itertools.product(settings.configs, settings.spp, settings.seeds)
                   if point_key(scene.name, config, depth, spp, seed) not in sweep.done)
        progress.advance(left + (work if counted else 0.0), f"{scene.name} ({mode}) reference failed")
        return None
    if not reference.cached and not counted:
        progress.add_work(work)
    if not reference.cached or counted:
        progress.advance(work, f"{scene.name} ({mode}) reference ready")

    run_key = scene_run_key(scene, depth, reference)
    key = state_key(scene.name, depth)
    previous = sweep.state["runs"].get(key, {}).get("run_key")
    mine = [r for r in sweep.rows if r["scene"] == scene.name and r["max_depth"] == depth]
    if previous != run_key and mine:
        progress.message(f"{scene.name} ({mode}, max depth {depth}): settings or reference changed "
                         f"since the points in {sweep.csv_path.name} were made; running them again")
        selected = set(settings.configs)
        progress.add_work(sum(point_work(scene, config_of(r), depth, r["spp"]) for r in mine
                              if config_of(r) in selected and r["spp"] in settings.spp
                              and r["seed"] in settings.seeds))
        sweep.rows = [r for r in sweep.rows if not (r["scene"] == scene.name and r["max_depth"] == depth)]
        write_csv(sweep.csv_path, sweep.rows)
        sweep.done = {row_key(r) for r in sweep.rows}
    sweep.state["runs"][key] = {
        "run_key": run_key, "scene": scene.name, "mode": mode, "scene_file": str(scene.path),
        "width": scene.width, "height": scene.height, "max_depth": depth,
        "reference": {"file": os.path.relpath(reference.path, settings.out), "strategy": reference.strategy,
                      "integrator": reference.integrator, "sampler": reference.sampler,
                      "spp": reference.spp, "seed": reference.seed, "render_seconds": reference.seconds},
    }
    sweep.save_state()
    return reference


def sweep_scene(sweep: Sweep, scene: SceneInfo, references: dict[int, Reference]) -> None:
    """The sweep of one scene: every seed, spp, depth mode and configuration not yet in the CSV.

    For each seed and spp, every depth mode and every configuration is
    rendered in turn, the order of the configurations rotated by one from
    each (seed, spp, depth) to the next, so that a change of machine load
    affects all configurations alike and none is always first.
    """
    settings, progress = sweep.settings, sweep.progress
    configs = settings.configs
    dead: dict[tuple[int, Config], McrtError] = {}
    turn = 0
    for seed in settings.seeds:
        for spp in settings.spp:
            for depth, reference in references.items():
                shift = turn % len(configs)
                turn += 1
                for config in configs[shift:] + configs[:shift]:
                    key = point_key(scene.name, config, depth, spp, seed)
                    if key in sweep.done or (depth, config) in dead:
                        continue
                    label = f"{scene.name} {reference.mode} {config.label} spp={spp} seed={seed}"
                    image = sweep.tmpdir / (f"{scene.name}-{depth}-{config.strategy}-{config.integrator}-"
                                            f"{config.sampler}-{spp}-{seed}.exr")
                    try:
                        seconds = render(settings, scene, config, depth, spp, seed, image)
                        errors = diff(settings, image, reference.path)
                    except McrtError as err:
                        dead[(depth, config)] = err
                        kind = "not available in this build, skipped" if err.unavailable else "FAILED"
                        progress.message(f"{scene.name} ({reference.mode}) {config.label}: {kind}: {err}")
                        settings.failures.append(Failure(scene.name, config.strategy, str(err), err.unavailable,
                                                         config.integrator, config.sampler, depth))
                        left = sum(point_work(scene, config, depth, s) for s in settings.spp for sd in settings.seeds
                                   if point_key(scene.name, config, depth, s, sd) not in sweep.done)
                        progress.advance(left, label)
                        continue
                    finally:
                        image.unlink(missing_ok=True)
                    row = {"scene": scene.name, "strategy": config.strategy, "integrator": config.integrator,
                           "sampler": config.sampler, "max_depth": depth, "spp": spp, "seed": seed,
                           "seconds": seconds, **errors}
                    append_csv(sweep.csv_path, row)
                    sweep.rows.append(row)
                    sweep.done.add(key)
                    progress.advance(point_work(scene, config, depth, spp), label)


# ---------------------------------------------------------- sampler costs
def run_sampler_bench(settings: Settings) -> list[dict] | None:
    """Run mcrt_bench_samplers (JSON) and return ns per sample per sampler.

    Returns None when the executable is missing or fails; the raw JSON is
    kept in OUT/samplers.json. With repetitions the median is used.
    """
    raw_path = settings.out / SAMPLERS_JSON
    if settings.bench is None:
        return None
    if settings.report_only:
        data = json.loads(raw_path.read_text(encoding="utf-8")) if raw_path.is_file() else None
        return parse_bench(data) if data else None
    if not settings.bench.is_file():
        log(f"sampler benchmark not found ({settings.bench}); skipped")
        return None
    log(f"sampler benchmark: {settings.bench.name}")
    base = [str(settings.bench), "--benchmark_format=json"]
    if settings.bench_repetitions > 1:
        base += [f"--benchmark_repetitions={settings.bench_repetitions}",
                 "--benchmark_report_aggregates_only=true"]
    # Older Google Benchmark takes a plain number of seconds, newer ones want a unit.
    for min_time in (f"{settings.bench_min_time:g}", f"{settings.bench_min_time:g}s"):
        proc = subprocess.run([*base, f"--benchmark_min_time={min_time}"], capture_output=True, text=True)
        if proc.returncode == 0:
            break
    else:
        log(f"sampler benchmark failed: {proc.stderr.strip().splitlines()[-1:] or proc.returncode}")
        return None
    data = json.loads(proc.stdout)
    write_text_atomic(raw_path, json.dumps(data, indent=2) + "\n")
    return parse_bench(data)


def parse_bench(data: dict) -> list[dict]:
    """ns per sample (CPU and wall clock) per benchmark from Google Benchmark JSON."""
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
    picked: dict[str, dict] = {}
    for b in data.get("benchmarks", []):
        name = b.get("run_name", b["name"])
        is_median = b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median"
        is_plain = b.get("run_type", "iteration") == "iteration"
        if not (is_median or is_plain):
            continue
        if name in picked and not is_median:
            continue
        unit = scale.get(b.get("time_unit", "ns"), 1.0)
        items = b.get("items_per_second")
        iterations_per_item = 1.0
        if items and b.get("cpu_time"):
            # items per iteration = items_per_second * cpu_time_per_iteration
            iterations_per_item = 1.0 / max(items * b["cpu_time"] * unit * 1e-9, 1e-12)
        picked[name] = {
            "name": name,
            "description": SAMPLER_DESCRIPTIONS.get(name, ""),
            "cpu_ns": b["cpu_time"] * unit * iterations_per_item,
            "real_ns": b["real_time"] * unit * iterations_per_item,
        }
    order = list(SAMPLER_DESCRIPTIONS)
    return sorted(picked.values(), key=lambda r: (order.index(r["name"]) if r["name"] in order else 99, r["name"]))


# ------------------------------------------------------------ aggregation
def scene_panels(scenes: list[SceneInfo], settings: Settings) -> list[tuple[str, str, int]]:
    """(scene, depth mode, max depth) of every scene and selected depth mode, depth mode first."""
    pairs = {sc.name: sc.depth_modes(settings.depths) for sc in scenes}
    return [(sc.name, mode, depth) for mode in settings.depths for sc in scenes
            for m, depth in pairs[sc.name] if m == mode]


def select_rows(rows: list[dict], settings: Settings, scenes: list[SceneInfo]) -> list[dict]:
    """The rows of this run's scenes, depth modes, configurations, spp and seeds."""
    depths = {sc.name: {d for _, d in sc.depth_modes(settings.depths)} for sc in scenes}
    configs = set(settings.configs)
    spp, seeds = set(settings.spp), set(settings.seeds)
    return [r for r in rows if r["max_depth"] in depths.get(r["scene"], ()) and config_of(r) in configs
            and r["spp"] in spp and r["seed"] in seeds]


def pick(axis: list[str], preferred: str) -> str:
    """`preferred` if it is among the selected values of an axis, else the first selected."""
    return preferred if preferred in axis else axis[0]


def baseline_config(settings: Settings) -> Config:
    """The configuration the others are compared with: area, mixture, independent (or the first
    selected value of an axis that lacks it)."""
    return Config(pick(settings.strategies, BASELINE.strategy), pick(settings.integrators, BASELINE.integrator),
                  pick(settings.samplers, BASELINE.sampler))


def slice_of(settings: Settings) -> tuple[str, str, str]:
    """(integrator, sampler, depth mode) of the area-vs-solid-angle tables and plots of the
    earlier study: mixture, independent, global (or the first selected value of an axis that
    lacks it)."""
    return (pick(settings.integrators, LEGACY_INTEGRATOR), pick(settings.samplers, LEGACY_SAMPLER),
            pick(settings.depths, "global"))


def slice_rows(rows: list[dict], settings: Settings, scenes: list[SceneInfo]) -> list[dict]:
    """The rows of the earlier study's slice (see slice_of)."""
    integrator, sampler, mode = slice_of(settings)
    depth = {sc.name: sc.depth(mode) for sc in scenes}
    return [r for r in rows if r["integrator"] == integrator and r["sampler"] == sampler
            and r["max_depth"] == depth.get(r["scene"])]


def group_stats(rows: list[dict], **match):
    """Per spp, over the rows whose fields equal `match`: arrays over seeds of seconds, rmse,
    mse, relmse (numpy), sorted by spp."""
    import numpy as np

    by_spp: dict[int, list[dict]] = {}
    for r in rows:
        if all(r[k] == v for k, v in match.items()):
            by_spp.setdefault(r["spp"], []).append(r)
    spps = sorted(by_spp)
    return {
        "spp": np.array(spps, dtype=float),
        "seeds": [sorted(x["seed"] for x in by_spp[s]) for s in spps],
        **{k: [np.array([x[k] for x in sorted(by_spp[s], key=lambda x: x["seed"])]) for s in spps]
           for k in ("seconds", "rmse", "mse", "relmse")},
    }


def loglog_slope(x, y) -> float:
    """Least-squares slope of log y against log x (nan with fewer than two points)."""
    import numpy as np

    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = (x > 0) & (y > 0) & np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 2 or np.ptp(np.log(x[ok])) == 0:
        return float("nan")
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])


def interp_loglog(x_new: float, x, y) -> float:
    """y at x_new by linear interpolation in log-log space (nan outside the data)."""
    import numpy as np

    x, y = np.asarray(x, float), np.asarray(y, float)
    order = np.argsort(x)
    x, y = x[order], y[order]
    if len(x) < 2 or x_new < x[0] or x_new > x[-1]:
        return float("nan")
    return float(np.exp(np.interp(np.log(x_new), np.log(x), np.log(y))))


def mean_curve(stats: dict, key: str):
    """Mean, min and max over seeds of a quantity, per spp."""
    import numpy as np

    vals = stats[key]
    return (np.array([v.mean() for v in vals]), np.array([v.min() for v in vals]),
            np.array([v.max() for v in vals]))


def default_budgets(curves: dict[str, tuple], count: int = 4) -> list[float]:
    """Time budgets spread (log) over the times every strategy reached."""
    import numpy as np

    lo = max(min(t) for t, _ in curves.values())
    hi = min(max(t) for t, _ in curves.values())
    if not (hi > lo > 0):
        return []
    # Stay slightly inside the range so every strategy can be interpolated.
    return [float(v) for v in np.geomspace(lo * 1.0001, hi * 0.9999, count)]


def efficiency_summary(stats: dict) -> dict:
    """Efficiency 1/(MSE·seconds) of every render of one configuration, summarised.

    The summary is the geometric mean over all renders (every spp and seed).
    `rel_se` is the relative standard error of that mean from the noise of
    the renders, not from the trend of efficiency over spp: the spread of log
    efficiency over the seeds of each spp, pooled; with one seed, the scatter
    about a straight line in log spp (three spp values or more).
    """
    import numpy as np

    spps, groups = [], []  # per spp: log efficiency of each seed's render
    for spp, ms, ts in zip(stats["spp"], stats["mse"], stats["seconds"]):
        if len(ms) and np.all(ms > 0) and np.all(ts > 0):
            spps.append(spp)
            groups.append(np.log(1.0 / (ms * ts)))
    if not groups:
        return {"n": 0, "efficiency": float("nan"), "rel_se": float("nan")}
    logs = np.concatenate(groups)
    n = len(logs)
    squares, dof = sum(float(((g - g.mean()) ** 2).sum()) for g in groups), n - len(groups)
    if dof == 0 and len(groups) >= 3:
        x = np.log(np.repeat(spps, [len(g) for g in groups]))
        residuals = np.polyval(np.polyfit(x, logs, 1), x) - logs
        squares, dof = float((residuals ** 2).sum()), n - 2
    se = math.sqrt(squares / dof / n) if dof > 0 else float("nan")
    return {"n": n, "efficiency": float(np.exp(logs.mean())), "rel_se": math.expm1(se)}


def analyse_configs(rows: list[dict], settings: Settings,
                    panels: list[tuple[str, str, int]]) -> dict[tuple[str, int], dict[Config, dict]]:
    """Per (scene, max depth) and configuration with points: its per-spp statistics
    (group_stats), efficiency summary, RMSE slope against spp and ms per spp at the largest spp."""
    analysis: dict[tuple[str, int], dict[Config, dict]] = {}
    for scene, _, depth in panels:
        per: dict[Config, dict] = {}
        for config in settings.configs:
            st = group_stats(rows, scene=scene, max_depth=depth, strategy=config.strategy,
                             integrator=config.integrator, sampler=config.sampler)
            if not len(st["spp"]):
                continue
            per[config] = {
                "stats": st,
                **efficiency_summary(st),
                "slope": loglog_slope(st["spp"], mean_curve(st, "rmse")[0]),
                "ms_per_spp": float(st["seconds"][-1].mean() / st["spp"][-1] * 1e3),
            }
        analysis[(scene, depth)] = per
    return analysis


# ------------------------------------------------------------------ tables
def fmt(value: float, digits: int = 4) -> str:
    """A number for a table: significant digits, '–' for nan."""
    if value is None or not math.isfinite(value):
        return "–"
    return f"{value:.{digits}g}"


def md_table(header: list[str], rows: list[list[str]], text_columns: int = 1) -> str:
    """A markdown table; the first `text_columns` columns are left-aligned, the rest right-aligned."""
    align = ["---" if i < text_columns else "---:" for i in range(len(header))]
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def build_slice_tables(rows: list[dict], settings: Settings, scenes: list[str]) -> tuple[str, dict]:
    """The earlier study's tables (convergence, equal time, sweep: area against solid angle) for
    the rows of its slice, and the numbers the checks use."""
    parts: list[str] = []
    summary: dict = {"slopes": {}, "equal_time": []}

    # Convergence: slopes and efficiency.
    slope_rows = []
    for scene in scenes:
        for strategy in settings.strategies:
            st = group_stats(rows, scene=scene, strategy=strategy)
            if not len(st["spp"]):
                continue
            rmse, _, _ = mean_curve(st, "rmse")
            secs, _, _ = mean_curve(st, "seconds")
            mse, _, _ = mean_curve(st, "mse")
            slope = loglog_slope(st["spp"], rmse)
            summary["slopes"][(scene, strategy)] = slope
            eff = [float((1.0 / (m * s)).mean()) for m, s in zip(st["mse"], st["seconds"])]
            rel = mean_curve(st, "relmse")[0]
            slope_rows.append([scene, strategy, str(len(st["spp"])), fmt(slope, 3),
                               fmt(float(secs[-1] / st["spp"][-1]) * 1e3, 3), fmt(float(rmse[-1])),
                               fmt(float(rel[-1])), fmt(float(sum(eff) / len(eff)), 3)])
    parts.append("### Convergence\n\nRMSE ∝ spp^slope (least squares in log-log over the mean RMSE "
                 "per spp; Monte-Carlo convergence gives −0.5). ms/spp and the errors are at the "
                 "largest spp; efficiency is 1/(MSE·seconds), averaged over the sweep.\n\n")
    parts.append(md_table(["scene", "strategy", "spp values", "slope", "ms per spp", "RMSE (max spp)",
                           "relMSE (max spp)", "mean efficiency"], slope_rows, 2))

    # Equal time.
    et_rows = []
    for scene in scenes:
        curves = {}
        for strategy in settings.strategies:
            st = group_stats(rows, scene=scene, strategy=strategy)
            if len(st["spp"]) >= 2:
                curves[strategy] = (mean_curve(st, "seconds")[0], mean_curve(st, "rmse")[0])
        if len(curves) < 2:
            continue
        budgets = settings.budgets or default_budgets(curves)
        for budget in budgets:
            vals = {s: interp_loglog(budget, t, e) for s, (t, e) in curves.items()}
            a, sa = vals.get("area", float("nan")), vals.get("solid-angle", float("nan"))
            ratio = a / sa if math.isfinite(a) and math.isfinite(sa) and sa > 0 else float("nan")
            summary["equal_time"].append((scene, budget, a, sa, ratio))
            et_rows.append([scene, fmt(budget, 3), fmt(a), fmt(sa), fmt(ratio, 3),
                            fmt(ratio * ratio, 3)])
    parts.append("\n### Equal time\n\nEach strategy's mean RMSE interpolated (log-log) at a render "
                 "time budget. Ratio > 1: solid-angle sampling has the lower error for the same "
                 "time; the MSE ratio is the gain in efficiency.\n\n")
    if et_rows:
        parts.append(md_table(["scene", "time budget (s)", "RMSE area", "RMSE solid angle",
                               "RMSE ratio area/SA", "MSE ratio"], et_rows))
    else:
        parts.append("_Needs both strategies with at least two spp values and overlapping times._\n")

    # Per-scene sweep.
    parts.append("\n### Sweep\n\nMean over seeds of the render time (s) and RMSE per spp; "
                 "ratio = RMSE area / RMSE solid angle at equal spp.\n")
    for scene in scenes:
        stats = {s: group_stats(rows, scene=scene, strategy=s) for s in settings.strategies}
        spps = sorted({int(x) for st in stats.values() for x in st["spp"]})
        if not spps:
            continue
        header = ["spp"]
        for s in settings.strategies:
            header += [f"time {s}", f"RMSE {s}"]
        if len(settings.strategies) == 2:
            header.append("ratio")
        table = []
        for spp in spps:
            line = [str(spp)]
            rm = {}
            for s in settings.strategies:
                st = stats[s]
                idx = [i for i, x in enumerate(st["spp"]) if int(x) == spp]
                if idx:
                    i = idx[0]
                    rm[s] = float(st["rmse"][i].mean())
                    line += [fmt(float(st["seconds"][i].mean()), 3), fmt(rm[s])]
                else:
                    line += ["–", "–"]
            if len(settings.strategies) == 2:
                ok = len(rm) == 2 and rm.get("solid-angle", 0) > 0
                line.append(fmt(rm["area"] / rm["solid-angle"], 3) if ok else "–")
            table.append(line)
        parts.append(f"\n#### {scene}\n\n")
        parts.append(md_table(header, table))

    return "".join(parts), summary


def sampler_cost_table(samplers: list[dict] | None) -> str:
    """The sampler costs of mcrt_bench_samplers as a markdown section."""
    parts = ["\n### Sampler cost\n\n"]
    if samplers:
        parts.append("mcrt_bench_samplers (Google Benchmark): one sample plus its pdf, over observers "
                     "spread around the light; CPU time, and wall-clock time in brackets.\n\n")
        area_ref = {"Rect": None, "Ellipse": None}
        for s in samplers:
            for shape in area_ref:
                if s["name"] == f"BM_Sample{shape}Area":
                    area_ref[shape] = s["cpu_ns"]
        srows = []
        for s in samplers:
            shape = "Rect" if "Rect" in s["name"] else "Ellipse" if "Ellipse" in s["name"] else None
            base = area_ref.get(shape) if shape else None
            srows.append([f"`{s['name']}`", SAMPLER_DESCRIPTIONS.get(s["name"], s["description"]), f"{s['cpu_ns']:.1f} ({s['real_ns']:.1f})",
                          fmt(s["cpu_ns"] / base, 3) if base else "–"])
        parts.append(md_table(["benchmark", "sampler", "ns per sample", "× area sampler"], srows, 2))
    else:
        parts.append("_Not measured (mcrt_bench_samplers not built or --no-bench)._\n")
    return "".join(parts)


def panel_title(scene: str, mode: str, depth: int) -> str:
    """A (scene, depth mode) for headings: 'cornell_rect, global (max depth 50)'."""
    return f"{scene}, {mode} (max depth {depth})"


def config_cells(config: Config) -> list[str]:
    """The integrator, sampler and strategy columns of a configuration's table row."""
    return [config.integrator, config.sampler, config.strategy]


def bold(text: str, on: bool) -> str:
    """Markdown bold when `on`."""
    return f"**{text}**" if on else text


def build_config_tables(analysis: dict, settings: Settings,
                        panels: list[tuple[str, str, int]]) -> tuple[str, dict]:
    """The tables over every configuration: efficiency (overview and per scene and depth mode),
    MSE at equal time, RMSE slopes; and the numbers the checks use."""
    base = baseline_config(settings)
    configs = [c for c in settings.configs if any(c in analysis[(sc, d)] for sc, _, d in panels)]
    summary: dict = {"efficiency": {}, "config_slopes": {}, "best": {}}
    parts: list[str] = []
    if not configs:
        return "### Efficiency by configuration\n\n_No points._\n", summary
    for scene, _, depth in panels:
        per = analysis[(scene, depth)]
        summary["efficiency"][(scene, depth)] = {c: a["efficiency"] for c, a in per.items()}
        for c, a in per.items():
            summary["config_slopes"][(scene, depth, c)] = a["slope"]
        finite = {c: a["efficiency"] for c, a in per.items() if math.isfinite(a["efficiency"])}
        if finite:
            summary["best"][(scene, depth)] = max(finite, key=finite.get)

    def ratio(scene: str, depth: int, config: Config) -> float:
        per = analysis[(scene, depth)]
        if config not in per or base not in per:
            return float("nan")
        return per[config]["efficiency"] / per[base]["efficiency"]

    # Efficiency: overview, then one table per scene and depth mode.
    parts.append(
        "### Efficiency by configuration\n\n"
        "Efficiency = 1/(MSE × seconds) of a render (MSE against the reference, seconds = "
        "`render_seconds`); a configuration's efficiency is the **geometric mean over all its "
        f"renders** (every spp and seed of the sweep: {len(settings.spp)} spp × "
        f"{len(settings.seeds)} seeds), so it weighs every spp alike. Where the MSE falls faster "
        "than 1/spp (see the convergence rates below) efficiency grows with spp, and this is the "
        "efficiency near the geometric middle of the spp list; every configuration has the same "
        "spp list, so the ratios compare them at equal spp. Ratios are to the baseline "
        f"({base.integrator}, {base.sampler}, {base.strategy}) of the same scene and depth mode; "
        "higher is better, the best configuration of each column is in bold. In the tables per "
        "scene, ± s.e. is the standard error of the geometric mean from the spread of the renders "
        "over seeds at equal spp (machine-speed and Monte-Carlo noise, not the trend over spp); "
        "ms per spp is at the largest spp.\n\n")
    header = ["integrator", "sampler", "strategy"]
    header += [f"{scene} {mode}" for scene, mode, _ in panels]
    table = []
    for c in configs:
        line = config_cells(c)
        for scene, _, depth in panels:
            line.append(bold(fmt(ratio(scene, depth, c), 3), summary["best"].get((scene, depth)) == c))
        table.append(line)
    parts.append(md_table(header, table, 3))
    for scene, mode, depth in panels:
        per = analysis[(scene, depth)]
        parts.append(f"\n#### {panel_title(scene, mode, depth)}\n\n")
        if not per:
            parts.append("_No points._\n")
            continue
        table = []
        for c in configs:
            if c not in per:
                continue
            a = per[c]
            best = summary["best"].get((scene, depth)) == c
            table.append([*config_cells(c), str(a["n"]), bold(fmt(a["efficiency"], 4), best),
                          f"±{fmt(100 * a['rel_se'], 2)} %", bold(fmt(ratio(scene, depth, c), 3), best),
                          fmt(a["ms_per_spp"], 3), "★ best" if best else ""])
        parts.append(md_table(["integrator", "sampler", "strategy", "renders", "efficiency",
                               "± s.e.", "× baseline", "ms per spp", ""], table, 3))

    # Equal time.
    parts.append(
        "\n### Equal time by configuration\n\n"
        "Mean MSE over seeds of each configuration, interpolated (log-log, in render time) at a "
        "few time budgets per scene and depth mode, spread over the times every configuration "
        "reached (– outside a configuration's range); the lowest MSE of each budget in bold. "
        "Last column: baseline MSE / MSE, geometric mean over the budgets (> 1: better than the "
        "baseline at equal time).\n")
    for scene, mode, depth in panels:
        per = analysis[(scene, depth)]
        curves = {c: (mean_curve(a["stats"], "seconds")[0], mean_curve(a["stats"], "mse")[0])
                  for c, a in per.items() if len(a["stats"]["spp"]) >= 2}
        if not curves:
            continue
        budgets = settings.budgets or default_budgets(curves, 3)
        if not budgets and base in curves:  # no time common to all: the baseline's range
            budgets = default_budgets({base: curves[base]}, 3)
        if not budgets:
            continue
        mse = {c: [interp_loglog(b, t, e) for b in budgets] for c, (t, e) in curves.items()}
        lowest = [min((m[i] for m in mse.values() if math.isfinite(m[i])), default=float("nan"))
                  for i in range(len(budgets))]
        table = []
        for c in configs:
            if c not in mse:
                continue
            gains = [mse[base][i] / m for i, m in enumerate(mse[c])
                     if base in mse and math.isfinite(m) and math.isfinite(mse[base][i]) and m > 0]
            gain = math.exp(sum(map(math.log, gains)) / len(gains)) if gains else float("nan")
            table.append([*config_cells(c), *[bold(fmt(m, 4), m == lowest[i]) for i, m in enumerate(mse[c])],
                          fmt(gain, 3)])
        parts.append(f"\n#### {panel_title(scene, mode, depth)}\n\n")
        parts.append(md_table(["integrator", "sampler", "strategy",
                               *[f"MSE at {fmt(b, 3)} s" for b in budgets], "baseline MSE / MSE"], table, 3))

    # Convergence rates.
    parts.append(
        "\n### Convergence rate by configuration\n\n"
        "Log-log slope of the mean RMSE (over seeds) against spp, least squares. Monte-Carlo "
        "noise alone gives −0.5; a stratified or quasi-Monte-Carlo sampler can do better (steeper) "
        "where the integrand is smooth, as in direct lighting, and tends to −0.5 when long paths "
        "make the integrand high-dimensional. The image error also holds the pixel-footprint "
        "(antialiasing) error, which falls faster than Monte-Carlo noise when the pixel positions "
        "are stratified, so even the independent sampler can show slopes below −0.5, more so at "
        "low resolution and where the lighting noise is small (direct lighting, NEE): compare a "
        "sampler's slope with the independent sampler's of the same integrator, strategy and "
        "mode.\n\n")
    table = []
    for c in configs:
        table.append([*config_cells(c), *[fmt(analysis[(sc, d)][c]["slope"], 3) if c in analysis[(sc, d)]
                                          else "–" for sc, _, d in panels]])
    parts.append(md_table(["integrator", "sampler", "strategy", *[f"{sc} {m}" for sc, m, _ in panels]],
                          table, 3))
    return "".join(parts), summary


def build_tables(rows: list[dict], settings: Settings, scenes: list[SceneInfo],
                 samplers: list[dict] | None) -> tuple[str, dict, dict]:
    """All markdown tables of the report; the numbers the checks use; the per-configuration
    analysis (for the plots)."""
    panels = scene_panels(scenes, settings)
    analysis = analyse_configs(rows, settings, panels)
    config_text, summary = build_config_tables(analysis, settings, panels)
    integrator, sampler, mode = slice_of(settings)
    slice_text, slice_summary = build_slice_tables(slice_rows(rows, settings, scenes), settings,
                                                   [sc.name for sc in scenes])
    summary.update(slice_summary)
    intro = (f"\n## Area against solid angle: {integrator}, {sampler}, {mode} depth\n\n"
             "The tables of the earlier, single-configuration study, for the slice integrator "
             f"{integrator}, sampler {sampler}, {mode} depth mode.\n\n")
    text = config_text + intro + slice_text + sampler_cost_table(samplers)
    return text, summary, analysis


# ------------------------------------------------------------------- plots
def make_slice_plots(rows: list[dict], settings: Settings, scenes: list[str]) -> list[tuple[str, str]]:
    """Write the earlier study's PNG figures (area against solid angle) for the rows of its slice;
    return (file name, caption) pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker as ticker
    import numpy as np

    out = settings.out
    figures: list[tuple[str, str]] = []
    integrator, sampler, mode = slice_of(settings)
    slice_note = f"({integrator}, {sampler}, {mode} depth.)"
    stats = {(sc, s): group_stats(rows, scene=sc, strategy=s) for sc in scenes for s in settings.strategies}
    scenes = [sc for sc in scenes if any(len(stats[(sc, s)]["spp"]) for s in settings.strategies)]
    if not scenes:
        return figures

    def grid(title: str):
        n = len(scenes)
        cols = 2 if n > 1 else 1
        rows_ = (n + cols - 1) // cols
        fig, axes = plt.subplots(rows_, cols, figsize=(6 * cols, 4.2 * rows_), squeeze=False)
        for ax in axes.flat[n:]:
            ax.set_visible(False)
        fig.suptitle(title)
        return fig, list(axes.flat[:n])

    def save(fig, name: str, caption: str) -> None:
        fig.tight_layout()
        fig.savefig(out / name, dpi=110)
        plt.close(fig)
        figures.append((name, f"{caption} {slice_note}"))

    def log_axes(ax) -> None:
        """Log-log axes labelled at 1, 2, 5 x 10^k in plain numbers."""
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(ticker.NullFormatter())

    def band_plot(ax, x, key_or_values, strategy, marker="o"):
        mean, lo, hi = key_or_values
        style = STRATEGY_STYLE[strategy]
        ax.plot(x, mean, marker=marker, ms=3, color=style["color"], label=style["label"])
        ax.fill_between(x, lo, hi, color=style["color"], alpha=0.2, linewidth=0)

    # RMSE vs spp, time vs spp, efficiency vs spp.
    for name, key, ylabel, title, caption in [
        ("rmse_vs_spp.png", "rmse", "RMSE", "RMSE against samples per pixel",
         "RMSE against spp (log-log; mean over seeds, band: min–max)."),
        ("time_vs_spp.png", "seconds", "render time (s)", "Render time against samples per pixel",
         "Render time against spp (log-log; mean over seeds, band: min–max)."),
    ]:
        fig, axes = grid(title)
        for ax, sc in zip(axes, scenes):
            for s in settings.strategies:
                st = stats[(sc, s)]
                if len(st["spp"]):
                    band_plot(ax, st["spp"], mean_curve(st, key), s)
            if key == "rmse":
                st0 = next((stats[(sc, s)] for s in settings.strategies if len(stats[(sc, s)]["spp"])), None)
                if st0 is not None:
                    r0 = mean_curve(st0, "rmse")[0][0]
                    ref_x = st0["spp"]
                    ax.plot(ref_x, r0 * np.sqrt(ref_x[0] / ref_x), "k:", lw=1, label="∝ spp^-1/2")
            log_axes(ax)
            ax.set_title(sc)
            ax.set_xlabel("samples per pixel")
            ax.set_ylabel(ylabel)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
        save(fig, name, caption)

    fig, axes = grid("RMSE against render time")
    for ax, sc in zip(axes, scenes):
        for s in settings.strategies:
            st = stats[(sc, s)]
            if not len(st["spp"]):
                continue
            t = mean_curve(st, "seconds")[0]
            band_plot(ax, t, mean_curve(st, "rmse"), s)
            ax.scatter(np.concatenate(st["seconds"]), np.concatenate(st["rmse"]), s=4,
                       color=STRATEGY_STYLE[s]["color"], alpha=0.35)
        log_axes(ax)
        ax.set_title(sc)
        ax.set_xlabel("render time (s)")
        ax.set_ylabel("RMSE")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, "rmse_vs_time.png",
         "RMSE against render time (log-log; line: mean over seeds per spp, band: min–max RMSE, "
         "dots: single renders). Lower-left is better.")

    fig, axes = grid("Efficiency 1 / (MSE · time)")
    for ax, sc in zip(axes, scenes):
        for s in settings.strategies:
            st = stats[(sc, s)]
            if not len(st["spp"]):
                continue
            eff = [1.0 / (m * t) for m, t in zip(st["mse"], st["seconds"])]
            band_plot(ax, st["spp"], (np.array([e.mean() for e in eff]), np.array([e.min() for e in eff]),
                                      np.array([e.max() for e in eff])), s)
        log_axes(ax)
        ax.set_title(sc)
        ax.set_xlabel("samples per pixel")
        ax.set_ylabel("1 / (MSE · s)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, "efficiency.png",
         "Efficiency 1/(MSE·time) against spp (mean over seeds, band: min–max). Higher is better; "
         "it should be roughly flat in spp.")

    # RMSE difference per scene (the seed's figures 4.2, 4.3, 4.5 and 4.6).
    if {"area", "solid-angle"} <= set(settings.strategies):
        for sc in scenes:
            a, sa = stats[(sc, "area")], stats[(sc, "solid-angle")]
            common = sorted(set(a["spp"].tolist()) & set(sa["spp"].tolist()))
            if not common:
                continue
            mean, lo, hi = [], [], []
            for spp in common:
                i = a["spp"].tolist().index(spp)
                j = sa["spp"].tolist().index(spp)
                seeds = sorted(set(a["seeds"][i]) & set(sa["seeds"][j]))
                da = dict(zip(a["seeds"][i], a["rmse"][i]))
                dsa = dict(zip(sa["seeds"][j], sa["rmse"][j]))
                d = np.array([da[s] - dsa[s] for s in seeds])
                mean.append(d.mean())
                lo.append(d.min())
                hi.append(d.max())
            fig, ax = plt.subplots(figsize=(6.5, 4.2))
            ax.axhline(0.0, color="k", lw=0.8)
            ax.plot(common, mean, marker="o", ms=3, color="tab:green", label="mean over seeds")
            ax.fill_between(common, lo, hi, color="tab:green", alpha=0.2, linewidth=0, label="min–max")
            ax.set_title(f"RMSE(area) − RMSE(solid angle): {sc}")
            ax.set_xlabel("samples per pixel")
            ax.set_ylabel("RMSE difference")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
            save(fig, f"rmse_diff_{sc}.png",
                 f"{sc}: RMSE of area sampling minus RMSE of solid-angle sampling at equal spp "
                 "(paired by seed). Above zero: solid angle has the lower error.")
    return figures


def make_efficiency_plots(analysis: dict, settings: Settings,
                          panels: list[tuple[str, str, int]]) -> list[tuple[str, str]]:
    """One figure per depth mode: per scene, the efficiency of every configuration as grouped
    bars (groups: integrator and sampler; bars: strategy; log scale; whiskers: ± one standard
    error). Returns (file name, caption) pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    figures: list[tuple[str, str]] = []
    base = baseline_config(settings)
    groups = [(i, m) for i in settings.integrators for m in settings.samplers]
    width = 0.8 / len(settings.strategies)
    for mode in settings.depths:
        mine = [(sc, d) for sc, m, d in panels if m == mode and analysis[(sc, d)]]
        if not mine:
            continue
        cols = 2 if len(mine) > 1 else 1
        nrows = (len(mine) + cols - 1) // cols
        panel_width = max(6.0, 0.5 * len(groups) * len(settings.strategies) + 2)
        fig, axes = plt.subplots(nrows, cols, figsize=(panel_width * cols, 4.4 * nrows), squeeze=False)
        for ax in axes.flat[len(mine):]:
            ax.set_visible(False)
        for ax, (scene, depth) in zip(axes.flat, mine):
            per = analysis[(scene, depth)]
            best = max((c for c in per if math.isfinite(per[c]["efficiency"])),
                       key=lambda c: per[c]["efficiency"], default=None)
            for k, strategy in enumerate(settings.strategies):
                xs, ys, lo, hi = [], [], [], []
                for g, (integrator, sampler) in enumerate(groups):
                    a = per.get(Config(strategy, integrator, sampler))
                    if a is None or not math.isfinite(a["efficiency"]):
                        continue
                    xs.append(g + (k - (len(settings.strategies) - 1) / 2) * width)
                    ys.append(a["efficiency"])
                    se = a["rel_se"] if math.isfinite(a["rel_se"]) else 0.0
                    lo.append(a["efficiency"] * se / (1 + se))
                    hi.append(a["efficiency"] * se)
                    if Config(strategy, integrator, sampler) == best:
                        ax.annotate("★", (xs[-1], a["efficiency"] * (1 + se)), ha="center", va="bottom",
                                    fontsize=12)
                style = STRATEGY_STYLE[strategy]
                ax.bar(xs, ys, width * 0.95, color=style["color"], label=style["label"],
                       yerr=np.array([lo, hi]), capsize=2, error_kw={"lw": 0.8})
            if base in per:
                ax.axhline(per[base]["efficiency"], color="k", ls="--", lw=0.8,
                           label=f"baseline ({base.integrator}, {base.sampler}, {base.strategy})")
            ax.set_yscale("log")
            ax.set_xticks(range(len(groups)))
            ax.set_xticklabels([f"{i}\n{m}" for i, m in groups], fontsize=8)
            ax.set_title(f"{scene} (max depth {depth})")
            ax.set_ylabel("efficiency 1 / (MSE · s)")
            ax.grid(True, axis="y", which="both", alpha=0.3)
            ax.legend(fontsize=7)
        fig.suptitle(f"Efficiency per configuration, {mode} {'illumination' if mode == 'global' else 'lighting'}")
        fig.tight_layout()
        name = f"efficiency_{mode}.png"
        fig.savefig(settings.out / name, dpi=110)
        plt.close(fig)
        figures.append((name, f"Efficiency 1/(MSE·time) of every configuration, {mode} depth mode: "
                              "geometric mean over spp and seeds (bars, log scale), ± one standard "
                              "error (whiskers, from the spread over seeds), the baseline (dashed) and the "
                              "best configuration (★). Higher is better."))
    return figures


# ------------------------------------------------------------------ report
def machine_info() -> dict[str, str]:
    """CPU model, core count, OS, and the repository's git commit."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.lower().startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    commit = "unknown"
    try:
        head = subprocess.run(["git", "-C", str(REPO_ROOT), "rev-parse", "HEAD"],
                              capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(REPO_ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
        commit = head + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        pass
    return {"cpu": cpu, "cores": str(os.cpu_count() or "?"),
            "os": f"{platform.system()} {platform.release()}", "commit": commit,
            "python": platform.python_version()}


def failure_lines(failures: list[Failure]) -> list[str]:
    """The report's lines for skipped or failed configurations, one per scene, strategy and reason."""
    grouped: dict[tuple, list[str]] = {}
    for f in failures:
        where = f"{f.integrator}/{f.sampler}" + (f" at max depth {f.max_depth}" if f.max_depth is not None else "")
        grouped.setdefault((f.scene, f.strategy, f.unavailable, f.message), []).append(where)
    lines = []
    for (scene, strategy, unavailable, message), where in grouped.items():
        kind = "not available in this mcrt build, skipped" if unavailable else "**failed**"
        lines.append(f"- {scene}, {strategy} ({'; '.join(dict.fromkeys(where))}): {kind} — `{message}`")
    return lines


def write_report(settings: Settings, scenes: list[SceneInfo], tables: str,
                 figures: list[tuple[str, str]], started: datetime.datetime) -> None:
    """Write tables.md and the report README.md (relative links to the plots)."""
    out = settings.out
    write_text_atomic(out / TABLES_MD, tables)
    info = machine_info()
    state = read_state(out / STATE_JSON)
    mcrt_hash = sha256_file(settings.mcrt)[:12] if settings.mcrt.is_file() else "?"
    threads = str(settings.threads) if settings.threads else f"all ({info['cores']})"
    base = baseline_config(settings)
    modes = {"global": "global (the scene's max depth" + (", --max-depth" if settings.max_depth else "") + ")",
             "direct": f"direct (max depth {DIRECT_MAX_DEPTH}: direct lighting only)"}

    lines = [
        "# Error against run time: light sampling, integrators and samplers\n",
        f"Generated by `scripts/study.py` on {started.strftime('%Y-%m-%d %H:%M UTC')}"
        + (" (**--quick**: a smoke test, not a measurement)" if settings.quick else "") + ".\n",
        "## Setup\n",
        f"- Command: `{settings.command_line}`",
        f"- Commit: `{info['commit']}`",
        f"- Machine: {info['cpu']}, {info['cores']} cores, {info['os']}; render threads: {threads}",
        f"- mcrt: `{repo_relative(str(settings.mcrt))}` (sha256 {mcrt_hash}…)",
        f"- Scenes: {', '.join(sc.name for sc in scenes)}",
        f"- Configurations ({len(settings.configs)}): integrators {', '.join(settings.integrators)}; "
        f"samplers {', '.join(settings.samplers)}; strategies {', '.join(settings.strategies)}; "
        f"in the depth modes {' and '.join(modes[m] for m in settings.depths)}",
        f"- Sweep: spp {', '.join(map(str, settings.spp))}; seeds {', '.join(map(str, settings.seeds))}; "
        "for each seed and spp every depth mode and configuration in turn",
        "- Time: `render_seconds` of `mcrt render --stats` (rendering only: no process start, "
        "no scene parsing, no image output). Error: `mcrt diff --json` against the reference "
        "(relMSE as in pbrt: mean of (v−r)²/(r+0.01)²).",
        "- Efficiency: 1/(MSE × seconds) of each render; a configuration's is the geometric mean "
        "over its renders (every spp and seed), compared with the baseline "
        f"({base.integrator}, {base.sampler}, {base.strategy}) of the same scene and depth mode.",
        f"- Data: [{RESULTS_CSV}]({RESULTS_CSV}) (one row per render), tables also in [{TABLES_MD}]({TABLES_MD}).\n",
        "### References\n",
        "One reference per scene and depth mode with a seed the sweep does not use, shared by "
        "every configuration (all converge to the same image); the table gives the configuration "
        f"each was rendered with (this run's choice: integrator {settings.ref_integrator}, sampler "
        f"{settings.ref_sampler}, "
        + ("solid-angle sampling where this mcrt build supports it, else area sampling"
           if settings.ref_strategy == "auto" else f"{settings.ref_strategy} sampling")
        + "). Cached by scene content, resolution, spp, max depth, seed, strategy, integrator and sampler.\n",
    ]
    ref_rows = []
    for scene, mode, depth in scene_panels(scenes, settings):
        s = state.get("runs", {}).get(state_key(scene, depth))
        if s:
            ref = s["reference"]
            ref_rows.append([scene, mode, ref.get("integrator", LEGACY_INTEGRATOR),
                             ref.get("sampler", LEGACY_SAMPLER), ref["strategy"], f"{s['width']}×{s['height']}",
                             str(depth), str(ref["spp"]), str(ref["seed"]),
                             fmt(ref.get("render_seconds", float("nan")), 4)])
    if ref_rows:
        lines.append(md_table(["scene", "mode", "integrator", "sampler", "strategy", "resolution", "max depth",
                               "spp", "seed", "render time (s)"], ref_rows, 5))
    if settings.failures:
        lines.append("### Skipped or failed\n")
        lines += failure_lines(settings.failures)
        lines.append("")
    lines.append("## Results\n")
    lines.append(tables)
    if figures:
        lines.append("\n## Plots\n")
        for name, caption in figures:
            lines.append(f"![{name}]({name})\n\n{caption}\n")
    write_text_atomic(out / REPORT_MD, "\n".join(lines) + "\n")


# ------------------------------------------------------------------ checks
REQUIRED_HEADINGS = ["### Efficiency by configuration", "### Equal time by configuration",
                     "### Convergence rate by configuration", "### Convergence", "### Equal time", "### Sweep"]


def run_checks(settings: Settings, rows: list[dict], scenes: list[SceneInfo], summary: dict,
               figures: list[tuple[str, str]]) -> bool:
    """Verify the outputs; print one line per check and a closing count. True if all pass."""
    out = settings.out
    results: list[tuple[bool, str]] = []
    panels = scene_panels(scenes, settings)

    def check(ok: bool, what: str) -> None:
        results.append((bool(ok), what))
        print(f"{'PASS' if ok else 'FAIL'}: {what}", flush=True)

    def text(name: str) -> str:
        return (out / name).read_text(encoding="utf-8") if (out / name).is_file() else ""

    plots = [*COMMON_PLOTS, *(f"efficiency_{m}.png" for m in dict.fromkeys(m for _, m, _ in panels))]
    for name in dict.fromkeys([RESULTS_CSV, TABLES_MD, REPORT_MD, *plots, *(n for n, _ in figures)]):
        path = out / name
        check(path.is_file() and path.stat().st_size > 0, f"{name} exists and is not empty")
    for name, _ in figures:
        path = out / name
        check(path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{name} is a PNG")
    header = []
    if (out / RESULTS_CSV).is_file():
        with (out / RESULTS_CSV).open(newline="", encoding="utf-8") as f:
            header = next(csv.reader(f), [])
    check(header == CSV_COLUMNS, f"CSV columns are {','.join(CSV_COLUMNS)}")
    report, tables = text(REPORT_MD), text(TABLES_MD)
    for heading in REQUIRED_HEADINGS:
        check(f"\n{heading}\n" in f"\n{tables}" and f"\n{heading}\n" in report,
              f"tables.md and the report have the table '{heading[4:]}'")
    check(all(f"#### {panel_title(*p)}\n" in tables for p in panels),
          "the efficiency and equal-time tables cover every scene and depth mode")
    check(all(f"({n})" in report for n in plots), "report embeds the plots")
    check(not [f for f in settings.failures if not f.unavailable],
          "no mcrt failure other than 'not available in this build'")
    finite = all(math.isfinite(r[k]) and r[k] >= 0 for r in rows for k in ("rmse", "mse", "relmse"))
    check(finite and all(r["seconds"] > 0 for r in rows), "errors finite and non-negative, times positive")
    unavailable = {(f.scene, Config(f.strategy, f.integrator, f.sampler), f.max_depth)
                   for f in settings.failures if f.unavailable}
    expected = len(settings.spp) * len(settings.seeds)
    for scene, mode, depth in panels:
        where = f"{scene} {mode}"
        counts = {c: 0 for c in settings.configs}
        for r in rows:
            if r["scene"] == scene and r["max_depth"] == depth:
                counts[config_of(r)] += 1
        skipped = {c for c in settings.configs
                   if (scene, c, depth) in unavailable or (scene, c, None) in unavailable}
        wrong = [f"{c.label}: {n}" for c, n in counts.items() if n != (0 if c in skipped else expected)]
        check(not wrong, f"{where}: every configuration has its {expected} points"
              + (f" ({len(skipped)} not available in this build, none)" if skipped else "")
              + (f"; wrong counts: {', '.join(wrong)}" if wrong else ""))
        run = [c for c in settings.configs if c not in skipped]
        if len(settings.spp) >= 2:
            slopes = {c: summary["config_slopes"].get((scene, depth, c), float("nan")) for c in run}
            bad = [f"{c.label} {s:.3f}" for c, s in slopes.items() if not (math.isfinite(s) and s < 0)]
            finite_slopes = [s for s in slopes.values() if math.isfinite(s)]
            span = f"{min(finite_slopes):.3f} … {max(finite_slopes):.3f}" if finite_slopes else "none"
            check(not bad, f"{where}: RMSE decreases with spp for every configuration (log-log slopes "
                  f"{span})" + (f"; not decreasing: {', '.join(bad)}" if bad else ""))
        effs = summary["efficiency"].get((scene, depth), {})
        missing = [c.label for c in run if not (math.isfinite(effs.get(c, float("nan"))) and effs[c] > 0)]
        check(not run or (not missing and (scene, depth) in summary["best"]),
              f"{where}: efficiency table has every configuration and a best one"
              + (f"; missing: {', '.join(missing)}" if missing else ""))
    passed = sum(ok for ok, _ in results)
    failed = len(results) - passed
    print(f"study check: {passed} passed, {failed} failed", flush=True)
    return failed == 0


# -------------------------------------------------------------------- main
def report_only_inputs(settings: Settings, scenes: list[SceneInfo], spp_given: bool,
                       seeds_given: bool) -> list[dict]:
    """For --report-only: the CSV's rows and the failures recorded in the state file.

    Without --spp or --seeds, the report covers the spp values and seeds the
    CSV holds for the selected scenes (so an earlier run's report can be
    rebuilt without repeating its sweep options).
    """
    settings.out.mkdir(parents=True, exist_ok=True)
    state_path = settings.out / STATE_JSON
    rows = read_csv(settings.out / RESULTS_CSV, legacy_max_depths(settings, state_path))
    names = {sc.name for sc in scenes}
    mine = [r for r in rows if r["scene"] in names]
    if mine and not spp_given:
        settings.spp = sorted({r["spp"] for r in mine})
    if mine and not seeds_given:
        settings.seeds = sorted({r["seed"] for r in mine})
    depths = {sc.name: {d for _, d in sc.depth_modes(settings.depths)} for sc in scenes}
    configs = set(settings.configs)
    failures = [Failure(**f) for f in read_state(state_path).get("failures", [])]
    settings.failures = [f for f in failures if f.scene in names
                         and Config(f.strategy, f.integrator, f.sampler) in configs
                         and (f.max_depth is None or f.max_depth in depths[f.scene])]
    return rows


def main(argv: list[str] | None = None) -> int:
    """Run the study (or rebuild its report); 0 on success, 1 on failure."""
    argv = sys.argv if argv is None else argv
    # Stop cleanly (temporary images removed, finished points kept) on SIGTERM too.
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    args = build_parser().parse_args(argv[1:])
    settings = resolve_settings(args, argv)
    started = datetime.datetime.now(datetime.timezone.utc)
    t0 = time.monotonic()
    log(f"output: {settings.out}")
    scenes = [load_scene(s, settings) for s in settings.scenes]
    if settings.report_only:
        rows = report_only_inputs(settings, scenes, args.spp is not None, args.seeds is not None)
    else:
        rows = run_study(settings, scenes)
    samplers = run_sampler_bench(settings)
    selected = select_rows(rows, settings, scenes)
    tables, summary, analysis = build_tables(selected, settings, scenes, samplers)
    figures = make_efficiency_plots(analysis, settings, scene_panels(scenes, settings))
    figures += make_slice_plots(slice_rows(selected, settings, scenes), settings, [sc.name for sc in scenes])
    write_report(settings, scenes, tables, figures, started)
    log(f"done in {format_duration(time.monotonic() - t0)}: {settings.out / REPORT_MD}")
    ok = not [f for f in settings.failures if not f.unavailable]
    if settings.check:
        ok = run_checks(settings, selected, scenes, summary, figures) and ok
    return 0 if ok else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print("\nstudy: interrupted; the points finished so far are in the CSV, "
              "run the same command again to resume", file=sys.stderr)
        sys.exit(130)
