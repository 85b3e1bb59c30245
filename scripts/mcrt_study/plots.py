"""The study's figures (matplotlib)."""

from __future__ import annotations

import math

from .analysis import baseline_config, group_stats, mean_curve, slice_of
from .config import DEFAULT_LIGHT_SELECT, Config, STRATEGY_STYLE, Settings


def make_slice_plots(rows: list[dict], settings: Settings, scenes: list[str]) -> list[tuple[str, str]]:
    """Write the earlier study's PNG figures (area against solid angle) for the rows of its slice;
    return (file name, caption) pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker as ticker
    import numpy as np

    out = settings.out
    figures: list[tuple[str, str]] = []
    integrator, sampler, mode = slice_of(settings)
    slice_note = f"({integrator}, {sampler}, {mode} depth.)"
    stats = {(sc, s): group_stats(rows, scene=sc, strategy=s) for sc in scenes for s in settings.strategies}
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
        figures.append((name, f"{caption} {slice_note}"))

    def log_axes(ax) -> None:
        """Log-log axes labelled at 1, 2, 5 x 10^k in plain numbers."""
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(ticker.NullFormatter())

    def finish_panel(ax, title: str, xlabel: str, ylabel: str) -> None:
        """Log-log axes, labels, grid and legend of one scene's panel."""
        log_axes(ax)
        ax.set_title(title)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)

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
            finish_panel(ax, sc, "samples per pixel", ylabel)
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
        finish_panel(ax, sc, "render time (s)", "RMSE")
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
        finish_panel(ax, sc, "samples per pixel", "1 / (MSE · s)")
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


def make_efficiency_plots(analysis: dict, settings: Settings,
                          panels: list[tuple[str, str, int]]) -> list[tuple[str, str]]:
    """One figure per depth mode: per scene, the efficiency of every configuration as grouped
    bars (groups: integrator and sampler; bars: strategy; log scale; whiskers: ± one standard
    error). Returns (file name, caption) pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    figures: list[tuple[str, str]] = []
    base = baseline_config(settings)
    groups = [(i, m, ls) for i in settings.integrators for m in settings.samplers for ls in settings.light_selects]
    width = 0.8 / len(settings.strategies)
    for mode in settings.depths:
        mine = [(sc, d) for sc, m, d in panels if m == mode and analysis[(sc, d)]]
        if not mine:
            continue
        cols = 2 if len(mine) > 1 else 1
        nrows = (len(mine) + cols - 1) // cols
        panel_width = max(6.0, 0.5 * len(groups) * len(settings.strategies) + 2)
        fig, axes = plt.subplots(nrows, cols, figsize=(panel_width * cols, 4.4 * nrows), squeeze=False)
        for ax in axes.flat[len(mine):]:
            ax.set_visible(False)
        for ax, (scene, depth) in zip(axes.flat, mine):
            per = analysis[(scene, depth)]
            best = max((c for c in per if math.isfinite(per[c]["efficiency"])),
                       key=lambda c: per[c]["efficiency"], default=None)
            for k, strategy in enumerate(settings.strategies):
                xs, ys, lo, hi = [], [], [], []
                for g, (integrator, sampler, select) in enumerate(groups):
                    a = per.get(Config(strategy, integrator, sampler, select))
                    if a is None or not math.isfinite(a["efficiency"]):
                        continue
                    xs.append(g + (k - (len(settings.strategies) - 1) / 2) * width)
                    ys.append(a["efficiency"])
                    se = a["rel_se"] if math.isfinite(a["rel_se"]) else 0.0
                    lo.append(a["efficiency"] * se / (1 + se))
                    hi.append(a["efficiency"] * se)
                    if Config(strategy, integrator, sampler, select) == best:
                        ax.annotate("★", (xs[-1], a["efficiency"] * (1 + se)), ha="center", va="bottom",
                                    fontsize=12)
                style = STRATEGY_STYLE[strategy]
                ax.bar(xs, ys, width * 0.95, color=style["color"], label=style["label"],
                       yerr=np.array([lo, hi]), capsize=2, error_kw={"lw": 0.8})
            if base in per:
                ax.axhline(per[base]["efficiency"], color="k", ls="--", lw=0.8,
                           label=f"baseline ({base.integrator}, {base.sampler}, {base.strategy})")
            ax.set_yscale("log")
            ax.set_xticks(range(len(groups)))
            ax.set_xticklabels([f"{i}\n{m}" + (f"\n{ls}" if settings.varies_light_select else "")
                                for i, m, ls in groups], fontsize=8)
            ax.set_title(f"{scene} (max depth {depth})")
            ax.set_ylabel("efficiency 1 / (MSE · s)")
            ax.grid(True, axis="y", which="both", alpha=0.3)
            ax.legend(fontsize=7)
        fig.suptitle(f"Efficiency per configuration, {mode} {'illumination' if mode == 'global' else 'lighting'}")
        fig.tight_layout()
        name = f"efficiency_{mode}.png"
        fig.savefig(settings.out / name, dpi=110)
        plt.close(fig)
        figures.append((name, f"Efficiency 1/(MSE·time) of every configuration, {mode} depth mode: "
                              "geometric mean over spp and seeds (bars, log scale), ± one standard "
                              "error (whiskers, from the spread over seeds), the baseline (dashed) and the "
                              "best configuration (★). Higher is better."))
    return figures


def densify(x, y, steps: int = 24):
    """A polyline through (x, y) with `steps` points per segment, evenly spaced in log x and
    linear in y between the given points (x positive and increasing)."""
    import numpy as np

    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 2:
        return x, y
    t = np.linspace(0.0, 1.0, steps, endpoint=False)
    lx = np.log(x)
    xs = [np.exp(lx[i] + t * (lx[i + 1] - lx[i])) for i in range(len(x) - 1)]
    ys = [y[i] + t * (y[i + 1] - y[i]) for i in range(len(x) - 1)]
    return np.concatenate([*xs, x[-1:]]), np.concatenate([*ys, y[-1:]])


def family_figure_name(family: str, mode: str) -> str:
    """The file of a family's crossover figure in a depth mode."""
    return f"family_{family}_{mode}.png"


