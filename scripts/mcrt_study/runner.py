"""The sweep: references and renders of every scene, depth mode and configuration; the sampler benchmark."""

from __future__ import annotations

import dataclasses
import itertools
import json
import os
import queue
import shutil
import subprocess
import tempfile
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path

from .config import (
    Config, DIRECT_COST, DIRECT_MAX_DEPTH, Failure, INTEGRATOR_COST, PROCESS_OVERHEAD_SAMPLES,
    RESULTS_CSV, Reference, SAMPLERS_JSON, SAMPLER_DESCRIPTIONS, STATE_JSON, STRATEGY_COST,
    SceneInfo, Settings, config_of,
)
from .executors import Backend, Pool, machine_cores, open_pool, render_threads
from .mcrt import McrtError
from .points import (
    POINTS_DIR, Measure, PointTask, measure_point, merge_point_files, remove_points, run_point,
)
from .references import find_cached_reference, make_reference, reference_strategies
from .results import (
    append_csv, empty_state, legacy_max_depths, point_key, read_csv, read_state, row_key,
    scene_columns_lookup, scene_run_key, state_key, write_csv,
)
from .scenes import scene_info_columns
from .util import Progress, log, sha256_file, write_text_atomic


def point_work(scene: SceneInfo, config: Config, max_depth: int, spp: int) -> float:
    """Estimated work of one sweep point, in samples: the render (weighted by rough relative
    costs) plus two mcrt processes."""
    cost = (INTEGRATOR_COST[config.integrator] * STRATEGY_COST[config.strategy]
            * (DIRECT_COST if max_depth == DIRECT_MAX_DEPTH else 1.0))
    return spp * scene.width * scene.height * cost + 2 * PROCESS_OVERHEAD_SAMPLES


def reference_work(settings: Settings, scene: SceneInfo, max_depth: int) -> float:
    """Estimated work of one reference, in samples."""
    config = Config(reference_strategies(settings)[0], settings.ref_integrator, settings.ref_sampler,
                    settings.ref_light_select)
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
    points_dir: Path
    pool: Pool | None = None
    measure: Measure = measure_point
    threads: int | None = None  # --threads of each sweep render (None: mcrt's default)
    share_worker_cores: bool = False  # on Dask workers without --threads

    def save_state(self) -> None:
        """Write the state file."""
        write_text_atomic(self.state_path, json.dumps(self.state, indent=2) + "\n")


def run_study(settings: Settings, scenes: list[SceneInfo], backend: Backend = Backend(),
              measure: Measure = measure_point) -> list[dict]:
    """References and sweep for every scene, depth mode and configuration; returns all CSV rows.

    The references are rendered here, one after another; the sweep's points
    run on the backend's executor (`measure`: how a point is rendered and
    measured), each leaving its point file in OUT/points, merged into the CSV.
    """
    out = settings.out
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / RESULTS_CSV
    state_path = out / STATE_JSON
    points_dir = out / POINTS_DIR
    if settings.fresh and csv_path.exists():
        csv_path.unlink()
    if settings.fresh:
        shutil.rmtree(points_dir, ignore_errors=True)
    rows = read_csv(csv_path, legacy_max_depths(settings, state_path), scene_columns_lookup(settings))
    state = empty_state() if settings.fresh else read_state(state_path)
    rows = merge_point_files(csv_path, rows, points_dir, state)
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
    sweep = Sweep(settings, rows, done, csv_path, state, state_path, progress, tmpdir, binary_hash,
                  points_dir, measure=measure, threads=render_threads(settings.threads, backend, machine_cores()),
                  share_worker_cores=backend.name == "dask")
    try:
        with open_pool(backend) as pool:
            sweep.pool = pool
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
                                             config.integrator, config.sampler, depth, config.light_select))
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
        remove_points(sweep.points_dir, scene.name, depth)
        sweep.done = {row_key(r) for r in sweep.rows}
    sweep.state["runs"][key] = {
        "run_key": run_key, "scene": scene.name, "mode": mode, "scene_file": str(scene.path),
        "width": scene.width, "height": scene.height, "max_depth": depth,
        "reference": {"file": os.path.relpath(reference.path, settings.out), "strategy": reference.strategy,
                      "integrator": reference.integrator, "sampler": reference.sampler,
                      "light_select": reference.light_select,
                      "spp": reference.spp, "seed": reference.seed, "render_seconds": reference.seconds},
    }
    sweep.save_state()
    return reference


@dataclass(frozen=True)
class Point:
    """A point of a scene's sweep: max depth, configuration, spp, seed."""

    max_depth: int
    config: Config
    spp: int
    seed: int


