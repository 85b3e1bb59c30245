"""Unit tests of the study's analysis on synthetic data (known answers).

    .venv/bin/python -m unittest discover -s scripts/mcrt_study/tests -t scripts
"""

import math
import tempfile
import unittest
from pathlib import Path

import numpy as np

from mcrt_study.analysis import (
    analyse_configs, baseline_config, crossovers, default_budgets, efficiency_ratio,
    efficiency_summary, group_stats, interp_loglog, loglog_slope, mean_curve, pick, scene_panels,
    select_rows, slice_of, slice_rows,
)
from mcrt_study.config import Config, SceneInfo, build_parser, parse_int_list, resolve_settings
from mcrt_study.report import build_config_tables
from mcrt_study.runner import parse_bench

_OUT = tempfile.gettempdir()


def make_settings(*args: str):
    """Settings as the command line would make them (--report-only: no mcrt needed)."""
    argv = ["study.py", "--report-only", "--out", _OUT, *args]
    return resolve_settings(build_parser().parse_args(argv[1:]), argv)


def scene(name: str, max_depth: int) -> SceneInfo:
    return SceneInfo(name=name, path=Path(f"/nowhere/{name}.json"), content_sha256="0" * 64,
                     width=8, height=8, max_depth=max_depth)


def row(scene_name: str, config: Config, max_depth: int, spp: int, seed: int, mse: float,
        seconds: float) -> dict:
    return {"scene": scene_name, "strategy": config.strategy, "integrator": config.integrator,
            "sampler": config.sampler, "max_depth": max_depth, "spp": spp, "seed": seed,
            "seconds": seconds, "rmse": math.sqrt(mse), "mse": mse, "relmse": 2 * mse}


BASE = Config("area", "mixture", "independent")
SA = Config("solid-angle", "mixture", "independent")
# Seed noise: seed 1 has 1/1.2 times the MSE, seed 2 1.2 times.
SEED_FACTOR = {1: 1 / 1.2, 2: 1.2}


def two_config_rows(spps=(4, 16, 64), depth=5) -> list[dict]:
    """Baseline: MSE = 1/spp, time = 0.01 spp (efficiency 100); solid angle: MSE = 0.5/spp,
    time = 0.005 spp (efficiency 400); both times the seed factor on the MSE."""
    rows = []
    for spp in spps:
        for seed, f in SEED_FACTOR.items():
            rows.append(row("s", BASE, depth, spp, seed, f / spp, 0.01 * spp))
            rows.append(row("s", SA, depth, spp, seed, 0.5 * f / spp, 0.005 * spp))
    return rows


class LoglogSlopeTest(unittest.TestCase):
    def test_power_law_mse_gives_its_exponent(self):
        spp = np.array([4, 8, 16, 32, 64, 128], float)
        for k in (0.5, 1.0, 1.5, 2.0):
            mse = 3.0 * spp ** -k
            self.assertAlmostEqual(loglog_slope(spp, mse), -k, places=10)
            self.assertAlmostEqual(loglog_slope(spp, np.sqrt(mse)), -k / 2, places=10)

    def test_least_squares_through_noise(self):
        # log y = -1 * log x + (+e, -e, +e, -e): symmetric noise, slope fitted to a known value.
        x = np.exp([0.0, 1.0, 2.0, 3.0])
        y = np.exp(-np.log(x) + np.array([0.1, -0.1, 0.1, -0.1]))
        # Least squares: slope = -1 + sum((lx - 1.5) e) / sum((lx - 1.5)^2), with
        # sum((lx - 1.5) e) = (-1.5)(0.1) + (-0.5)(-0.1) + (0.5)(0.1) + (1.5)(-0.1) = -0.2 and
        # sum((lx - 1.5)^2) = 5: slope = -1 - 0.04.
        self.assertAlmostEqual(loglog_slope(x, y), -1.04, places=10)

    def test_points_that_cannot_be_logged_are_left_out(self):
        x = [1, 2, 4, 8, 16]
        y = [1.0, 0.0, 0.25, float("nan"), 1 / 16]
        self.assertAlmostEqual(loglog_slope(x, y), -1.0, places=10)

    def test_too_few_points_is_nan(self):
        self.assertTrue(math.isnan(loglog_slope([4], [1.0])))
        self.assertTrue(math.isnan(loglog_slope([4, 8], [1.0, 0.0])))
        self.assertTrue(math.isnan(loglog_slope([4, 4, 4], [1.0, 2.0, 3.0])))


