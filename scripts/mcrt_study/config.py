"""Constants, the study's types (configurations, scenes, references, failures, settings) and the command line."""

from __future__ import annotations

import argparse
import datetime
import itertools
import os
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable


# This file is scripts/mcrt_study/config.py.
REPO_ROOT = Path(__file__).resolve().parent.parent.parent
SCENES_DIR = REPO_ROOT / "scenes"

CSV_COLUMNS = ["scene", "strategy", "integrator", "sampler", "max_depth", "spp", "seed",
               "seconds", "rmse", "mse", "relmse", "family", "family_param", "light_solid_angle",
               "light_select"]
# The CSV before the light-selection column (every row: DEFAULT_LIGHT_SELECT): read, then
# rewritten as CSV_COLUMNS.
PRE_SELECT_CSV_COLUMNS = CSV_COLUMNS[:14]
# The CSV before the scene-family columns: read, then rewritten as CSV_COLUMNS.
PRE_FAMILY_CSV_COLUMNS = CSV_COLUMNS[:11]
# The CSV of the earlier, single-integrator study: read, then rewritten as CSV_COLUMNS.
OLD_CSV_COLUMNS = ["scene", "strategy", "spp", "seed", "seconds", "rmse", "mse", "relmse"]
STRATEGIES = ["area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "pbrt", "auto"]
# The default sweep (the committed report); the others by --strategies.
DEFAULT_STRATEGIES = ["area", "solid-angle"]
# References with --ref-strategy preferred: the first this mcrt has for the scene.
REF_STRATEGY_PREFERENCE = ["solid-angle", "area"]
INTEGRATORS = ["mixture", "nee", "mis"]
# How next-event estimation chooses among a scene's lights (mcrt's --light-select); "default"
# passes no --light-select: the scene's own (a pbrt-v4 file's lightsampler, else power).
DEFAULT_LIGHT_SELECT = "default"
LIGHT_SELECTS = [DEFAULT_LIGHT_SELECT, "power", "uniform", "bvh", "pbrt-bvh"]
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
# Without --out a run writes to a new directory, study-out/<UTC start time>/ under the current
# directory (not tracked by git); the committed results (bench/results/...) are rewritten only
# with --out naming them and --overwrite-committed.
NEW_OUT_PARENT = Path("study-out")
COMMITTED_RESULTS = REPO_ROOT / "bench" / "results"

QUICK_SPP = [4, 8, 16, 32]
QUICK_SEEDS = [1]
QUICK_REF_SPP = 1024
QUICK_SIZE = 48
QUICK_INTEGRATORS = ["mixture", "mis"]
QUICK_SAMPLERS = ["independent", "sobol"]
QUICK_STRATEGIES = ["area", "solid-angle", "projected-solid-angle", "auto"]
QUICK_OUT = REPO_ROOT / "build" / "study-quick"

RESULTS_CSV = "results.csv"
STATE_JSON = "study_state.json"
TABLES_MD = "tables.md"
REPORT_MD = "README.md"
SAMPLERS_JSON = "samplers.json"
REFERENCES_DIR = "references"
GENERATED_SCENES_DIR = "scenes"  # OUT/scenes/: the scene files of generated families
STATE_VERSION = 2

# Files every complete run writes (the per-scene difference plots are added
# when both strategies have points, the efficiency plots per depth mode).
COMMON_PLOTS = ["rmse_vs_spp.png", "time_vs_spp.png", "rmse_vs_time.png", "efficiency.png"]

STRATEGY_STYLE = {
    "area": {"color": "tab:blue", "label": "area"},
    "solid-angle": {"color": "tab:orange", "label": "solid angle"},
    "projected-solid-angle": {"color": "tab:green", "label": "projected solid angle"},
    "bilinear-solid-angle": {"color": "tab:purple", "label": "bilinear solid angle"},
    "pbrt": {"color": "tab:brown", "label": "pbrt-v4's choice"},
    "auto": {"color": "tab:red", "label": "auto (per shading point)"},
}

SAMPLER_DESCRIPTIONS = {
    "BM_SampleRectArea": "rectangle, by area",
    "BM_SampleRectSolidAngle": "rectangle, by solid angle (spherical rectangle)",
    "BM_SampleRectSolidAngleExact": "rectangle, by solid angle, exact path only",
    "BM_SampleEllipseArea": "disk/ellipse, by area",
    "BM_SampleEllipseSolidAngle": "disk/ellipse, by solid angle (parallel map, Newton)",
    "BM_SampleEllipseSolidAnglePolar": "disk/ellipse, by solid angle (polar map, Newton)",
    "BM_SampleEllipseSolidAngleBisectionSimpson": "disk/ellipse, by solid angle (parallel map, the thesis's bisection + Simpson)",
}

NOT_AVAILABLE_MARKER = "not available in this build"
# What mcrt says (exit status 2) for a strategy it lacks: in this build, or for a kind of scene
# file (--light-sampling auto on a pbrt-v4 scene where auto has no rule for its lights).
NOT_AVAILABLE_MARKERS = (NOT_AVAILABLE_MARKER, "not available for pbrt-v4 scenes")

# For the progress bar's estimate only: the fixed cost of one mcrt process
# (start, scene set-up, image input/output), counted as this many samples of
# work, and rough relative costs per sample (mixture, global depth = 1).
PROCESS_OVERHEAD_SAMPLES = 1_000_000
INTEGRATOR_COST = {"mixture": 1.0, "nee": 1.8, "mis": 1.8}
STRATEGY_COST = {"area": 1.0, "solid-angle": 1.9, "projected-solid-angle": 2.5, "bilinear-solid-angle": 2.2,
                 "pbrt": 2.0, "auto": 1.5}
DIRECT_COST = 0.55


@dataclass(frozen=True)
class Config:
    """One configuration of the renderer: light-sampling strategy, integrator, sample generator,
    light selection."""

    strategy: str
    integrator: str
    sampler: str
    light_select: str = DEFAULT_LIGHT_SELECT

    @property
    def label(self) -> str:
        """Short name for logs and file names: integrator/sampler/strategy, then /light selection
        unless it is the default."""
        tail = "" if self.light_select == DEFAULT_LIGHT_SELECT else f"/{self.light_select}"
        return f"{self.integrator}/{self.sampler}/{self.strategy}{tail}"


# The configuration every other is compared with: the earlier study's area sampling.
BASELINE = Config("area", LEGACY_INTEGRATOR, LEGACY_SAMPLER)


def config_of(row: dict) -> Config:
    """The configuration a CSV row was rendered with."""
    return Config(row["strategy"], row["integrator"], row["sampler"],
                  row.get("light_select") or DEFAULT_LIGHT_SELECT)


@dataclass(frozen=True)
class SceneInfo:
    """A scene of the study: its name, file, content hash, render size and global max depth."""

    name: str
    path: Path
    content_sha256: str
    width: int
    height: int
    max_depth: int  # the global mode's: --max-depth, else the scene's, else mcrt's default
    family: str = ""  # generated family (scenes.FAMILIES), "" for a scene file
    family_param: float | None = None  # the family's parameter (light area ratio, or h / light size)
    light_solid_angle: float | None = None  # first light's solid angle (sr) from the scene's centre point

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


@dataclass(frozen=True)
class FamilyMember:
    """One generated scene (scenes.FAMILIES): its name, family, family parameter, scene and the
    light solid angle (sr) the CSV reports.

    `scene` is a JSON scene's data (a dict), a pbrt-v4 file's text, or a function that makes that
    text; `light_solid_angle` a number or a function that computes it (members that take a while
    to make are made when first asked for, once per process)."""

    name: str
    family: str
    param: float
    scene: dict | str | Callable[[], str]
    light_solid_angle: float | Callable[[], float]

    @property
    def suffix(self) -> str:
        """The extension of the member's file: .json or .pbrt."""
        return ".json" if isinstance(self.scene, dict) else ".pbrt"

    @property
    def solid_angle(self) -> float:
        """The light solid angle (sr)."""
        value = self.light_solid_angle
        return float(value()) if callable(value) else float(value)


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
    light_select: str = DEFAULT_LIGHT_SELECT


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
    light_select: str = DEFAULT_LIGHT_SELECT

    @property
    def config(self) -> Config:
        """The configuration that failed."""
        return Config(self.strategy, self.integrator, self.sampler, self.light_select)


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
    # Per-pixel efficiency maps (scripts/mcrt_study/pixelmaps.py).
    pixel_maps: list[str] = field(default_factory=list)  # scenes to map; none by default
    pixel_map_seeds: int = 8
    pixel_map_spp: int | None = None  # None: the sweep's largest spp
    # Runs of each render whose median time is its time (renders of a few
    # ms vary by 10-20 % run to run; the image is the same every run).
    time_repeats: int = 1
    # True when `out` is the new directory chosen without --out (resuming needs --out naming it).
    out_is_new: bool = False
    # Light selections of the sweep (--light-selects) and of the references (--ref-light-select).
    light_selects: list[str] = field(default_factory=lambda: [DEFAULT_LIGHT_SELECT])
    ref_light_select: str = DEFAULT_LIGHT_SELECT

    @property
    def configs(self) -> list[Config]:
        """Every selected configuration, in table order (strategies of one integrator, sampler and
        light selection adjacent)."""
        axes = itertools.product(self.integrators, self.samplers, self.light_selects, self.strategies)
        return [Config(s, i, m, ls) for i, m, ls, s in axes]

    @property
    def varies_light_select(self) -> bool:
        """Whether the run names a light selection (the tables then have a column for it)."""
        return self.light_selects != [DEFAULT_LIGHT_SELECT]


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
        epilog="See the docstring of scripts/mcrt_study/__init__.py for details.",
    )
    p.add_argument("--quick", action="store_true",
                   help=f"tiny study: {QUICK_SIZE}x{QUICK_SIZE}, spp {','.join(map(str, QUICK_SPP))}, "
                   f"one seed, integrators {' '.join(QUICK_INTEGRATORS)}, samplers "
                   f"{' '.join(QUICK_SAMPLERS)}, strategies {' '.join(QUICK_STRATEGIES)}, "
                   f"{QUICK_REF_SPP} spp references, output in "
                   "build/study-quick (each of these can still be overridden)")
    p.add_argument("--mcrt", type=Path, default=REPO_ROOT / "build" / "mcrt",
                   help="mcrt executable (default: build/mcrt)")
    p.add_argument("--bench", type=Path, default=None,
                   help="mcrt_bench_samplers executable (default: beside the mcrt executable; "
                   "skipped if missing)")
    p.add_argument("--no-bench", action="store_true", help="do not run the sampler benchmark")
    p.add_argument("--out", type=Path, default=None,
                   help=f"output directory; the same --out again resumes a run (default: a new directory "
                   f"{NEW_OUT_PARENT}/<UTC time>/ under the current directory, or build/study-quick with --quick)")
    p.add_argument("--overwrite-committed", action="store_true",
                   help="allow --out to name a directory that holds files tracked by git (the committed "
                   "results, e.g. --out bench/results/strategy_map), whose files the run rewrites; "
                   "without it such a directory is refused (exit status 2)")
    p.add_argument("--scenes", nargs="+", default=None,
                   help="scene names in scenes/, paths to scene files (.json or .pbrt), generated "
                   "families (size_rect, size_disk, size_sphere, distance, tri_size, tri_distance, "
                   "tri_aspect, tri_grazing, many_lights: all their members) or members "
                   "(e.g. size_rect_x2, distance_h0.01, tri_aspect_a1000, many_lights_n1000) "
                   f"(default: {' '.join(DEFAULT_SCENES)})")
    p.add_argument("--strategies", nargs="+", choices=STRATEGIES, default=None,
                   help="light-sampling strategies (default: area solid-angle; --quick: "
                   f"{' '.join(QUICK_STRATEGIES)})")
    p.add_argument("--integrators", nargs="+", choices=INTEGRATORS, default=None,
                   help="integrators (default: all three; --quick: "
                   f"{' '.join(QUICK_INTEGRATORS)})")
    p.add_argument("--samplers", nargs="+", choices=SAMPLERS, default=None,
                   help="sample generators (default: all three; --quick: "
                   f"{' '.join(QUICK_SAMPLERS)})")
    p.add_argument("--light-selects", nargs="+", choices=LIGHT_SELECTS, default=None,
                   help="light selections (mcrt's --light-select: how next-event estimation chooses "
                   "among several lights); default: the scene's own, no --light-select passed "
                   "(a pbrt-v4 file's lightsampler, else power) (default: default)")
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
    p.add_argument("--ref-strategy", choices=["preferred", *STRATEGIES], default="preferred",
                   help="strategy of the references; auto: solid-angle when available, else area")
    p.add_argument("--ref-integrator", choices=INTEGRATORS, default=DEFAULT_REF_INTEGRATOR,
                   help=f"integrator of the references (default: {DEFAULT_REF_INTEGRATOR})")
    p.add_argument("--ref-sampler", choices=SAMPLERS, default=DEFAULT_REF_SAMPLER,
                   help=f"sample generator of the references (default: {DEFAULT_REF_SAMPLER})")
    p.add_argument("--ref-light-select", choices=LIGHT_SELECTS, default=DEFAULT_LIGHT_SELECT,
                   help="light selection of the references (default: the scene's own; bvh gives "
                   "less noisy references of scenes with many lights)")
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
    p.add_argument("--time-repeats", type=int, default=1, metavar="R",
                   help="run each render R times and take the median of its times (the image is the "
                   "same every run; default: 1)")
    p.add_argument("--fresh", action="store_true",
                   help="discard the points of previous runs (cached references are kept)")
    p.add_argument("--report-only", action="store_true",
                   help="render nothing: rebuild tables, plots and report from the CSV")
    p.add_argument("--check", action="store_true",
                   help="verify the outputs at the end; exit 1 if a check fails")
    p.add_argument("--pixel-maps", nargs="+", default=None, metavar="SCENE",
                   help="per-pixel efficiency maps against area sampling for these scenes (names as for "
                   "--scenes), in the report's slice (integrator, sampler, depth mode) (default: none)")
    p.add_argument("--pixel-map-seeds", type=int, default=8,
                   help="renders (seeds) per strategy of each pixel map (default: 8)")
    p.add_argument("--pixel-map-spp", type=int, default=None,
                   help="samples per pixel of the pixel maps' renders (default: the sweep's largest)")
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
        out=(args.out or (QUICK_OUT if quick else new_output_dir())).resolve(),
        scenes=args.scenes or list(DEFAULT_SCENES),
        strategies=args.strategies or list(QUICK_STRATEGIES if quick else DEFAULT_STRATEGIES),
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
    settings.light_selects = [s for s in LIGHT_SELECTS if s in (args.light_selects or [DEFAULT_LIGHT_SELECT])]
    settings.ref_light_select = args.ref_light_select
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
    settings.pixel_maps = list(dict.fromkeys(args.pixel_maps or []))
    settings.pixel_map_seeds, settings.pixel_map_spp = args.pixel_map_seeds, args.pixel_map_spp
    settings.time_repeats = args.time_repeats
    settings.out_is_new = args.out is None and not quick
    if settings.time_repeats < 1:
        problems.append("--time-repeats must be positive")
    if settings.pixel_map_seeds < 1 or (settings.pixel_map_spp is not None and settings.pixel_map_spp < 1):
        problems.append("--pixel-map-seeds and --pixel-map-spp must be positive")
    if problems:
        raise SystemExit("study.py: " + "; ".join(problems))
    return settings