def sweep_order(settings: Settings, depths: list[int]) -> list[Point]:
    """Every point of a scene's sweep, in the order they are run.

    For each seed and spp, every depth and every configuration in turn, the
    order of the configurations rotated by one from each (seed, spp, depth) to
    the next, so that a change of machine load affects all configurations alike
    and none is always first.
    """
    configs = settings.configs
    points: list[Point] = []
    turn = 0
    for seed in settings.seeds:
        for spp in settings.spp:
            for depth in depths:
                shift = turn % len(configs)
                turn += 1
                points += [Point(depth, config, spp, seed) for config in configs[shift:] + configs[:shift]]
    return points


def sweep_scene(sweep: Sweep, scene: SceneInfo, references: dict[int, Reference]) -> None:
    """The sweep of one scene: every point of sweep_order not yet in the CSV, on the sweep's executor.

    As many points are kept in flight as the executor has room for (one with
    --jobs 1: each point runs when it is submitted, as before). Finished rows
    are appended to the CSV in the sweep's order, whatever order they finish
    in; their point files are written by the workers as they finish. When a
    configuration fails (or is not available in this build) at a depth, its
    points not yet submitted are skipped.
    """
    settings = sweep.settings
    assert sweep.pool is not None
    point_settings = dataclasses.replace(settings, threads=sweep.threads, failures=[])
    run_keys = {depth: scene_run_key(scene, depth, reference) for depth, reference in references.items()}
    columns = scene_info_columns(scene)
    dead: dict[tuple[int, Config], str] = {}
    inflight: dict[tuple, Point] = {}
    finished: dict[int, dict | None] = {}  # submission number -> row (None: failed)
    flushed = 0
    submitted = 0
    completions: queue.Queue = queue.Queue()
    todo = iter(sweep_order(settings, list(references)))

    def key_of(point: Point) -> tuple:
        return point_key(scene.name, point.config, point.max_depth, point.spp, point.seed)

    def next_point() -> Point | None:
        for point in todo:
            if key_of(point) not in sweep.done and (point.max_depth, point.config) not in dead:
                return point
        return None

    while True:
        room = sweep.pool.capacity() - len(inflight)
        while room > 0 and (point := next_point()) is not None:
            config, depth = point.config, point.max_depth
            image = sweep.tmpdir / (f"{scene.name}-{depth}-{config.strategy}-{config.integrator}-"
                                    f"{config.sampler}-{config.light_select}-{point.spp}-{point.seed}.exr")
            task = PointTask(point_settings, scene, config, depth, point.spp, point.seed, image,
                             references[depth].path, sweep.points_dir, run_keys[depth], columns,
                             sweep.share_worker_cores)
            inflight[key_of(point)] = point
            number = submitted
            submitted += 1
            future = sweep.pool.executor.submit(run_point, task, sweep.measure)
            future.add_done_callback(lambda f, n=number, p=point: completions.put((n, p, f)))
            room -= 1
        if not inflight:
            break
        number, point, future = completions.get()
        finished[number] = record_outcome(sweep, scene, point, references[point.max_depth].mode, future,
                                          dead, inflight)
        while flushed in finished:
            row = finished.pop(flushed)
            flushed += 1
            if row is not None:
                append_csv(sweep.csv_path, row)
                sweep.rows.append(row)


def record_outcome(sweep: Sweep, scene: SceneInfo, point: Point, mode: str, future: Future,
                   dead: dict[tuple[int, Config], str], inflight: dict[tuple, Point]) -> dict | None:
    """Take in a finished point: its row (the point done), or its failure (its configuration and
    depth dead for this scene, the rest of their work off the progress bar). Returns the row, or
    None."""
    settings, progress = sweep.settings, sweep.progress
    config, depth = point.config, point.max_depth
    key = point_key(scene.name, config, depth, point.spp, point.seed)
    del inflight[key]
    label = f"{scene.name} {mode} {config.label} spp={point.spp} seed={point.seed}"
    outcome = future.result()
    if "row" in outcome:
        sweep.done.add(key)
        progress.advance(point_work(scene, config, depth, point.spp), label)
        return outcome["row"]
    if (depth, config) in dead:  # in flight when its configuration failed
        progress.advance(point_work(scene, config, depth, point.spp), label)
        return None
    err = McrtError(outcome["error"], outcome["returncode"], outcome["unavailable"])
    dead[(depth, config)] = str(err)
    kind = "not available in this build (for this scene), skipped" if err.unavailable else "FAILED"
    progress.message(f"{scene.name} ({mode}) {config.label}: {kind}: {err}")
    settings.failures.append(Failure(scene.name, config.strategy, str(err), err.unavailable,
                                     config.integrator, config.sampler, depth, config.light_select))
    left = sum(point_work(scene, config, depth, s) for s in settings.spp for sd in settings.seeds
               if point_key(scene.name, config, depth, s, sd) not in sweep.done
               and point_key(scene.name, config, depth, s, sd) not in inflight)
    progress.advance(left, label)
    return None


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