class EqualTimeTest(unittest.TestCase):
    # A made-up error against time curve: error = 2 t^-1/2, which is a straight line in log-log,
    # so interpolation at any time inside the range is exact.
    T = [1.0, 4.0, 16.0]
    E = [2.0, 1.0, 0.5]

    def test_interpolation_at_equal_time(self):
        self.assertAlmostEqual(interp_loglog(2.0, self.T, self.E), math.sqrt(2.0), places=12)
        self.assertAlmostEqual(interp_loglog(8.0, self.T, self.E), 1 / math.sqrt(2.0), places=12)
        self.assertAlmostEqual(interp_loglog(4.0, self.T, self.E), 1.0, places=12)
        self.assertAlmostEqual(interp_loglog(1.0, self.T, self.E), 2.0, places=12)
        self.assertAlmostEqual(interp_loglog(16.0, self.T, self.E), 0.5, places=12)

    def test_interpolation_is_log_log_not_linear(self):
        # Between (1, 1) and (100, 0.01) the log-log midpoint is (10, 0.1); linear would give 0.91.
        self.assertAlmostEqual(interp_loglog(10.0, [1.0, 100.0], [1.0, 0.01]), 0.1, places=12)

    def test_unsorted_input(self):
        self.assertAlmostEqual(interp_loglog(2.0, self.T[::-1], self.E[::-1]), math.sqrt(2.0), places=12)

    def test_outside_the_data_is_nan(self):
        self.assertTrue(math.isnan(interp_loglog(0.5, self.T, self.E)))
        self.assertTrue(math.isnan(interp_loglog(17.0, self.T, self.E)))
        self.assertTrue(math.isnan(interp_loglog(1.0, [1.0], [2.0])))

    def test_default_budgets_span_the_common_times(self):
        curves = {"a": ([1.0, 10.0, 100.0], [1, 1, 1]), "b": ([2.0, 20.0, 50.0], [1, 1, 1])}
        budgets = default_budgets(curves)
        self.assertEqual(len(budgets), 4)
        self.assertAlmostEqual(budgets[0], 2.0 * 1.0001, places=12)
        self.assertAlmostEqual(budgets[-1], 50.0 * 0.9999, places=12)
        ratios = [b / a for a, b in zip(budgets, budgets[1:])]
        for r in ratios:
            self.assertAlmostEqual(r, ratios[0], places=12)  # log-spaced
        for t, e in curves.values():
            self.assertTrue(all(math.isfinite(interp_loglog(b, t, e)) for b in budgets))
        self.assertEqual(len(default_budgets(curves, 3)), 3)

    def test_no_common_time_no_budgets(self):
        self.assertEqual(default_budgets({"a": ([1.0, 2.0], [1, 1]), "b": ([3.0, 4.0], [1, 1])}), [])


class CrossoversTest(unittest.TestCase):
    def assertPositions(self, got, expected):
        self.assertEqual(len(got), len(expected), got)
        for g, e in zip(got, expected):
            self.assertAlmostEqual(g, e, places=10)

    def test_two_crossings_at_known_points(self):
        x = [1, 2, 4, 8, 16]
        r = [0.5, 1.5, 1.5, 0.5, 0.5]
        # Half way in the ratio, half way in log x: sqrt(1 * 2) and sqrt(4 * 8).
        self.assertPositions(crossovers(x, r), [math.sqrt(2.0), math.sqrt(32.0)])

    def test_interpolation_is_linear_in_log_x(self):
        # A quarter of the way from 0.9 to 1.3: 10^(1 + 2/4); linear in x would give 257.5.
        self.assertPositions(crossovers([10.0, 1000.0], [0.9, 1.3]), [10 ** 1.5])

    def test_no_crossing(self):
        self.assertEqual(crossovers([1, 2, 4], [1.5, 2.0, 1.1]), [])
        self.assertEqual(crossovers([1, 2, 4], [0.5, 0.9, 0.99]), [])
        self.assertEqual(crossovers([], []), [])

    def test_touching_is_not_crossing(self):
        self.assertEqual(crossovers([1, 2, 4], [0.5, 1.0, 0.5]), [])
        self.assertEqual(crossovers([1, 2, 4], [1.5, 1.0, 1.5]), [])
        self.assertEqual(crossovers([1, 2], [1.0, 2.0]), [])  # starts at 1
        self.assertEqual(crossovers([1, 2], [2.0, 1.0]), [])  # ends at 1

    def test_crossing_through_exactly_one(self):
        self.assertPositions(crossovers([1, 2, 4], [0.5, 1.0, 2.0]), [2.0])
        self.assertPositions(crossovers([1, 2, 4, 8], [2.0, 1.0, 1.0, 0.5]), [2.0])

    def test_unsorted_and_missing_values(self):
        # Sorted: (1, 0.5), (2, nan: left out), (4, 1.5) -> half way in log x between 1 and 4.
        self.assertPositions(crossovers([4, 1, 2], [1.5, 0.5, float("nan")]), [2.0])


