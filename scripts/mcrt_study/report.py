"""Markdown tables and the report (README.md) of a study."""

from __future__ import annotations

import datetime
import math
import os
import platform
import subprocess
from pathlib import Path

from .analysis import (
    analyse_configs, baseline_config, default_budgets, efficiency_ratio, group_stats, interp_loglog,
    loglog_slope, mean_curve, scene_panels, slice_of, slice_rows,
)
from .config import (
    DEFAULT_LIGHT_SELECT, Config, DIRECT_MAX_DEPTH, Failure, LEGACY_INTEGRATOR, LEGACY_SAMPLER, REPORT_MD, REPO_ROOT,
    RESULTS_CSV, SAMPLER_DESCRIPTIONS, STATE_JSON, SceneInfo, Settings, TABLES_MD, repo_relative,
)
from .results import read_state, state_key
from .util import sha256_file, write_text_atomic


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


def cells_of(config: Config, with_select: bool = False) -> list[str]:
    """The integrator, sampler (light selection) and strategy columns of a configuration's table row."""
    return [config.integrator, config.sampler, *([config.light_select] if with_select else []), config.strategy]


def config_header(with_select: bool = False) -> list[str]:
    """The headers of cells_of's columns."""
    return ["integrator", "sampler", *(["light selection"] if with_select else []), "strategy"]


def config_text(config: Config, with_select: bool = False) -> str:
    """A configuration in words: 'mixture, independent, area' (', light selection bvh' added)."""
    return (f"{config.integrator}, {config.sampler}, {config.strategy}"
            + (f", light selection {config.light_select}" if with_select else ""))


def bold(text: str, on: bool) -> str:
    """Markdown bold when `on`."""
    return f"**{text}**" if on else text


def build_config_tables(analysis: dict, settings: Settings,
                        panels: list[tuple[str, str, int]]) -> tuple[str, dict]:
    """The tables over every configuration: efficiency (overview and per scene and depth mode),
    MSE at equal time, RMSE slopes; and the numbers the checks use."""
    base = baseline_config(settings)
    configs = [c for c in settings.configs if any(c in analysis[(sc, d)] for sc, _, d in panels)]
    with_select = settings.varies_light_select
    columns = config_header(with_select)

    def config_cells(c: Config) -> list[str]:  # this run's columns
        return cells_of(c, with_select)
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
        return efficiency_ratio(analysis, base, scene, depth, config)

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
        f"({config_text(base, with_select)}) of the same scene and depth mode; "
        "higher is better, the best configuration of each column is in bold. In the tables per "
        "scene, ± s.e. is the standard error of the geometric mean from the spread of the renders "
        "over seeds at equal spp (machine-speed and Monte-Carlo noise, not the trend over spp); "
        "ms per spp is at the largest spp.\n\n")
    header = list(columns)
    header += [f"{scene} {mode}" for scene, mode, _ in panels]
    table = []
    for c in configs:
        line = config_cells(c)
        for scene, _, depth in panels:
            line.append(bold(fmt(ratio(scene, depth, c), 3), summary["best"].get((scene, depth)) == c))
        table.append(line)
    parts.append(md_table(header, table, len(columns)))
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
        parts.append(md_table([*columns, "renders", "efficiency",
                               "± s.e.", "× baseline", "ms per spp", ""], table, len(columns)))

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
        parts.append(md_table([*columns,
                               *[f"MSE at {fmt(b, 3)} s" for b in budgets], "baseline MSE / MSE"], table,
                              len(columns)))

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
    parts.append(md_table([*columns, *[f"{sc} {m}" for sc, m, _ in panels]],
                          table, len(columns)))
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


