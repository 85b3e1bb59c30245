#!/usr/bin/env python3
"""Error against run time: area vs solid-angle sampling of area lights.

Runs the whole study with one command: for every Cornell scene and every
light-sampling strategy (``area``, ``solid-angle``) it renders a sweep of
sample counts with several seeds, measures the render time (``render_seconds``
from ``mcrt render --stats``: the rendering alone, no process start, no I/O)
and the error against a reference image (``rmse``, ``mse``, ``relmse`` from
``mcrt diff --json``), then writes a CSV, markdown tables, plots and a report.

Usage (from the repository root, with the virtual environment made by
scripts/setup.sh)::

    .venv/bin/python scripts/study.py                 # full study -> bench/results/
    .venv/bin/python scripts/study.py --quick         # ~1 minute  -> build/study-quick/
    .venv/bin/python scripts/study.py --quick --check # and verify the outputs

    # choose what to run
    .venv/bin/python scripts/study.py --scenes cornell_rect cornell_disk \\
        --spp 5:100:5 --seeds 1 2 3 --ref-spp 4000 --width 300 --height 300 \\
        --threads 2 --mcrt build/mcrt --out /tmp/study

Defaults (the full study): scenes cornell_rect, cornell_rect_large,
cornell_disk, cornell_disk_large (add cornell_materials with --scenes);
spp 5, 10, ..., 100; seeds 1, 2, 3; the scenes' own resolution and max depth;
a 4000 spp reference per scene rendered with seed 7919; all hardware threads.
``--quick``: 48x48, spp 4, 8, 16, 32, one seed, 1024 spp references, output in
build/study-quick (ignored by git).

Reference images. One reference per scene, rendered with solid-angle sampling
when the mcrt binary supports it for that scene, else with area sampling
(``--ref-strategy`` overrides); both converge to the same image. References
are cached in OUT/references/ under a key made of the scene file's content,
the resolution, spp, max depth, seed and strategy (``--ref-key-binary`` adds
a hash of the mcrt binary), so they are rendered once.

Resuming. Every finished point is appended to OUT/results.csv at once; a run
skips the points already there. OUT/study_state.json remembers, per scene,
the settings the points were made with (scene content, resolution, max depth,
reference): when those change, the scene's old points are dropped and run
again. ``--fresh`` discards all previous points (references stay cached).

Unavailable strategies. A strategy that mcrt rejects as "not available in
this build" (exit status 2) is skipped for that scene and named in the report;
the study goes on, and picks the strategy up unchanged once mcrt supports it
(the scene's reference is then rendered again with solid-angle sampling, and
its area points with it). Any other mcrt failure is reported too and makes
the exit status 1.

Progress is shown on stderr as a plain-text bar with an estimate of the time
left. ``--report-only`` rebuilds tables, plots and report from the CSV
without rendering. ``python scripts/study.py --help`` lists every option.

Outputs (in OUT):
    results.csv          scene,strategy,spp,seed,seconds,rmse,mse,relmse
    tables.md            the markdown tables
    README.md            the report: machine, commit, command line, date,
                         tables, sampler costs and the plots
    rmse_vs_spp.png, time_vs_spp.png, rmse_vs_time.png, efficiency.png,
    rmse_diff_SCENE.png  (RMSE area - RMSE solid-angle per spp)
    samplers.json        raw output of mcrt_bench_samplers
    references/          cached reference images (EXR) and their metadata

``--check`` verifies the outputs afterwards (files exist, CSV columns, RMSE
decreasing with spp: negative log-log slope per scene and strategy) and exits
1 when a check fails; the test suite runs ``--quick --check``.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import datetime
import hashlib
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

REPO_ROOT = Path(__file__).resolve().parent.parent
SCENES_DIR = REPO_ROOT / "scenes"

CSV_COLUMNS = ["scene", "strategy", "spp", "seed", "seconds", "rmse", "mse", "relmse"]
STRATEGIES = ["area", "solid-angle"]
DEFAULT_SCENES = ["cornell_rect", "cornell_rect_large", "cornell_disk", "cornell_disk_large"]
DEFAULT_SPP = list(range(5, 101, 5))
DEFAULT_SEEDS = [1, 2, 3]
DEFAULT_REF_SPP = 4000
DEFAULT_REF_SEED = 7919
DEFAULT_OUT = REPO_ROOT / "bench" / "results"

QUICK_SPP = [4, 8, 16, 32]
QUICK_SEEDS = [1]
QUICK_REF_SPP = 1024
QUICK_SIZE = 48
QUICK_OUT = REPO_ROOT / "build" / "study-quick"

RESULTS_CSV = "results.csv"
STATE_JSON = "study_state.json"
TABLES_MD = "tables.md"
REPORT_MD = "README.md"
SAMPLERS_JSON = "samplers.json"
REFERENCES_DIR = "references"
STATE_VERSION = 1

# Files every complete run writes (the per-scene difference plots are added
# when both strategies have points).
COMMON_PLOTS = ["rmse_vs_spp.png", "time_vs_spp.png", "rmse_vs_time.png", "efficiency.png"]

STRATEGY_STYLE = {
    "area": {"color": "tab:blue", "label": "area"},
    "solid-angle": {"color": "tab:orange", "label": "solid angle"},
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

# For the progress bar's estimate: the fixed cost of one mcrt process (start,
# scene set-up, image input/output), counted as this many samples of work.
PROCESS_OVERHEAD_SAMPLES = 1_000_000


# --------------------------------------------------------------------- types
@dataclass(frozen=True)
class SceneInfo:
    """A scene of the study: its name, file, content hash and render size."""

    name: str
    path: Path
    content_sha256: str
    width: int
    height: int
    max_depth: int | None


@dataclass
class Reference:
    """A cached reference image and how it was made."""

    scene: str
    path: Path
    key: str
    strategy: str
    spp: int
    seed: int
    seconds: float
    cached: bool


@dataclass
class Failure:
    """A (scene, strategy) that could not be run, and why."""

    scene: str
    strategy: str
    message: str
    unavailable: bool  # True: "not available in this build" (expected for now)


@dataclass
class Settings:
    """Everything a run needs, resolved from the command line."""

    mcrt: Path
    bench: Path | None
    out: Path
    scenes: list[str]
    strategies: list[str]
    spp: list[int]
    seeds: list[int]
    ref_spp: int
    ref_seed: int
    ref_strategy: str
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
        description="Error against run time of area vs solid-angle light sampling "
        "(references, RMSE/time sweeps, tables, plots, report).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="See the docstring at the top of scripts/study.py for details.",
    )
    p.add_argument("--quick", action="store_true",
                   help=f"tiny study: {QUICK_SIZE}x{QUICK_SIZE}, spp {','.join(map(str, QUICK_SPP))}, "
                   f"one seed, {QUICK_REF_SPP} spp references, output in build/study-quick "
                   "(each of these can still be overridden)")
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
                   help="light-sampling strategies (default: both)")
    p.add_argument("--spp", nargs="+", default=None,
                   help="samples per pixel of the sweep: values, comma lists or A:B:STEP "
                   "(default: 5:100:5)")
    p.add_argument("--seeds", nargs="+", default=None,
                   help="seeds of the sweep, each spp is rendered once per seed (default: 1 2 3)")
    p.add_argument("--ref-spp", type=int, default=None,
                   help=f"samples per pixel of the references (default: {DEFAULT_REF_SPP})")
    p.add_argument("--ref-seed", type=int, default=DEFAULT_REF_SEED,
                   help=f"seed of the references, must differ from the sweep's (default: {DEFAULT_REF_SEED})")
    p.add_argument("--ref-strategy", choices=["auto", *STRATEGIES], default="auto",
                   help="strategy of the references; auto: solid-angle when available, else area")
    p.add_argument("--ref-key-binary", action="store_true",
                   help="include a hash of the mcrt binary in the reference cache key")
    p.add_argument("--width", type=int, default=None, help="image width (default: the scene's)")
    p.add_argument("--height", type=int, default=None, help="image height (default: the scene's)")
    p.add_argument("--max-depth", type=int, default=None, help="path depth (default: the scene's)")
    p.add_argument("--threads", type=int, default=None,
                   help="render threads passed to mcrt (default: all hardware threads)")
    p.add_argument("--budgets", nargs="+", type=float, default=None,
                   help="time budgets in seconds for the equal-time table "
                   "(default: four per scene, spread over the times both strategies reached)")
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
        strategies=args.strategies or list(STRATEGIES),
        spp=parse_int_list(args.spp) if args.spp else list(QUICK_SPP if quick else DEFAULT_SPP),
        seeds=parse_int_list(args.seeds) if args.seeds else list(QUICK_SEEDS if quick else DEFAULT_SEEDS),
        ref_spp=args.ref_spp or (QUICK_REF_SPP if quick else DEFAULT_REF_SPP),
        ref_seed=args.ref_seed,
        ref_strategy=args.ref_strategy,
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
    settings.strategies = list(dict.fromkeys(settings.strategies))
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
def load_scene(spec: str, settings: Settings) -> SceneInfo:
    """Find a scene by name (scenes/NAME.json) or path, and read its size and depth."""
    path = Path(spec)
    if not path.suffix:
        path = SCENES_DIR / f"{spec}.json"
    if not path.is_file():
        raise SystemExit(f"study.py: scene not found: {spec}")
    data = json.loads(path.read_text(encoding="utf-8"))
    camera = data.get("camera", {})
    render = data.get("render", {})
    width = settings.width or int(camera.get("width", 0))
    height = settings.height or int(camera.get("height", 0))
    if width <= 0 or height <= 0:
        raise SystemExit(f"study.py: {path}: no camera width/height; pass --width and --height")
    max_depth = settings.max_depth or (int(render["max_depth"]) if "max_depth" in render else None)
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


def render(settings: Settings, scene: SceneInfo, strategy: str, spp: int, seed: int,
           image: Path) -> float:
    """Render one image; return render_seconds from --stats."""
    stats = image.with_suffix(".stats.json")
    args = ["render", str(scene.path), "-o", str(image), "--spp", str(spp), "--seed", str(seed),
            "--width", str(scene.width), "--height", str(scene.height),
            "--light-sampling", strategy, "--stats", str(stats), "--quiet"]
    if scene.max_depth is not None:
        args += ["--max-depth", str(scene.max_depth)]
    if settings.threads is not None:
        args += ["--threads", str(settings.threads)]
    run_mcrt(settings, args)
    data = json.loads(stats.read_text(encoding="utf-8"))
    stats.unlink(missing_ok=True)
    return float(data["render_seconds"])


def diff(settings: Settings, image: Path, reference: Path) -> dict[str, float]:
    """Error of an image against a reference (mcrt diff --json)."""
    proc = run_mcrt(settings, ["diff", str(image), str(reference), "--json"])
    data = json.loads(proc.stdout)
    return {k: float(data[k]) for k in ("rmse", "mse", "relmse")}


# --------------------------------------------------------------- references
def reference_key(settings: Settings, scene: SceneInfo, strategy: str, binary_hash: str) -> str:
    """Cache key of a reference: scene content, resolution, spp, depth, seed, strategy."""
    key = {
        "scene_sha256": scene.content_sha256,
        "width": scene.width,
        "height": scene.height,
        "spp": settings.ref_spp,
        "max_depth": scene.max_depth,
        "seed": settings.ref_seed,
        "strategy": strategy,
    }
    if settings.ref_key_binary:
        key["mcrt_sha256"] = binary_hash
    return sha256_json(key)[:16]


def find_cached_reference(settings: Settings, scene: SceneInfo, binary_hash: str) -> Reference | None:
    """A cached reference for the scene, if any matches the current settings.

    With --ref-strategy auto a solid-angle reference is preferred, then area.
    """
    order = STRATEGIES[::-1] if settings.ref_strategy == "auto" else [settings.ref_strategy]
    for strategy in order:
        key = reference_key(settings, scene, strategy, binary_hash)
        image = settings.out / REFERENCES_DIR / f"{scene.name}-{key}.exr"
        meta = image.with_suffix(".json")
        if image.is_file() and meta.is_file():
            info = json.loads(meta.read_text(encoding="utf-8"))
            return Reference(scene=scene.name, path=image, key=key, strategy=strategy,
                             spp=settings.ref_spp, seed=settings.ref_seed,
                             seconds=float(info.get("render_seconds", float("nan"))), cached=True)
    return None


def make_reference(settings: Settings, scene: SceneInfo, binary_hash: str,
                   progress: Progress | None) -> Reference:
    """Render (or find in the cache) the scene's reference image.

    Solid-angle sampling is tried first with --ref-strategy auto; if this
    build lacks it for the scene, area sampling is used and the reason noted.
    """
    cached = find_cached_reference(settings, scene, binary_hash)
    order = STRATEGIES[::-1] if settings.ref_strategy == "auto" else [settings.ref_strategy]
    if cached is not None and (cached.strategy == order[0] or settings.report_only):
        return cached
    if settings.report_only:
        raise SystemExit(f"study.py: --report-only: no cached reference for {scene.name}")
    refdir = settings.out / REFERENCES_DIR
    refdir.mkdir(parents=True, exist_ok=True)
    last_error: McrtError | None = None
    for strategy in order:
        if cached is not None and cached.strategy == strategy:
            return cached
        key = reference_key(settings, scene, strategy, binary_hash)
        image = refdir / f"{scene.name}-{key}.exr"
        say = progress.message if progress else log
        say(f"reference {scene.name}: {settings.ref_spp} spp, {scene.width}x{scene.height}, "
            f"{strategy} sampling, seed {settings.ref_seed}")
        try:
            seconds = render(settings, scene, strategy, settings.ref_spp, settings.ref_seed, image)
        except McrtError as err:
            last_error = err
            if err.unavailable and strategy != order[-1]:
                say(f"reference {scene.name}: {strategy} unavailable ({err}); falling back")
                continue
            raise
        meta = {
            "scene": scene.name, "scene_file": str(scene.path), "scene_sha256": scene.content_sha256,
            "width": scene.width, "height": scene.height, "spp": settings.ref_spp,
            "max_depth": scene.max_depth, "seed": settings.ref_seed, "strategy": strategy,
            "render_seconds": seconds, "mcrt": str(settings.mcrt), "mcrt_sha256": binary_hash,
            "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        }
        write_text_atomic(image.with_suffix(".json"), json.dumps(meta, indent=2) + "\n")
        return Reference(scene=scene.name, path=image, key=key, strategy=strategy,
                         spp=settings.ref_spp, seed=settings.ref_seed, seconds=seconds, cached=False)
    assert last_error is not None
    raise last_error


# ---------------------------------------------------------- CSV and state
def read_csv(path: Path) -> list[dict]:
    """Rows of the results CSV, typed; [] if there is none. Refuses a foreign header."""
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames != CSV_COLUMNS:
            raise SystemExit(f"study.py: {path} has columns {reader.fieldnames}, expected "
                             f"{CSV_COLUMNS}; move it away or pass --fresh")
        rows = []
        for r in reader:
            rows.append({"scene": r["scene"], "strategy": r["strategy"], "spp": int(r["spp"]),
                         "seed": int(r["seed"]), "seconds": float(r["seconds"]),
                         "rmse": float(r["rmse"]), "mse": float(r["mse"]), "relmse": float(r["relmse"])})
        return rows


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
    return {"scene": row["scene"], "strategy": row["strategy"], "spp": row["spp"], "seed": row["seed"],
            "seconds": f"{row['seconds']:.9g}", "rmse": f"{row['rmse']:.9g}",
            "mse": f"{row['mse']:.9g}", "relmse": f"{row['relmse']:.9g}"}


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


def read_state(path: Path) -> dict:
    """The state file (per-scene run keys); an empty one if missing or of another version."""
    if path.is_file():
        try:
            state = json.loads(path.read_text(encoding="utf-8"))
            if state.get("version") == STATE_VERSION:
                return state
        except json.JSONDecodeError:
            pass
    return {"version": STATE_VERSION, "scenes": {}}


def scene_run_key(scene: SceneInfo, reference: Reference) -> str:
    """What a scene's points depend on: content, resolution, depth and the reference."""
    return sha256_json({"scene_sha256": scene.content_sha256, "width": scene.width,
                        "height": scene.height, "max_depth": scene.max_depth,
                        "reference": reference.key})[:16]


