"""The command: run the study, or rebuild its report, then optionally check it."""

from __future__ import annotations

import datetime
import shlex
import signal
import sys
import time

from .analysis import scene_panels, select_rows, slice_rows
from .check import run_checks
from .config import (
    Failure, REPORT_MD, RESULTS_CSV, STATE_JSON, SceneInfo, Settings, build_parser,
    make_new_output_dir, output_refusal, resolve_settings,
)
from .executors import add_arguments, backend_of
from .plots import make_efficiency_plots, make_slice_plots
from .points import POINTS_DIR, merge_point_files
from .report import build_tables, write_report
from .results import legacy_max_depths, read_csv, read_state, scene_columns_lookup
from .runner import run_sampler_bench, run_study
from .scenes import load_scenes
from .util import format_duration, log


def report_only_inputs(settings: Settings, scenes: list[SceneInfo], spp_given: bool,
                       seeds_given: bool) -> list[dict]:
    """For --report-only: the CSV's rows (with the point files merged in) and the failures recorded
    in the state file.

    Without --spp or --seeds, the report covers the spp values and seeds the
    CSV holds for the selected scenes (so an earlier run's report can be
    rebuilt without repeating its sweep options).
    """
    settings.out.mkdir(parents=True, exist_ok=True)
    state_path = settings.out / STATE_JSON
    csv_path = settings.out / RESULTS_CSV
    state = read_state(state_path)
    rows = read_csv(csv_path, legacy_max_depths(settings, state_path), scene_columns_lookup(settings))
    rows = merge_point_files(csv_path, rows, settings.out / POINTS_DIR, state)
    names = {sc.name for sc in scenes}
    mine = [r for r in rows if r["scene"] in names]
    if mine and not spp_given:
        settings.spp = sorted({r["spp"] for r in mine})
    if mine and not seeds_given:
        settings.seeds = sorted({r["seed"] for r in mine})
    depths = {sc.name: {d for _, d in sc.depth_modes(settings.depths)} for sc in scenes}
    configs = set(settings.configs)
    failures = [Failure(**f) for f in state.get("failures", [])]
    settings.failures = [f for f in failures if f.scene in names
                         and f.config in configs
                         and (f.max_depth is None or f.max_depth in depths[f.scene])]
    return rows


def main(argv: list[str] | None = None) -> int:
    """Run the study (or rebuild its report); 0 on success, 1 on failure, 2 when the output
    directory is refused (one line on stderr: see config.output_refusal)."""
    argv = sys.argv if argv is None else argv
    parser = build_parser()
    add_arguments(parser)
    args = parser.parse_args(argv[1:])
    settings = resolve_settings(args, argv)
    refusal = output_refusal(args, settings)
    if refusal:
        print(f"study.py: {refusal}", file=sys.stderr)
        return 2
    # Stop cleanly (temporary images removed, finished points kept) on SIGTERM too.
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    try:
        return study(args, settings)
    except KeyboardInterrupt as stop:
        stop.resume_hint = ("run the same command with --out " + shlex.quote(str(settings.out)) + " to resume"
                            if settings.out_is_new else "run the same command again to resume")
        raise


def study(args, settings: Settings) -> int:
    """main()'s run once the output directory is settled."""
    backend = backend_of(args)
    started = datetime.datetime.now(datetime.timezone.utc)
    t0 = time.monotonic()
    if settings.out_is_new:
        make_new_output_dir(settings.out)
    log(f"output: {settings.out}" + (" (a new directory; --out DIR chooses one)" if settings.out_is_new else ""))
    scenes = load_scenes(settings.scenes, settings)
    if settings.report_only:
        rows = report_only_inputs(settings, scenes, args.spp is not None, args.seeds is not None)
    else:
        rows = run_study(settings, scenes, backend)
    samplers = run_sampler_bench(settings)
    selected = select_rows(rows, settings, scenes)
    tables, summary, analysis = build_tables(selected, settings, scenes, samplers)
    figures = make_efficiency_plots(analysis, settings, scene_panels(scenes, settings))
    figures += make_slice_plots(slice_rows(selected, settings, scenes), settings, [sc.name for sc in scenes])
    # Scene families (efficiency over area sampling against the light's solid angle, crossovers)
    # and the per-pixel efficiency maps of --pixel-maps: sections of the tables and report.
    from .analysis import family_crossovers
    from .pixelmaps import make_pixel_maps, pixel_map_figures, pixel_map_section
    from .plots import make_family_plots
    from .report import family_section
    crossings = family_crossovers(analysis, settings, scenes)
    family_figures = make_family_plots(crossings, settings)
    maps = make_pixel_maps(settings)
    tables += family_section(crossings, family_figures) + pixel_map_section(maps)
    figures += family_figures + pixel_map_figures(maps)
    write_report(settings, scenes, tables, figures, started)
    log(f"done in {format_duration(time.monotonic() - t0)}: {settings.out / REPORT_MD}")
    ok = not [f for f in settings.failures if not f.unavailable]
    if settings.check:
        ok = run_checks(settings, selected, scenes, summary, figures) and ok
    return 0 if ok else 1


def run(argv: list[str] | None = None) -> int:
    """main() as a command's exit status: 130, with a note, when interrupted (Ctrl-C, SIGTERM)."""
    try:
        return main(argv)
    except KeyboardInterrupt as stop:
        hint = getattr(stop, "resume_hint", "run the same command again to resume")
        print(f"\nstudy: interrupted; the points finished so far are in the CSV, {hint}", file=sys.stderr)
        return 130
