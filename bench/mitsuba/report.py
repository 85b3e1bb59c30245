"""Aggregation of the raw measurements and the markdown report.

Per (scene, renderer/config, spp): seconds and MSE are means over the seeds,
efficiency = 1 / (mean MSE x mean seconds); the ratios divide by Mitsuba's
efficiency at the same scene and spp, with its `independent` sampler and with
its best low-discrepancy sampler (the one with the highest geometric-mean
efficiency over the spp values of that scene)."""
import math
from collections import defaultdict

from . import validate


def aggregate(runs):
    groups = defaultdict(list)
    for r in runs:
        groups[(r["scene"], r["config"], r["spp"])].append(r)
    rows = []
    for (scene, config, spp), rs in groups.items():
        sec = sum(r["seconds"] for r in rs) / len(rs)
        mse = sum(r["mse"] for r in rs) / len(rs)
        rows.append({"scene": scene, "config": config, "renderer": rs[0]["renderer"], "spp": spp,
                     "seeds": len(rs), "seconds": sec, "mse": mse, "efficiency": 1 / (mse * sec),
                     "ref_noise_share": rs[0]["ref_noise_mse"] / mse,
                     "efficiency_per_seed": [1 / (r["mse"] * r["seconds"]) for r in rs],
                     "seconds_range": [min(r["seconds"] for r in rs), max(r["seconds"] for r in rs)]})
    best = {}
    for scene in {r["scene"] for r in rows}:
        ld = defaultdict(list)
        for r in rows:
            if r["scene"] == scene and r["renderer"] == "mitsuba" and r["config"] != "mitsuba:independent":
                ld[r["config"]].append(math.log(r["efficiency"]))
        best[scene] = max(ld, key=lambda c: sum(ld[c]) / len(ld[c])) if ld else None
    eff = {(r["scene"], r["config"], r["spp"]): r["efficiency"] for r in rows}
    for r in rows:
        ind = eff.get((r["scene"], "mitsuba:independent", r["spp"]))
        ld = eff.get((r["scene"], best[r["scene"]], r["spp"]))
        r["ratio_to_mitsuba_independent"] = r["efficiency"] / ind if ind else None
        r["ratio_to_mitsuba_best_ld"] = r["efficiency"] / ld if ld else None
    order = lambda r: (r["scene"], r["renderer"] != "mcrt", r["config"], r["spp"])
    return sorted(rows, key=order), best


def _f(x, fmt):
    return "—" if x is None else format(x, fmt)


def markdown(res):
    rows, best = res["table"], res["best_ld_sampler"]
    out = [f"# mcrt against Mitsuba {res['mitsuba_version']} (`path`, {res['mitsuba_variant']})", ""]
    out += [f"{k}: {v}" for k, v in res["setup_lines"].items()] + [""]
    out += ["## Validation: converged references (Mitsuba relative to mcrt)", "",
            "| scene | mean diff % | ± SE % | z | per channel % | RMSE / mean | expected from noise | ratio "
            "| ratio off light silhouettes | red wall (mcrt, Mitsuba) | agree |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for s, v in res["validation"].items():
        c = v["references"]
        out.append(f"| {s} | {c['mean_diff_percent']:+.3f} | {c['mean_diff_se_percent']:.3f} | {c['z']:+.2f} "
                   f"| {', '.join(f'{x:+.2f}' for x in c['channel_mean_diff_percent'])} "
                   f"| {c['rmse_over_mean']:.4f} | {c['expected_rmse_over_mean']:.4f} | {c['rmse_ratio']:.3f} "
                   f"| {_f(c.get('rmse_ratio_off_silhouettes'), '.3f')} "
                   f"({c.get('silhouette_pixels', '?')} px, {_f(c.get('silhouette_share_of_d2'), '.0%')} of the d²) "
                   f"| {c['red_wall_side']['mcrt']}, {c['red_wall_side']['mitsuba']} | {'yes' if c['agree'] else 'NO'} |")
    out += ["", "ratio: RMSE of the difference over the RMSE the two references' noise explains (1 = pure noise). "
            "Off light silhouettes: without the pixels that see part of a light (and their neighbours), where "
            "mcrt's camera shifts edges by ~1e-3 px (ray directions from absolute float positions). "
            f"Agree: |z| < {validate.Z_MAX:g}, ratio (off silhouettes) < {validate.RMSE_RATIO_MAX:g}, "
            "red wall on the same side."]
    out += ["", "## max_depth: image mean of mcrt --max-depth D against Mitsuba max_depth D+1 and D", "",
            "| scene | D | mcrt mean | Mitsuba D+1: diff % | Mitsuba D: diff % |", "|---|---|---|---|---|"]
    for s, v in res["validation"].items():
        for d in v["depth_check"]:
            a, b = d["mitsuba_D+1"], d["mitsuba_D"]
            out.append(f"| {s} | {d['mcrt_max_depth']} | {d['mcrt_mean']:.5f} | {a['diff_percent']:+.2f} "
                       f"| {_f(b and b['diff_percent'], '+.2f')} |")
    out += ["", "## Efficiency = 1 / (MSE × seconds), each renderer against its own reference", "",
            "| scene | renderer / config | spp | seconds | MSE | ref. noise in MSE | efficiency "
            "| × Mitsuba independent | × Mitsuba best LD |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['scene']} | {r['config']} | {r['spp']} | {r['seconds']:.3f} | {r['mse']:.4g} "
                   f"| {r['ref_noise_share']:.1%} | {r['efficiency']:.4g} | {_f(r['ratio_to_mitsuba_independent'], '.2f')} "
                   f"| {_f(r['ratio_to_mitsuba_best_ld'], '.2f')} |")
    out += ["", "seconds, MSE: means over the seeds; efficiency = 1 / (MSE × seconds). ref. noise in MSE: the "
            "share of the MSE that is the reference's own noise (estimated from its two halves)."]
    out += ["", "Best low-discrepancy Mitsuba sampler per scene: "
            + ", ".join(f"{s}: {b}" for s, b in sorted(best.items())), "",
            "## Geometric mean over spp of the efficiency ratio", "",
            "| scene | renderer / config | × Mitsuba independent | × Mitsuba best LD |", "|---|---|---|---|"]
    for (scene, config), (a, b) in summary(rows).items():
        out.append(f"| {scene} | {config} | {_f(a, '.2f')} | {_f(b, '.2f')} |")
    out += ["", "## Commands", "", "```"] + res["commands_summary"] + ["```", ""]
    return "\n".join(out)


def summary(rows):
    acc = defaultdict(lambda: ([], []))
    for r in rows:
        for i, k in enumerate(("ratio_to_mitsuba_independent", "ratio_to_mitsuba_best_ld")):
            if r[k]:
                acc[(r["scene"], r["config"])][i].append(math.log(r[k]))
    g = lambda xs: math.exp(sum(xs) / len(xs)) if xs else None
    return {k: (g(a), g(b)) for k, (a, b) in acc.items()}