# -------------------------------------------------------------------- sweep
def point_work(scene: SceneInfo, spp: int) -> float:
    """Estimated work of one sweep point, in samples: the render plus two mcrt processes."""
    return spp * scene.width * scene.height + 2 * PROCESS_OVERHEAD_SAMPLES


def reference_work(settings: Settings, scene: SceneInfo) -> float:
    """Estimated work of one reference, in samples."""
    return settings.ref_spp * scene.width * scene.height + PROCESS_OVERHEAD_SAMPLES


def run_study(settings: Settings) -> list[dict]:
    """References and sweep for every scene and strategy; returns all CSV rows."""
    out = settings.out
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / RESULTS_CSV
    state_path = out / STATE_JSON
    if settings.fresh and csv_path.exists():
        csv_path.unlink()
    rows = read_csv(csv_path)
    state = read_state(state_path)
    if settings.fresh:
        state = {"version": STATE_VERSION, "scenes": {}}
    binary_hash = sha256_file(settings.mcrt) if settings.mcrt.is_file() else ""
    scenes = [load_scene(s, settings) for s in settings.scenes]

    # Work left, to size the progress bar, in samples (spp x pixels plus a
    # fixed cost per process): the remaining sweep points plus the references
    # not in the cache.
    done_keys = {(r["scene"], r["strategy"], r["spp"], r["seed"]) for r in rows}
    total = 0.0
    counted_refs = set()
    preferred = "solid-angle" if settings.ref_strategy == "auto" else settings.ref_strategy
    for scene in scenes:
        cached = find_cached_reference(settings, scene, binary_hash)
        if cached is None or cached.strategy != preferred:
            total += reference_work(settings, scene)
            counted_refs.add(scene.name)
        for strategy in settings.strategies:
            for spp in settings.spp:
                for seed in settings.seeds:
                    if (scene.name, strategy, spp, seed) not in done_keys:
                        total += point_work(scene, spp)
    progress = Progress(total)
    tmpdir = Path(tempfile.mkdtemp(prefix=".sweep-", dir=out))
    try:
        for scene in scenes:
            try:
                reference = make_reference(settings, scene, binary_hash, progress)
            except McrtError as err:
                progress.message(f"{scene.name}: reference failed: {err}")
                for strategy in settings.strategies:
                    settings.failures.append(Failure(scene.name, strategy, f"reference: {err}", False))
                continue
            ref_work = reference_work(settings, scene)
            if not reference.cached and scene.name not in counted_refs:
                progress.add_work(ref_work)
            if not reference.cached or scene.name in counted_refs:
                progress.advance(ref_work, f"{scene.name} reference ready")
            run_key = scene_run_key(scene, reference)
            previous = state["scenes"].get(scene.name, {}).get("run_key")
            if previous != run_key and any(r["scene"] == scene.name for r in rows):
                progress.message(f"{scene.name}: settings or reference changed since the points in "
                                 f"{csv_path.name} were made; running them again")
                progress.add_work(sum(point_work(scene, r["spp"]) for r in rows if r["scene"] == scene.name
                                      and r["strategy"] in settings.strategies and r["spp"] in settings.spp
                                      and r["seed"] in settings.seeds))
                rows = [r for r in rows if r["scene"] != scene.name]
                write_csv(csv_path, rows)
                done_keys = {(r["scene"], r["strategy"], r["spp"], r["seed"]) for r in rows}
            state["scenes"][scene.name] = {
                "run_key": run_key, "scene_file": str(scene.path), "width": scene.width,
                "height": scene.height, "max_depth": scene.max_depth,
                "reference": {"file": os.path.relpath(reference.path, out), "strategy": reference.strategy,
                              "spp": reference.spp, "seed": reference.seed,
                              "render_seconds": reference.seconds},
            }
            write_text_atomic(state_path, json.dumps(state, indent=2) + "\n")
            rows = sweep_scene(settings, scene, reference, rows, done_keys, csv_path, tmpdir, progress)
    finally:
        progress.finish()
        shutil.rmtree(tmpdir, ignore_errors=True)
    # Remember what was skipped or failed, for --report-only.
    state["failures"] = [dataclasses.asdict(f) for f in settings.failures]
    write_text_atomic(state_path, json.dumps(state, indent=2) + "\n")
    return rows