class GroupStatsTest(unittest.TestCase):
    def test_per_spp_arrays_in_seed_order(self):
        rows = [row("s", BASE, 5, 16, 2, 0.2, 2.0), row("s", BASE, 5, 4, 1, 0.4, 0.5),
                row("s", BASE, 5, 16, 1, 0.1, 1.0), row("s", SA, 5, 16, 1, 9.0, 9.0),
                row("t", BASE, 5, 16, 1, 9.0, 9.0)]
        st = group_stats(rows, scene="s", strategy="area")
        self.assertEqual(st["spp"].tolist(), [4.0, 16.0])
        self.assertEqual(st["seeds"], [[1], [1, 2]])
        self.assertEqual(st["mse"][1].tolist(), [0.1, 0.2])
        self.assertEqual(st["seconds"][1].tolist(), [1.0, 2.0])
        mean, lo, hi = mean_curve(st, "seconds")
        self.assertEqual(mean.tolist(), [0.5, 1.5])
        self.assertEqual(lo.tolist(), [0.5, 1.0])
        self.assertEqual(hi.tolist(), [0.5, 2.0])
        self.assertEqual(len(group_stats(rows, scene="nothing")["spp"]), 0)


class EfficiencySummaryTest(unittest.TestCase):
    @staticmethod
    def stats(spp, mse, seconds):
        return {"spp": np.array(spp, float), "mse": [np.array(m, float) for m in mse],
                "seconds": [np.array(t, float) for t in seconds]}

    def test_geometric_mean_and_seed_spread(self):
        # Efficiency 100 times 1.2^(+-1) at each of three spp: geometric mean 100, log spread
        # L = log 1.2 about each spp's mean, pooled over 3 degrees of freedom:
        # s.e. = sqrt(6 L^2 / 3 / 6) = L / sqrt(3).
        spp = [4, 16, 64]
        s = self.stats(spp, [[1.2 / n, 1 / (1.2 * n)] for n in spp], [[0.01 * n] * 2 for n in spp])
        summary = efficiency_summary(s)
        self.assertEqual(summary["n"], 6)
        self.assertAlmostEqual(summary["efficiency"], 100.0, places=9)
        self.assertAlmostEqual(summary["rel_se"], math.expm1(math.log(1.2) / math.sqrt(3)), places=12)

    def test_one_seed_scatter_about_a_line_in_log_spp(self):
        # log spp = 0, 1, 2 and log efficiency = c + (0, 1, 0): the fitted line is flat at c + 1/3,
        # residuals -1/3, 2/3, -1/3, one degree of freedom: s.e. = sqrt((2/3) / 1 / 3) = sqrt(2)/3.
        spp = [1.0, math.e, math.e ** 2]
        mse = [[1.0 / 5.0], [math.exp(-1.0) / 5.0], [1.0 / 5.0]]
        s = self.stats(spp, mse, [[1.0]] * 3)
        summary = efficiency_summary(s)
        self.assertEqual(summary["n"], 3)
        self.assertAlmostEqual(summary["efficiency"], 5.0 * math.exp(1 / 3), places=10)
        self.assertAlmostEqual(summary["rel_se"], math.expm1(math.sqrt(2) / 3), places=10)

    def test_no_spread_available(self):
        s = self.stats([4, 16], [[0.25], [0.0625]], [[1.0], [4.0]])  # one seed, two spp
        summary = efficiency_summary(s)
        self.assertAlmostEqual(summary["efficiency"], 4.0, places=12)
        self.assertTrue(math.isnan(summary["rel_se"]))

    def test_renders_without_error_are_left_out(self):
        s = self.stats([4, 16], [[0.0], [0.0625]], [[1.0], [4.0]])
        summary = efficiency_summary(s)
        self.assertEqual(summary["n"], 1)
        self.assertAlmostEqual(summary["efficiency"], 4.0, places=12)
        empty = efficiency_summary(self.stats([], [], []))
        self.assertEqual(empty["n"], 0)
        self.assertTrue(math.isnan(empty["efficiency"]))