def new_output_dir(parent: Path | None = None, now: datetime.datetime | None = None) -> Path:
    """A directory that does not exist yet for a run without --out: PARENT/<UTC time>
    (default parent: study-out/ under the current directory), with -2, -3, ... appended when a
    run of the same second took that name. Not created here."""
    parent = (parent if parent is not None else NEW_OUT_PARENT).resolve()
    stamp = (now or datetime.datetime.now(datetime.timezone.utc)).strftime("%Y-%m-%dT%H%M%SZ")
    path, n = parent / stamp, 2
    while path.exists():
        path, n = parent / f"{stamp}-{n}", n + 1
    return path


def make_new_output_dir(out: Path) -> None:
    """Create the new directory of a run without --out, and beside it in its parent (study-out/)
    a .gitignore of '*', so that git ignores every run's directory wherever the parent lies."""
    out.parent.mkdir(parents=True, exist_ok=True)
    ignore = out.parent / ".gitignore"
    if not ignore.exists():
        ignore.write_text("# Outputs of scripts/study.py runs without --out; not tracked.\n*\n", encoding="utf-8")
    out.mkdir()


def committed_files(path: Path) -> list[str]:
    """The files under `path` that git tracks (paths relative to the repository's top), in the
    repository that holds `path`; empty when it holds none, lies in no repository or git is
    missing. Without git, a non-empty directory under bench/results counts as committed."""
    probe = Path(path).resolve()
    while not probe.is_dir() and probe != probe.parent:
        probe = probe.parent
    try:
        listed = subprocess.run(["git", "-C", str(probe), "ls-files", "-z", "--", str(Path(path).resolve())],
                                capture_output=True, text=True)
    except OSError:  # no git: the committed results are known by where they are
        inside = Path(path).resolve().is_relative_to(COMMITTED_RESULTS.resolve())
        return sorted(str(f) for f in Path(path).rglob("*") if f.is_file()) if inside and Path(path).is_dir() else []
    if listed.returncode != 0:  # not in a repository (or outside this one's work tree)
        return []
    return [f for f in listed.stdout.split("\0") if f]


def output_refusal(args: argparse.Namespace, settings: Settings) -> str:
    """Why the run must not write to its output directory ("" when it may): --report-only without
    --out (nothing to report on in a new directory), or an --out that holds files tracked by git
    (the committed results) without --overwrite-committed."""
    if args.report_only and args.out is None and not args.quick:
        return "--report-only needs --out DIR, the directory of the run to report on"
    if getattr(args, "overwrite_committed", False):
        return ""
    committed = committed_files(settings.out)
    if committed:
        files = f"{len(committed)} file{'s' if len(committed) != 1 else ''}"
        return (f"{repo_relative(str(settings.out))} holds committed results ({files} tracked by git); "
                "rewrite them with --overwrite-committed, or leave out --out to write to a new directory")
    return ""


def repo_relative(path: str) -> str:
    """A path relative to the repository root when it lies inside it, else as given."""
    try:
        return str(Path(os.path.abspath(path)).relative_to(REPO_ROOT))
    except ValueError:
        return path