def sweep_scene(settings: Settings, scene: SceneInfo, reference: Reference, rows: list[dict],
                done_keys: set, csv_path: Path, tmpdir: Path, progress: Progress) -> list[dict]:
    """The sweep of one scene: every seed, spp and strategy not yet in the CSV.

    Strategies alternate point by point so that a change of machine load
    affects both alike.
    """
    dead: dict[str, McrtError] = {}
    for seed in settings.seeds:
        for spp in settings.spp:
            for strategy in settings.strategies:
                key = (scene.name, strategy, spp, seed)
                if key in done_keys or strategy in dead:
                    continue
                label = f"{scene.name} {strategy} spp={spp} seed={seed}"
                image = tmpdir / f"{scene.name}-{strategy}-{spp}-{seed}.exr"
                try:
                    seconds = render(settings, scene, strategy, spp, seed, image)
                    errors = diff(settings, image, reference.path)
                except McrtError as err:
                    dead[strategy] = err
                    kind = "not available in this build, skipped" if err.unavailable else "FAILED"
                    progress.message(f"{scene.name} {strategy}: {kind}: {err}")
                    settings.failures.append(Failure(scene.name, strategy, str(err), err.unavailable))
                    left = sum(point_work(scene, s) for s in settings.spp for sd in settings.seeds
                               if (scene.name, strategy, s, sd) not in done_keys)
                    progress.advance(left, label)
                    continue
                finally:
                    image.unlink(missing_ok=True)
                row = {"scene": scene.name, "strategy": strategy, "spp": spp, "seed": seed,
                       "seconds": seconds, **errors}
                append_csv(csv_path, row)
                rows.append(row)
                done_keys.add(key)
                progress.advance(point_work(scene, spp), label)
    return rows


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
def select_rows(rows: list[dict], settings: Settings) -> list[dict]:
    """The rows of this run's scenes, strategies, spp and seeds."""
    names = {Path(s).stem for s in settings.scenes}
    spp, seeds = set(settings.spp), set(settings.seeds)
    return [r for r in rows if r["scene"] in names and r["strategy"] in settings.strategies
            and r["spp"] in spp and r["seed"] in seeds]