class ConfigAnalysisTest(unittest.TestCase):
    def setUp(self):
        self.settings = make_settings("--scenes", "s", "--strategies", "area", "solid-angle",
                                      "--integrators", "mixture", "--samplers", "independent",
                                      "--depths", "global", "--spp", "4", "16", "64", "--seeds", "1", "2")
        self.panels = scene_panels([scene("s", 5)], self.settings)
        self.analysis = analyse_configs(two_config_rows(), self.settings, self.panels)

    def test_panels(self):
        self.assertEqual(self.panels, [("s", "global", 5)])

    def test_efficiency_slope_and_cost(self):
        per = self.analysis[("s", 5)]
        self.assertEqual(set(per), {BASE, SA})
        self.assertAlmostEqual(per[BASE]["efficiency"], 100.0, places=9)
        self.assertAlmostEqual(per[SA]["efficiency"], 400.0, places=9)
        self.assertEqual(per[BASE]["n"], 6)
        expected_se = math.expm1(math.log(1.2) / math.sqrt(3))
        self.assertAlmostEqual(per[BASE]["rel_se"], expected_se, places=12)
        self.assertAlmostEqual(per[BASE]["slope"], -0.5, places=10)  # RMSE ~ spp^-1/2
        self.assertAlmostEqual(per[SA]["slope"], -0.5, places=10)
        self.assertAlmostEqual(per[BASE]["ms_per_spp"], 10.0, places=9)
        self.assertAlmostEqual(per[SA]["ms_per_spp"], 5.0, places=9)

    def test_ratios_against_the_baseline(self):
        base = baseline_config(self.settings)
        self.assertEqual(base, BASE)
        self.assertAlmostEqual(efficiency_ratio(self.analysis, base, "s", 5, SA), 4.0, places=9)
        self.assertAlmostEqual(efficiency_ratio(self.analysis, base, "s", 5, BASE), 1.0, places=12)
        other = Config("solid-angle", "mis", "sobol")
        self.assertTrue(math.isnan(efficiency_ratio(self.analysis, base, "s", 5, other)))
        self.assertTrue(math.isnan(efficiency_ratio(self.analysis, other, "s", 5, SA)))

    def test_tables_best_ratio_and_equal_time_gain(self):
        text, summary = build_config_tables(self.analysis, self.settings, self.panels)
        self.assertEqual(summary["best"][("s", 5)], SA)
        self.assertAlmostEqual(summary["efficiency"][("s", 5)][SA], 400.0, places=9)
        self.assertAlmostEqual(summary["config_slopes"][("s", 5, BASE)], -0.5, places=10)
        # Overview: ratio to the baseline, the best in bold.
        self.assertIn("| mixture | independent | area | 1 |\n", text)
        self.assertIn("| mixture | independent | solid-angle | **4** |\n", text)
        # Equal time: MSE = 0.01/t (baseline) and 0.0025/t (solid angle) at every budget,
        # so baseline MSE / MSE is 4 (the seed factor is the same for both).
        equal_time = text.split("### Equal time by configuration")[1].split("### Convergence rate")[0]
        lines = [ln for ln in equal_time.splitlines() if ln.startswith("| mixture")]
        self.assertEqual(len(lines), 2)
        self.assertTrue(lines[0].startswith("| mixture | independent | area |") and lines[0].endswith("| 1 |"))
        self.assertTrue(lines[1].startswith("| mixture | independent | solid-angle |")
                        and lines[1].endswith("| 4 |"))


