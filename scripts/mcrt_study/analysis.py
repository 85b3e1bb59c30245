"""Analysis of the points: selection, per-spp statistics, efficiency, equal-time interpolation, slopes."""

from __future__ import annotations

import itertools
import math

from .config import (
    BASELINE, DEFAULT_LIGHT_SELECT, Config, LEGACY_INTEGRATOR, LEGACY_SAMPLER, SceneInfo, Settings, config_of,
)


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
    """The configuration the others are compared with: area, mixture, independent, the default
    light selection (or the first selected value of an axis that lacks it)."""
    return Config(pick(settings.strategies, BASELINE.strategy), pick(settings.integrators, BASELINE.integrator),
                  pick(settings.samplers, BASELINE.sampler), pick(settings.light_selects, BASELINE.light_select))


def slice_of(settings: Settings) -> tuple[str, str, str]:
    """(integrator, sampler, depth mode) of the area-vs-solid-angle tables and plots of the
    earlier study: mixture, independent, global (or the first selected value of an axis that
    lacks it)."""
    return (pick(settings.integrators, LEGACY_INTEGRATOR), pick(settings.samplers, LEGACY_SAMPLER),
            pick(settings.depths, "global"))


def slice_rows(rows: list[dict], settings: Settings, scenes: list[SceneInfo]) -> list[dict]:
    """The rows of the earlier study's slice (see slice_of), with the baseline's light selection."""
    integrator, sampler, mode = slice_of(settings)
    depth = {sc.name: sc.depth(mode) for sc in scenes}
    select = baseline_config(settings).light_select
    return [r for r in rows if r["integrator"] == integrator and r["sampler"] == sampler
            and r["max_depth"] == depth.get(r["scene"])
            and (r.get("light_select") or DEFAULT_LIGHT_SELECT) == select]


def group_stats(rows: list[dict], **match):
    """Per spp, over the rows whose fields equal `match`: arrays over seeds of seconds, rmse,
    mse, relmse (numpy), sorted by spp."""
    import numpy as np

    def field(r: dict, k: str):
        # Rows made before the light selection was recorded have the default one.
        return (r.get(k) or DEFAULT_LIGHT_SELECT) if k == "light_select" else r[k]

    by_spp: dict[int, list[dict]] = {}
    for r in rows:
        if all(field(r, k) == v for k, v in match.items()):
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
                             integrator=config.integrator, sampler=config.sampler,
                             light_select=config.light_select)
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


def efficiency_ratio(analysis: dict, base: Config, scene: str, depth: int, config: Config) -> float:
    """A configuration's efficiency over the baseline's, in one scene and max depth (from
    analyse_configs); nan when either has no points."""
    per = analysis[(scene, depth)]
    if config not in per or base not in per:
        return float("nan")
    return per[config]["efficiency"] / per[base]["efficiency"]


def crossovers(x, ratio) -> list[float]:
    """The x positions where a ratio series crosses 1 (e.g. the spp or time at which one
    configuration overtakes another), in increasing x.

    Between two points on opposite sides of 1 the crossing is interpolated linearly in
    the ratio against log x. A point exactly at 1 between points on opposite sides is a
    crossing at its x (a run of such points: at the first one); a series that only
    touches 1 (the same side before and after), or starts or ends at 1, does not cross.
    Points with a non-finite value or x <= 0 are left out.
    """
    import numpy as np

    x, r = np.asarray(x, float), np.asarray(ratio, float)
    ok = np.isfinite(x) & np.isfinite(r) & (x > 0)
    x, r = x[ok], r[ok]
    order = np.argsort(x, kind="stable")
    x, r = x[order], r[order]
    side = np.sign(r - 1.0)
    found: list[float] = []
    last = None  # index of the last point off 1
    for i in range(len(x)):
        if side[i] == 0:
            continue
        if last is not None and side[i] != side[last]:
            if last == i - 1:
                t = (1.0 - r[last]) / (r[i] - r[last])
                found.append(float(np.exp(np.log(x[last]) + t * (np.log(x[i]) - np.log(x[last])))))
            else:
                found.append(float(x[last + 1]))
        last = i
    return found


# --------------------------------------------------------------------------
# Scene families: each strategy's efficiency over area sampling against the
# light's solid angle, and where it crosses 1.
# --------------------------------------------------------------------------

FAMILY_PARAM_LABELS = {"size_rect": "light area / seed's", "size_disk": "light area / seed's",
                       "size_sphere": "projected area / seed's", "distance": "h / light size",
                       "tri_size": "triangle area / reference's", "tri_distance": "h / triangle edge",
                       "tri_aspect": "aspect (base / height vs equilateral)",
                       "tri_grazing": "cos(normal, down)", "many_lights": "emitters"}