def make_family_plots(found: list[dict], settings: Settings) -> list[tuple[str, str]]:
    """One figure per scene family and depth mode (from analysis.family_crossovers): per integrator
    and sampler, each strategy's efficiency over area sampling against the light's solid angle (log
    x; band: ± one standard error where the analysis has one), the line at 1, and the crossings of
    1 marked with their solid angle; the top axis gives the family parameter of the members.
    Returns (file name, caption) pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker as ticker
    import numpy as np

    from .analysis import family_param_label

    figures: list[tuple[str, str]] = []
    for family, mode in dict.fromkeys((f["family"], f["mode"]) for f in found):
        mine = [f for f in found if (f["family"], f["mode"]) == (family, mode) and f["series"]["ratio"]]
        groups = list(dict.fromkeys((f["integrator"], f["sampler"], f.get("light_select", DEFAULT_LIGHT_SELECT))
                                    for f in mine))
        if not groups:
            continue
        cols = min(3, len(groups))
        nrows = (len(groups) + cols - 1) // cols
        fig, axes = plt.subplots(nrows, cols, figsize=(5.6 * cols, 4.4 * nrows), squeeze=False)
        for ax in axes.flat[len(groups):]:
            ax.set_visible(False)
        for ax, (integrator, sampler, select) in zip(axes.flat, groups):
            members: dict[float, float] = {}
            for f in mine:
                if (f["integrator"], f["sampler"], f.get("light_select", DEFAULT_LIGHT_SELECT)) != (integrator, sampler,
                                                                                                  select):
                    continue
                s = f["series"]
                order = np.argsort(s["solid_angle"])
                x = np.asarray(s["solid_angle"])[order]
                r = np.asarray(s["ratio"])[order]
                se = np.asarray(s["log_se"])[order]
                members.update(zip(s["solid_angle"], s["param"]))
                style = STRATEGY_STYLE.get(f["strategy"], {"color": None, "label": f["strategy"]})
                # Between members the ratio is drawn as the crossings are found: linear in the
                # ratio against log solid angle (a curve on these log axes).
                xd, rd = densify(x, r)
                line, = ax.plot(xd, rd, color=style["color"], label=style["label"])
                ax.plot(x, r, "o", ms=4, color=line.get_color())
                if np.any(np.isfinite(se)):
                    band = np.where(np.isfinite(se), se, 0.0)
                    _, lo = densify(x, r * np.exp(-band))
                    _, hi = densify(x, r * np.exp(band))
                    ax.fill_between(xd, lo, hi, color=line.get_color(), alpha=0.18, linewidth=0)
                for c in f["crossings"]:
                    ax.axvline(c, color=line.get_color(), ls=":", lw=0.9)
                    ax.plot([c], [1.0], marker="D", ms=7, mfc="white", mec=line.get_color(), mew=1.6, zorder=5)
                    ax.annotate(f"{c:.3g} sr", (c, 1.0), xytext=(5, -13), textcoords="offset points",
                                fontsize=8, color=line.get_color(), zorder=6,
                                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})
            ax.axhline(1.0, color="k", lw=0.9)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.yaxis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            ax.yaxis.set_minor_formatter(ticker.NullFormatter())
            ax.set_xlabel("light solid angle (sr)")
            ax.set_ylabel("efficiency / area sampling's")
            ax.set_title(f"{integrator}, {sampler}" + (f", {select}" if select != DEFAULT_LIGHT_SELECT else ""),
                         fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
            # The members' family parameter on a top axis at their solid angles.
            known = {x: p for x, p in members.items() if math.isfinite(p)}
            if known:
                top = ax.twiny()
                top.set_xscale("log")
                top.set_xlim(ax.get_xlim())
                top.set_xticks(sorted(known))
                top.set_xticklabels([f"{known[x]:g}" for x in sorted(known)], fontsize=7)
                top.xaxis.set_minor_locator(ticker.NullLocator())
                top.set_xlabel(family_param_label(family), fontsize=8)
        what = "global illumination" if mode == "global" else "direct lighting"
        fig.suptitle(f"{family}, {what}:\nefficiency over area sampling against the light's solid angle",
                     fontsize=11)
        fig.tight_layout()
        name = family_figure_name(family, mode)
        fig.savefig(settings.out / name, dpi=110)
        plt.close(fig)
        figures.append((name, f"{family}, {mode} depth mode: each strategy's efficiency 1/(MSE·time) over "
                              "area sampling's (same integrator and sampler) against the solid angle of the "
                              f"light (log axes; top axis: {family_param_label(family)}); band: ± one standard "
                              "error; diamonds: where a strategy crosses area sampling (above 1: better)."))
    return figures
