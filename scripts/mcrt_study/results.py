"""The results CSV (one row per render) and the state file that makes a run resumable."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import Callable

from .config import (
    CSV_COLUMNS, Config, DEFAULT_LIGHT_SELECT, LEGACY_INTEGRATOR, LEGACY_SAMPLER, MCRT_DEFAULT_MAX_DEPTH,
    OLD_CSV_COLUMNS, PRE_FAMILY_CSV_COLUMNS, PRE_SELECT_CSV_COLUMNS, Reference, SCENES_DIR, STATE_VERSION,
    SceneInfo, Settings,
)
from .scenes import family_member, scene_columns, scene_file_max_depth, scene_path
from .util import log, sha256_json


def row_key(row: dict) -> tuple:
    """What identifies a point: scene, configuration (strategy, integrator, sampler), max depth,
    spp, seed, light selection."""
    return (row["scene"], row["strategy"], row["integrator"], row["sampler"], row["max_depth"],
            row["spp"], row["seed"], row.get("light_select") or DEFAULT_LIGHT_SELECT)


def point_key(scene: str, config: Config, max_depth: int, spp: int, seed: int) -> tuple:
    """row_key of the point not rendered yet."""
    return (scene, config.strategy, config.integrator, config.sampler, max_depth, spp, seed, config.light_select)


def parse_row(r: dict) -> dict:
    """A CSV row with its fields typed."""
    return {"scene": r["scene"], "strategy": r["strategy"], "integrator": r["integrator"],
            "sampler": r["sampler"], "max_depth": int(r["max_depth"]), "spp": int(r["spp"]),
            "seed": int(r["seed"]), "seconds": float(r["seconds"]), "rmse": float(r["rmse"]),
            "mse": float(r["mse"]), "relmse": float(r["relmse"]), "family": r.get("family") or "",
            "family_param": optional_float(r.get("family_param")),
            "light_solid_angle": optional_float(r.get("light_solid_angle")),
            "light_select": r.get("light_select") or DEFAULT_LIGHT_SELECT}


def optional_float(value: object) -> float | None:
    """A number of the CSV that may be empty (None)."""
    return None if value is None or value == "" else float(value)


def scene_columns_lookup(settings: Settings) -> Callable[[str], dict]:
    """The family columns (family, family_param, light_solid_angle) of a scene by name, for rows of
    a CSV written before those columns: from the --scenes file of that name, else scenes/NAME.json,
    else the generated family member of that name."""
    paths = {Path(s).stem: scene_path(s) for s in settings.scenes if family_member(s) is None}
    cache: dict[str, dict] = {}

    def columns(name: str) -> dict:
        if name not in cache:
            cache[name] = scene_columns(name, paths.get(name))
        return cache[name]
    return columns


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


def read_csv(path: Path, legacy_depth: Callable[[str], int],
             columns: Callable[[str], dict] | None = None) -> list[dict]:
    """Rows of the results CSV, typed; [] if there is none.

    A CSV of the earlier format (no integrator, sampler, max_depth) is read as
    integrator mixture, sampler independent, max depth `legacy_depth(scene)`;
    one without the family columns (family, family_param, light_solid_angle)
    gets them from `columns(scene)` (default: scenes.scene_columns); one without
    the light_select column (these and all the earlier) is read as light
    selection "default" (no --light-select was passed); each is rewritten in the
    current format. Any other header is refused.
    """
    columns = columns or scene_columns
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        header, raw = reader.fieldnames, list(reader)
    if header == CSV_COLUMNS:
        return [parse_row(r) for r in raw]
    if header == PRE_SELECT_CSV_COLUMNS:
        rows = [parse_row(r) for r in raw]
        write_csv(path, rows)
        log(f"{path.name}: {len(rows)} rows without the light_select column read as light selection "
            f"{DEFAULT_LIGHT_SELECT}; rewritten with the columns " + ",".join(CSV_COLUMNS))
        return rows
    if header == PRE_FAMILY_CSV_COLUMNS:
        rows = [{**parse_row(r), **columns(r["scene"])} for r in raw]
        write_csv(path, rows)
        log(f"{path.name}: {len(rows)} rows without the scene-family columns read; rewritten "
            "with the columns " + ",".join(CSV_COLUMNS))
        return rows
    if header == OLD_CSV_COLUMNS:
        rows = [{**parse_row({**r, "integrator": LEGACY_INTEGRATOR, "sampler": LEGACY_SAMPLER,
                              "max_depth": legacy_depth(r["scene"])}), **columns(r["scene"])} for r in raw]
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
            **{k: f"{row[k]:.9g}" for k in ("seconds", "rmse", "mse", "relmse")},
            "family": row.get("family") or "",
            "family_param": "" if row.get("family_param") is None else f"{row['family_param']:.9g}",
            "light_solid_angle": "" if row.get("light_solid_angle") is None else f"{row['light_solid_angle']:.9g}",
            "light_select": row.get("light_select") or DEFAULT_LIGHT_SELECT}


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
