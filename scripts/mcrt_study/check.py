"""--check: verify a study's outputs."""

from __future__ import annotations

import csv
import math

from .analysis import scene_panels
from .config import (
    COMMON_PLOTS, CSV_COLUMNS, REPORT_MD, RESULTS_CSV, SceneInfo, Settings, TABLES_MD,
    config_of,
)
from .report import panel_title


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
    unavailable = {(f.scene, f.config, f.max_depth)
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