def machine_info() -> dict[str, str]:
    """CPU model, core count, OS and Python version (the renderer's commit: renderer_commit)."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.lower().startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": str(os.cpu_count() or "?"),
            "os": f"{platform.system()} {platform.release()}", "python": platform.python_version()}


# The sources of the renderer (the mcrt executable) and of the sampler benchmark the study runs:
# a change elsewhere (documentation, scripts, tests, results) leaves the binary as it was.
RENDERER_SOURCES = ["CMakeLists.txt", "cmake", "include", "src"]
BENCH_SOURCES = ["bench/CMakeLists.txt", ":(glob)bench/*.cpp", ":(glob)bench/*.hpp", ":(glob)bench/*.inc"]


def renderer_commit(out: Path | None = None, sources: list[str] | None = None) -> tuple[str, bool]:
    """The commit of the renderer the repository builds and whether the work tree changes it: the
    last commit (up to HEAD) that changed its sources (RENDERER_SOURCES), as a short hash, and True
    when tracked or new files among those sources differ from it (changes under `out`, the
    study's own outputs, do not count, nor do changes anywhere else: documentation, scripts,
    tests, results); ("unknown", False) outside a git repository."""
    sources = sources or RENDERER_SOURCES
    exclude = []
    if out is not None:
        try:
            exclude = [":(exclude)" + str(Path(out).resolve().relative_to(REPO_ROOT.resolve()))]
        except ValueError:  # outside the repository
            pass

    def git(*args: str) -> str:
        return subprocess.run(["git", "-C", str(REPO_ROOT), *args], capture_output=True, text=True,
                              check=True).stdout.strip()
    try:
        commit = git("log", "-1", "--format=%h", "HEAD", "--", *sources) or git("rev-parse", "--short", "HEAD")
        dirty = git("status", "--porcelain", "--untracked-files=all", "--", *sources, *exclude)
    except (OSError, subprocess.CalledProcessError):
        return "unknown", False
    return commit, bool(dirty)


def machine_name(cpu: str, cores: str) -> str:
    """The machine as the reports name it: '2-core KVM virtual machine, CPU AMD EPYC' (lscpu's
    hypervisor vendor; without one, '8-core machine, CPU ...')."""
    kind = "machine"
    try:
        lscpu = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
        for line in lscpu.splitlines():
            if line.lower().startswith("hypervisor vendor:"):
                kind = f"{line.split(':', 1)[1].strip()} virtual machine"
    except (OSError, subprocess.CalledProcessError):
        try:
            if " hypervisor" in Path("/proc/cpuinfo").read_text(encoding="utf-8"):
                kind = "virtual machine"
        except OSError:
            pass
    return f"{cores}-core {kind}, CPU {cpu}"


def memory_gib() -> str:
    """Total memory in GiB ('?' where /proc/meminfo is missing)."""
    try:
        for line in Path("/proc/meminfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("MemTotal:"):
                return f"{int(line.split()[1]) / 2**20:.0f}"
    except (OSError, ValueError, IndexError):
        pass
    return "?"


def unkept_figures(out: Path, names: list[str]) -> list[str]:
    """The figures among `names` (files in `out`) that git ignores while it keeps the report
    beside them: the report does not link them, since a committed report would link files that
    are not committed. Where the report itself is ignored, or `out` lies outside a repository,
    every figure stays with it and none is returned."""
    if not names:
        return []
    try:
        found = subprocess.run(["git", "-C", str(out), "check-ignore", "--", REPORT_MD, *names],
                               capture_output=True, text=True)
    except OSError:
        return []
    if found.returncode not in (0, 1):  # not a repository
        return []
    ignored = {Path(line).name for line in found.stdout.splitlines()}
    if REPORT_MD in ignored:
        return []
    return [n for n in names if n in ignored]


def drop_figure_links(text: str, names: list[str]) -> str:
    """`text` without the figure blocks ('![..](NAME)', a blank line and the caption line) of `names`."""
    import re

    for name in names:
        text = re.sub(r"\n?!\[[^\]]*\]\(" + re.escape(name) + r"\)\n(\n[^\n]*\n)?", "\n", text)
    return text


def failure_lines(failures: list[Failure]) -> list[str]:
    """The report's lines for skipped or failed configurations, one per scene, strategy and reason."""
    grouped: dict[tuple, list[str]] = {}
    for f in failures:
        where = (f"{f.integrator}/{f.sampler}"
                 + (f"/{f.light_select}" if f.light_select != DEFAULT_LIGHT_SELECT else "")
                 + (f" at max depth {f.max_depth}" if f.max_depth is not None else ""))
        grouped.setdefault((f.scene, f.strategy, f.unavailable, f.message), []).append(where)
    lines = []
    for (scene, strategy, unavailable, message), where in grouped.items():
        kind = "not available in this mcrt build (for this scene), skipped" if unavailable else "**failed**"
        lines.append(f"- {scene}, {strategy} ({'; '.join(dict.fromkeys(where))}): {kind} — `{message}`")
    return lines