class SelectionTest(unittest.TestCase):
    def test_scene_panels_depth_mode_first_without_repeated_depths(self):
        settings = make_settings("--depths", "global", "direct")
        panels = scene_panels([scene("a", 5), scene("b", 1)], settings)
        # b's global depth is 1 already: its direct mode is the same render and left out.
        self.assertEqual(panels, [("a", "global", 5), ("b", "global", 1), ("a", "direct", 1)])

    def test_baseline_and_slice_fall_back_to_the_first_selected(self):
        default = make_settings()
        self.assertEqual(baseline_config(default), Config("area", "mixture", "independent"))
        self.assertEqual(slice_of(default), ("mixture", "independent", "global"))
        other = make_settings("--strategies", "solid-angle", "projected-solid-angle",
                              "--integrators", "mis", "nee", "--samplers", "sobol", "--depths", "direct")
        # Axes are put in canonical order: nee before mis.
        self.assertEqual(baseline_config(other), Config("solid-angle", "nee", "sobol"))
        self.assertEqual(slice_of(other), ("nee", "sobol", "direct"))
        self.assertEqual(pick(["x", "y"], "y"), "y")
        self.assertEqual(pick(["x", "y"], "z"), "x")

    def test_select_and_slice_rows(self):
        settings = make_settings("--strategies", "area", "solid-angle", "--integrators", "mixture", "mis",
                                 "--samplers", "independent", "--depths", "global", "direct",
                                 "--spp", "4", "16", "--seeds", "1")
        sc = scene("s", 5)
        mis = Config("area", "mis", "independent")
        keep = [row("s", BASE, 5, 4, 1, 1, 1), row("s", SA, 1, 16, 1, 1, 1), row("s", mis, 5, 4, 1, 1, 1)]
        drop = [row("s", BASE, 5, 8, 1, 1, 1),  # spp not selected
                row("s", BASE, 5, 4, 2, 1, 1),  # seed not selected
                row("s", BASE, 3, 4, 1, 1, 1),  # depth of no mode
                row("t", BASE, 5, 4, 1, 1, 1),  # scene not selected
                row("s", Config("area", "nee", "independent"), 5, 4, 1, 1, 1)]  # integrator
        self.assertEqual(select_rows(keep + drop, settings, [sc]), keep)
        # The slice: mixture, independent, global depth.
        self.assertEqual(slice_rows(keep, settings, [sc]), [keep[0]])


class ParseTest(unittest.TestCase):
    def test_int_lists(self):
        self.assertEqual(parse_int_list(["4", "8,16", "32:128:32", "1:3"]), [4, 8, 16, 32, 64, 96, 128, 1, 2, 3])
        with self.assertRaises(Exception):
            parse_int_list(["1:2:3:4"])
        with self.assertRaises(Exception):
            parse_int_list(["1:5:0"])

    def test_sampler_benchmark_ns_per_sample(self):
        data = {"benchmarks": [
            # 10 samples per iteration of 100 ns: 10 ns per sample.
            {"name": "BM_SampleRectSolidAngle", "run_type": "iteration", "time_unit": "ns",
             "cpu_time": 100.0, "real_time": 120.0, "items_per_second": 1e8},
            # Repetitions: the median, not the mean, is used.
            {"name": "BM_SampleRectArea_median", "run_name": "BM_SampleRectArea", "run_type": "aggregate",
             "aggregate_name": "median", "time_unit": "us", "cpu_time": 0.002, "real_time": 0.003},
            {"name": "BM_SampleRectArea_mean", "run_name": "BM_SampleRectArea", "run_type": "aggregate",
             "aggregate_name": "mean", "time_unit": "us", "cpu_time": 9.0, "real_time": 9.0},
        ]}
        out = parse_bench(data)
        self.assertEqual([b["name"] for b in out], ["BM_SampleRectArea", "BM_SampleRectSolidAngle"])
        self.assertAlmostEqual(out[0]["cpu_ns"], 2.0, places=9)
        self.assertAlmostEqual(out[0]["real_ns"], 3.0, places=9)
        self.assertAlmostEqual(out[1]["cpu_ns"], 10.0, places=9)
        self.assertAlmostEqual(out[1]["real_ns"], 12.0, places=9)


if __name__ == "__main__":
    unittest.main()