def group_stats(rows: list[dict], scene: str, strategy: str):
    """Per spp: arrays over seeds of seconds, rmse, mse, relmse (numpy), sorted by spp."""
    import numpy as np

    by_spp: dict[int, list[dict]] = {}
    for r in rows:
        if r["scene"] == scene and r["strategy"] == strategy:
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


def build_tables(rows: list[dict], settings: Settings, scenes: list[str],
                 samplers: list[dict] | None) -> tuple[str, dict]:
    """All markdown tables of the report, and the numbers the checks use."""
    parts: list[str] = []
    summary: dict = {"slopes": {}, "equal_time": []}

    # Convergence: slopes and efficiency.
    slope_rows = []
    for scene in scenes:
        for strategy in settings.strategies:
            st = group_stats(rows, scene, strategy)
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
            st = group_stats(rows, scene, strategy)
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
        stats = {s: group_stats(rows, scene, s) for s in settings.strategies}
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

    # Sampler costs.
    parts.append("\n### Sampler cost\n\n")
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
    return "".join(parts), summary


# ------------------------------------------------------------------- plots
def make_plots(rows: list[dict], settings: Settings, scenes: list[str]) -> list[tuple[str, str]]:
    """Write the PNG figures; return (file name, caption) pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker as ticker
    import numpy as np

    out = settings.out
    figures: list[tuple[str, str]] = []
    stats = {(sc, s): group_stats(rows, sc, s) for sc in scenes for s in settings.strategies}
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
        figures.append((name, caption))

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


def write_report(settings: Settings, rows: list[dict], scenes: list[str], tables: str,
                 figures: list[tuple[str, str]], started: datetime.datetime) -> None:
    """Write tables.md and the report README.md (relative links to the plots)."""
    out = settings.out
    write_text_atomic(out / TABLES_MD, tables)
    info = machine_info()
    state = read_state(out / STATE_JSON)
    mcrt_hash = sha256_file(settings.mcrt)[:12] if settings.mcrt.is_file() else "?"
    threads = str(settings.threads) if settings.threads else f"all ({info['cores']})"

    lines = [
        "# Error against run time: area vs solid-angle sampling of area lights\n",
        f"Generated by `scripts/study.py` on {started.strftime('%Y-%m-%d %H:%M UTC')}"
        + (" (**--quick**: a smoke test, not a measurement)" if settings.quick else "") + ".\n",
        "## Setup\n",
        f"- Command: `{settings.command_line}`",
        f"- Commit: `{info['commit']}`",
        f"- Machine: {info['cpu']}, {info['cores']} cores, {info['os']}; render threads: {threads}",
        f"- mcrt: `{repo_relative(str(settings.mcrt))}` (sha256 {mcrt_hash}…)",
        f"- Scenes: {', '.join(scenes)}",
        f"- Sweep: spp {', '.join(map(str, settings.spp))}; seeds {', '.join(map(str, settings.seeds))}; "
        f"strategies {', '.join(settings.strategies)}",
        "- Time: `render_seconds` of `mcrt render --stats` (rendering only: no process start, "
        "no scene parsing, no image output). Error: `mcrt diff --json` against the reference "
        "(relMSE as in pbrt: mean of (v−r)²/(r+0.01)²).",
        f"- Data: [{RESULTS_CSV}]({RESULTS_CSV}) (one row per render), tables also in [{TABLES_MD}]({TABLES_MD}).\n",
        "### References\n",
        "One reference per scene with a seed the sweep does not use, rendered with solid-angle "
        "sampling where this mcrt build supports it, else with area sampling (both converge "
        "to the same image). Cached by scene content, resolution, spp, depth, seed and strategy.\n",
    ]
    ref_rows = []
    for sc in scenes:
        s = state.get("scenes", {}).get(sc)
        if s:
            ref = s["reference"]
            ref_rows.append([sc, f"{s['width']}×{s['height']}", str(s.get("max_depth") or "scene"),
                             str(ref["spp"]), str(ref["seed"]), ref["strategy"],
                             fmt(ref.get("render_seconds", float("nan")), 4)])
    if ref_rows:
        lines.append(md_table(["scene", "resolution", "max depth", "spp", "seed", "strategy",
                               "render time (s)"], ref_rows, 1))
    if settings.failures:
        lines.append("### Skipped or failed\n")
        for f in settings.failures:
            kind = "not available in this mcrt build, skipped" if f.unavailable else "**failed**"
            lines.append(f"- {f.scene}, {f.strategy}: {kind} — `{f.message}`")
        lines.append("")
    lines.append("## Results\n")
    lines.append(tables)
    if figures:
        lines.append("\n## Plots\n")
        for name, caption in figures:
            lines.append(f"![{name}]({name})\n\n{caption}\n")
    write_text_atomic(out / REPORT_MD, "\n".join(lines) + "\n")


# ------------------------------------------------------------------ checks
def run_checks(settings: Settings, rows: list[dict], scenes: list[str], summary: dict,
               figures: list[tuple[str, str]]) -> bool:
    """Verify the outputs; print one line per check and a closing count. True if all pass."""
    out = settings.out
    results: list[tuple[bool, str]] = []

    def check(ok: bool, what: str) -> None:
        results.append((bool(ok), what))
        print(f"{'PASS' if ok else 'FAIL'}: {what}", flush=True)

    for name in dict.fromkeys([RESULTS_CSV, TABLES_MD, REPORT_MD, *COMMON_PLOTS, *(n for n, _ in figures)]):
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
    report = (out / REPORT_MD).read_text(encoding="utf-8") if (out / REPORT_MD).is_file() else ""
    check("### Equal time" in report and "### Convergence" in report and "| scene |" in report,
          "report has the markdown tables")
    check(all(f"({n})" in report for n in COMMON_PLOTS), "report embeds the plots")
    check(not [f for f in settings.failures if not f.unavailable],
          "no mcrt failure other than 'not available in this build'")
    finite = all(math.isfinite(r[k]) and r[k] >= 0 for r in rows for k in ("rmse", "mse", "relmse"))
    check(finite and all(r["seconds"] > 0 for r in rows), "errors finite and non-negative, times positive")
    unavailable = {(f.scene, f.strategy) for f in settings.failures if f.unavailable}
    for sc in scenes:
        check(any(r["scene"] == sc for r in rows), f"{sc}: has points")
        for strategy in settings.strategies:
            n = sum(1 for r in rows if r["scene"] == sc and r["strategy"] == strategy)
            expected = len(settings.spp) * len(settings.seeds)
            if (sc, strategy) in unavailable:
                check(n == 0, f"{sc} {strategy}: not available in this build, no points")
                continue
            check(n == expected, f"{sc} {strategy}: {n} of {expected} points")
            slope = summary["slopes"].get((sc, strategy), float("nan"))
            if len(settings.spp) >= 2:
                check(math.isfinite(slope) and slope < 0,
                      f"{sc} {strategy}: RMSE decreases with spp (log-log slope {slope:.3f} < 0)")
    passed = sum(ok for ok, _ in results)
    failed = len(results) - passed
    print(f"study check: {passed} passed, {failed} failed", flush=True)
    return failed == 0


# -------------------------------------------------------------------- main
def main(argv: list[str] | None = None) -> int:
    """Run the study (or rebuild its report); 0 on success, 1 on failure."""
    argv = sys.argv if argv is None else argv
    # Stop cleanly (temporary images removed, finished points kept) on SIGTERM too.
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    settings = resolve_settings(build_parser().parse_args(argv[1:]), argv)
    started = datetime.datetime.now(datetime.timezone.utc)
    t0 = time.monotonic()
    log(f"output: {settings.out}")
    if settings.report_only:
        settings.out.mkdir(parents=True, exist_ok=True)
        rows = read_csv(settings.out / RESULTS_CSV)
        names = {Path(s).stem for s in settings.scenes}
        settings.failures = [Failure(**f) for f in read_state(settings.out / STATE_JSON).get("failures", [])
                             if f["scene"] in names and f["strategy"] in settings.strategies]
    else:
        rows = run_study(settings)
    samplers = run_sampler_bench(settings)
    scenes = [Path(s).stem for s in settings.scenes]
    selected = select_rows(rows, settings)
    tables, summary = build_tables(selected, settings, scenes, samplers)
    figures = make_plots(selected, settings, scenes)
    write_report(settings, selected, scenes, tables, figures, started)
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