def scene_lines(scenes: list[SceneInfo]) -> list[str]:
    """The report's table of scene families and light solid angles (none when no scene has either)."""
    if not any(sc.family or sc.light_solid_angle is not None for sc in scenes):
        return []
    rows = [[sc.name, sc.family or "–", fmt(sc.family_param), fmt(sc.light_solid_angle)] for sc in scenes]
    return ["### Scenes\n",
            "Generated families (scene files in `scenes/` of this directory; see "
            "`scripts/mcrt_study/scenes.py`): size_* — light area relative to the Cornell box's 130×105 ceiling light; "
            "distance — light height over the floor relative to its size (130); tri_size — triangle area "
            "relative to the reference triangle's (equilateral, edge 1); tri_distance — its height over "
            "the floor in edges; tri_aspect — base / height relative to the equilateral's (slivers of "
            "the same area); tri_grazing — the cosine between its normal and straight down; "
            "many_lights — the number of emitters (12,800 triangles for the mesh). Solid angle (sr) of the "
            "first light seen from the box's centre (278, 278, 279.5), for the distance and triangle "
            "families from the floor point under the light, for many_lights the median over its "
            "emitting triangles seen from the floor point (0, 0, 0.5).\n",
            md_table(["scene", "family", "parameter", "light solid angle (sr)"], rows, 2)]


def write_report(settings: Settings, scenes: list[SceneInfo], tables: str,
                 figures: list[tuple[str, str]], started: datetime.datetime) -> None:
    """Write tables.md and the report README.md (relative links to the plots)."""
    out = settings.out
    # Only the figures that stay beside the report are linked (see unkept_figures).
    unkept = unkept_figures(out, [name for name, _ in figures])
    tables = drop_figure_links(tables, unkept)
    write_text_atomic(out / TABLES_MD, tables)
    info = machine_info()
    sources = RENDERER_SOURCES + (BENCH_SOURCES if settings.bench is not None and settings.bench.is_file() else [])
    renderer, changed = renderer_commit(out, sources)
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
        f"- Renderer: commit `{renderer}`" + (" with uncommitted changes to its sources" if changed else "")
        + f" (mcrt sha256 {mcrt_hash}…, run as `{repo_relative(str(settings.mcrt))}`)",
        f"- Machine: {machine_name(info['cpu'], info['cores'])}, {memory_gib()} GiB, {info['os']}; "
        f"render threads: {threads}",
        f"- Scenes: {', '.join(sc.name for sc in scenes)}",
        f"- Configurations ({len(settings.configs)}): integrators {', '.join(settings.integrators)}; "
        f"samplers {', '.join(settings.samplers)}; "
        + (f"light selections {', '.join(settings.light_selects)}; " if settings.varies_light_select else "")
        + f"strategies {', '.join(settings.strategies)}; in the depth modes {' and '.join(modes[m] for m in settings.depths)}",
        f"- Sweep: spp {', '.join(map(str, settings.spp))}; seeds {', '.join(map(str, settings.seeds))}; "
        "for each seed and spp every depth mode and configuration in turn",
        "- Time: `render_seconds` of `mcrt render --stats` (rendering only: no process start, "
        "no scene parsing, no image output)"
        + (f", the median of {settings.time_repeats} runs of each render" if settings.time_repeats > 1 else "")
        + ". Error: `mcrt diff --json` against the reference "
        "(relMSE as in pbrt: mean of (v−r)²/(r+0.01)²).",
        "- Efficiency: 1/(MSE × seconds) of each render; a configuration's is the geometric mean "
        "over its renders (every spp and seed), compared with the baseline "
        f"({config_text(base, settings.varies_light_select)}) of the same scene and depth mode.",
        f"- Data: [{RESULTS_CSV}]({RESULTS_CSV}) (one row per render), tables also in [{TABLES_MD}]({TABLES_MD}).\n",
    ]
    lines += scene_lines(scenes)
    lines += [
        "### References\n",
        "One reference per scene and depth mode with a seed the sweep does not use, shared by "
        "every configuration (all converge to the same image); the table gives the configuration "
        f"each was rendered with (this run's choice: integrator {settings.ref_integrator}, sampler "
        f"{settings.ref_sampler}, "
        + (f"light selection {settings.ref_light_select}, " if settings.ref_light_select != DEFAULT_LIGHT_SELECT
           else "")
        + ("solid-angle sampling where this mcrt build supports it, else area sampling"
           if settings.ref_strategy == "preferred" else f"{settings.ref_strategy} sampling")
        + "). Cached by scene content, resolution, spp, max depth, seed, strategy, integrator and sampler.\n",
    ]
    ref_rows = []
    ref_selects = False  # a light selection column when any reference has one of its own
    for scene, mode, depth in scene_panels(scenes, settings):
        s = state.get("runs", {}).get(state_key(scene, depth))
        if s:
            ref = s["reference"]
            select = ref.get("light_select", DEFAULT_LIGHT_SELECT)
            ref_selects = ref_selects or select != DEFAULT_LIGHT_SELECT
            ref_rows.append([scene, mode, ref.get("integrator", LEGACY_INTEGRATOR),
                             ref.get("sampler", LEGACY_SAMPLER), select, ref["strategy"],
                             f"{s['width']}×{s['height']}", str(depth), str(ref["spp"]), str(ref["seed"]),
                             fmt(ref.get("render_seconds", float("nan")), 4)])
    if ref_rows:
        header = ["scene", "mode", "integrator", "sampler", "light selection", "strategy", "resolution",
                  "max depth", "spp", "seed", "render time (s)"]
        if not ref_selects:
            header.pop(4)
            for row in ref_rows:
                row.pop(4)
        lines.append(md_table(header, ref_rows, len(header) - 5))
    if settings.failures:
        lines.append("### Skipped or failed\n")
        lines += failure_lines(settings.failures)
        lines.append("")
    lines.append("## Results\n")
    lines.append(tables)
    # Figures the tables already show (scene families, pixel maps) are not repeated.
    figures = [(name, caption) for name, caption in figures if f"]({name})" not in tables and name not in unkept]
    if figures or unkept:
        lines.append("\n## Plots\n")
        for name, caption in figures:
            lines.append(f"![{name}]({name})\n\n{caption}\n")
        if unkept:
            lines.append("Also written to this directory, not kept by git (so not linked): "
                         + ", ".join(f"`{name}`" for name in unkept) + ".\n")
    write_text_atomic(out / REPORT_MD, "\n".join(lines) + "\n")