def family_param_label(family: str) -> str:
    """What a family's parameter is, for axes and tables."""
    return FAMILY_PARAM_LABELS.get(family, "family parameter")


def run_families(scenes: list[SceneInfo]) -> dict[str, list[SceneInfo]]:
    """The generated families of this run's scenes (first appearance order), each with its members
    that have a light solid angle, in increasing solid angle."""
    families: dict[str, list[SceneInfo]] = {}
    for sc in scenes:
        if sc.family and sc.light_solid_angle is not None and sc.light_solid_angle > 0:
            families.setdefault(sc.family, []).append(sc)
    return {f: sorted(m, key=lambda sc: sc.light_solid_angle) for f, m in families.items()}


def ratio_with_se(per: dict, base: Config, config: Config) -> tuple[float, float]:
    """A configuration's efficiency over the baseline's in one (scene, depth) of analyse_configs,
    and the standard error of its log (nan when either efficiency lacks one): the two
    geometric means' log standard errors added in quadrature."""
    if config not in per or base not in per:
        return float("nan"), float("nan")
    a, b = per[config], per[base]
    ratio = a["efficiency"] / b["efficiency"] if b["efficiency"] > 0 else float("nan")
    se = [math.log1p(x["rel_se"]) for x in (a, b)]
    return ratio, (math.hypot(*se) if all(math.isfinite(s) for s in se) else float("nan"))


def family_series(analysis: dict, members: list[SceneInfo], mode: str, base: Config, config: Config) -> dict:
    """One strategy's efficiency over area sampling across a family's members (in the order given),
    in one depth mode: solid angles, family parameters, ratios and the ratios' log standard
    errors (lists; members without points left out)."""
    series: dict[str, list] = {"scene": [], "solid_angle": [], "param": [], "ratio": [], "log_se": []}
    for sc in members:
        per = analysis.get((sc.name, sc.depth(mode)), {})
        ratio, se = ratio_with_se(per, base, config)
        if not math.isfinite(ratio):
            continue
        series["scene"].append(sc.name)
        series["solid_angle"].append(float(sc.light_solid_angle))
        series["param"].append(float(sc.family_param) if sc.family_param is not None else float("nan"))
        series["ratio"].append(ratio)
        series["log_se"].append(se)
    return series


def crossover_verdict(x, ratio) -> tuple[list[float], str]:
    """The crossings of 1 (analysis.crossovers) and a word for a series without one: 'always
    above' or 'always below' (every point on one side of 1), 'none in range' (it touches 1 without
    crossing), 'no points'. The word is '' when there are crossings."""
    import numpy as np

    found = crossovers(x, ratio)
    if found:
        return found, ""
    x, r = np.asarray(x, float), np.asarray(ratio, float)
    r = r[np.isfinite(r) & np.isfinite(x) & (x > 0)]
    if not len(r):
        return [], "no points"
    if np.all(r > 1):
        return [], "always above"
    if np.all(r < 1):
        return [], "always below"
    return [], "none in range"


def interp_param(solid_angle: float, solid_angles, params) -> float:
    """The family parameter at a solid angle, interpolated linearly in log-log between the members
    (nan outside them, or when a parameter is missing)."""
    import numpy as np

    x, p = np.asarray(solid_angles, float), np.asarray(params, float)
    if not np.all(np.isfinite(p) & (p > 0)):
        return float("nan")
    return interp_loglog(solid_angle, x, p)


def family_crossovers(analysis: dict, settings: Settings, scenes: list[SceneInfo]) -> list[dict]:
    """Per family of the run, depth mode, integrator, sampler, light selection and strategy other
    than area (area of the same integrator, sampler and light selection the baseline): its series
    (family_series), crossings of 1 in solid angle with the family parameter there, and the
    verdict (crossover_verdict).

    Empty when area sampling is not among the strategies.
    """
    if "area" not in settings.strategies:
        return []
    found = []
    for family, members in run_families(scenes).items():
        for mode in settings.depths:
            for integrator, sampler, select in itertools.product(settings.integrators, settings.samplers,
                                                                 settings.light_selects):
                base = Config("area", integrator, sampler, select)
                for strategy in settings.strategies:
                    if strategy == "area":
                        continue
                    series = family_series(analysis, members, mode, base, Config(strategy, integrator, sampler, select))
                    crossings, verdict = crossover_verdict(series["solid_angle"], series["ratio"])
                    found.append({
                        "family": family, "mode": mode, "integrator": integrator, "sampler": sampler,
                        "light_select": select, "strategy": strategy, "series": series, "crossings": crossings,
                        "params": [interp_param(c, series["solid_angle"], series["param"]) for c in crossings],
                        "verdict": verdict,
                    })
    return found
