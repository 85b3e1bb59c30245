"""One sweep point: what runs it (render + diff, on any worker) and the file it leaves.

Every finished point is written by whoever rendered it as its own small file,
OUT/points/<key hash>.json, through a temporary name and os.replace, so a point
file is either complete or absent; several workers on shared storage never
write the same temporary file. The driver (and --report-only, and a resumed
run) merges these files into results.csv: a crashed or killed run loses no
finished point, and a point is never rendered twice for one set of settings.

A point file holds the CSV row (numbers at full precision) and the run key of
its scene and depth (results.scene_run_key); it is merged only while the state
file records that same run key, so points made with other settings or another
reference are never mixed in.
"""

from __future__ import annotations

import dataclasses
import json
import os
import socket
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

from .config import DEFAULT_LIGHT_SELECT, Config, SceneInfo, Settings
from .mcrt import McrtError, diff, render
from .results import parse_row, row_key, state_key, write_csv
from .util import log, sha256_json

POINTS_DIR = "points"  # OUT/points/
POINT_VERSION = 1

# The measurement of one point: (settings, scene, config, max depth, spp, seed,
# image, reference image) -> (render seconds, {"rmse", "mse", "relmse"}).
Measure = Callable[[Settings, SceneInfo, Config, int, int, int, Path, Path], tuple[float, dict]]


@dataclass(frozen=True)
class PointTask:
    """Everything a worker needs for one point; the paths lie on storage the driver and workers share."""

    settings: Settings  # with the render threads of this point (None: mcrt's default)
    scene: SceneInfo
    config: Config
    max_depth: int
    spp: int
    seed: int
    image: Path  # temporary image, removed after the diff
    reference: Path
    points_dir: Path
    run_key: str
    scene_columns: dict  # family, family_param, light_solid_angle
    share_worker_cores: bool = False  # on a Dask worker without --threads: share its cores


def measure_point(settings: Settings, scene: SceneInfo, config: Config, max_depth: int, spp: int,
                  seed: int, image: Path, reference: Path) -> tuple[float, dict]:
    """Render one point with mcrt and diff it against the reference: (seconds, errors)."""
    seconds = render(settings, scene, config, max_depth, spp, seed, image)
    return seconds, diff(settings, image, reference)


def run_point(task: PointTask, measure: Measure = measure_point) -> dict:
    """Run one point on a worker and write its point file.

    Returns {"row": the CSV row} or, when mcrt failed, {"error": message,
    "returncode": ..., "unavailable": ...} (plain values, so any executor can
    carry it back). Other exceptions propagate to the driver.
    """
    settings = task.settings
    if task.share_worker_cores and settings.threads is None:
        threads = dask_worker_render_threads()
        if threads is not None:
            settings = dataclasses.replace(settings, threads=threads)
    try:
        seconds, errors = measure(settings, task.scene, task.config, task.max_depth, task.spp, task.seed,
                                  task.image, task.reference)
    except McrtError as err:
        return {"error": str(err), "returncode": err.returncode, "unavailable": err.unavailable}
    finally:
        task.image.unlink(missing_ok=True)
    config = task.config
    row = {"scene": task.scene.name, "strategy": config.strategy, "integrator": config.integrator,
           "sampler": config.sampler, "max_depth": task.max_depth, "spp": task.spp, "seed": task.seed,
           "seconds": seconds, **errors, **task.scene_columns, "light_select": config.light_select}
    write_point(task.points_dir, row, task.run_key)
    return {"row": row}


def dask_worker_render_threads() -> int | None:
    """On a Dask worker: its cores shared among the renders it runs at once
    (max(1, cores // worker threads)); None elsewhere."""
    try:
        from distributed import get_worker
        worker = get_worker()
    except (ImportError, ValueError):
        return None
    slots = getattr(getattr(worker, "state", None), "nthreads", None) or 1
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return max(1, cores // slots)


def point_file_name(key: tuple) -> str:
    """The file name of a point (its row_key): a hash, the same on every machine. The key of a
    point with the default light selection is hashed without it, as before that axis existed."""
    key = list(key)
    if len(key) == 8 and key[7] == DEFAULT_LIGHT_SELECT:
        key = key[:7]
    return sha256_json(key)[:20] + ".json"


def write_point(points_dir: Path, row: dict, run_key: str) -> Path:
    """Write a finished point atomically: to a temporary name unique to this process, then os.replace.

    Readers skip names starting with a dot, so a half-written file is never read.
    """
    points_dir.mkdir(parents=True, exist_ok=True)
    path = points_dir / point_file_name(row_key(row))
    tmp = points_dir / f".{path.name}.{socket.gethostname()}-{os.getpid()}-{uuid.uuid4().hex[:8]}.tmp"
    text = json.dumps({"version": POINT_VERSION, "run_key": run_key, "row": row}, sort_keys=True) + "\n"
    try:
        with tmp.open("w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def point_files(points_dir: Path) -> Iterator[tuple[Path, str, dict]]:
    """(path, run key, typed row) of every complete point file, in file name order.

    Temporary files (names starting with a dot) are skipped, and so, with a
    note, is any file that does not hold a point.
    """
    if not points_dir.is_dir():
        return
    for path in sorted(points_dir.glob("*.json")):
        if path.name.startswith("."):
            continue
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            run_key, row = str(data["run_key"]), parse_row(data["row"])
        except (OSError, ValueError, KeyError, TypeError) as err:
            log(f"{path}: not a point file, ignored ({err})")
            continue
        yield path, run_key, row


def read_points(points_dir: Path) -> list[tuple[str, dict]]:
    """(run key, typed row) of every complete point file, in file name order."""
    return [(run_key, row) for _, run_key, row in point_files(points_dir)]


def merge_points(rows: list[dict], points: list[tuple[str, dict]], run_keys: dict[str, str]) -> list[dict]:
    """The rows plus every point not among them whose run key is the one recorded for its scene
    and depth (`run_keys`: state key -> run key).

    A point already in `rows` (or met before in `points`) is not added again.
    The points added come after the rows, in row_key order, so the result does
    not depend on the order in which the points were finished.
    """
    seen = {row_key(r) for r in rows}
    added = []
    for run_key, row in points:
        key = row_key(row)
        if key in seen or run_keys.get(state_key(row["scene"], row["max_depth"])) != run_key:
            continue
        seen.add(key)
        added.append(row)
    return rows + sorted(added, key=row_key)


def recorded_run_keys(state: dict) -> dict[str, str]:
    """The run key of every scene and depth in the state file."""
    return {key: run["run_key"] for key, run in state.get("runs", {}).items() if "run_key" in run}


def merge_point_files(csv_path: Path, rows: list[dict], points_dir: Path, state: dict) -> list[dict]:
    """Merge the point files into the CSV's rows; rewrite the CSV (atomically) when any was added."""
    merged = merge_points(rows, read_points(points_dir), recorded_run_keys(state))
    if len(merged) > len(rows):
        write_csv(csv_path, merged)
        log(f"{len(merged) - len(rows)} finished points merged from {points_dir} into {csv_path.name}")
    return merged


def remove_points(points_dir: Path, scene: str, max_depth: int) -> None:
    """Remove the point files of a scene and depth (its points are run again)."""
    for path, _, row in point_files(points_dir):
        if row["scene"] == scene and row["max_depth"] == max_depth:
            path.unlink(missing_ok=True)