def crossover_cell(entry: dict) -> str:
    """The crossings of one family series, with the family parameter there, or its verdict."""
    if not entry["crossings"]:
        return entry["verdict"]
    return "; ".join(f"{fmt(c, 3)} sr" + (f" ({fmt(p, 3)})" if math.isfinite(p) else "")
                     for c, p in zip(entry["crossings"], entry["params"]))


def family_section(found: list[dict], figures: list[tuple[str, str]]) -> str:
    """The report's section on scene families (from analysis.family_crossovers): the crossover
    table and the figures (plots.make_family_plots). Empty when the run has no family."""
    if not found:
        return ""
    from .analysis import family_param_label

    parts = [
        "\n## Scene families: crossovers\n\n"
        "Each strategy's efficiency over area sampling (same integrator, sampler and depth mode) on "
        "every member of a generated family, against the solid angle of the light (see Scenes). A "
        "crossover is where the ratio crosses 1, interpolated linearly in the ratio against log solid "
        "angle between neighbouring members; in brackets the family parameter there (log-log "
        "interpolation). Without one: always above (the strategy beats area sampling on every "
        "member), always below, none in range (it touches 1 without crossing), or no points.\n\n"]
    rows = []
    for f in found:
        r = f["series"]["ratio"]
        span = f"{fmt(min(r), 3)} – {fmt(max(r), 3)}" if r else "–"
        select = f.get("light_select", DEFAULT_LIGHT_SELECT)
        where = f"{f['mode']}, {f['integrator']}, {f['sampler']}" + (f", {select}" if select != DEFAULT_LIGHT_SELECT
                                                                      else "")
        rows.append([f["family"], where, f["strategy"],
                     str(len(r)), span, crossover_cell(f)])
    selects = any(f.get("light_select", DEFAULT_LIGHT_SELECT) != DEFAULT_LIGHT_SELECT for f in found)
    slice_header = "slice (depth, integrator, sampler" + (", light selection)" if selects else ")")
    parts.append(md_table(["family", slice_header, "strategy", "members",
                           "ratio range", "crossover solid angle (parameter)"], rows, 3))
    families = list(dict.fromkeys(f["family"] for f in found))
    parts.append("\nParameters: " + "; ".join(f"{fam}: {family_param_label(fam)}" for fam in families) + ".\n")
    for name, caption in figures:
        parts.append(f"\n![{name}]({name})\n\n{caption}\n")
    return "".join(parts)
