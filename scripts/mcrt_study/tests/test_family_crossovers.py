"""Unit tests of the scene families' crossover table and figures on synthetic rows (known answers).

    .venv/bin/python -m unittest discover -s scripts/mcrt_study/tests -t scripts
"""

import math
import tempfile
import unittest
from pathlib import Path

from mcrt_study.analysis import (
    analyse_configs, crossover_verdict, family_crossovers, family_series, interp_param, run_families,
    scene_panels,
)
from mcrt_study.config import Config, SceneInfo, build_parser, resolve_settings
from mcrt_study.plots import family_figure_name, make_family_plots
from mcrt_study.report import family_section

DEPTH = 5
SEED_FACTOR = {1: 1 / 1.2, 2: 1.2}
# size_rect: the solid-angle strategy's efficiency ratio over area is 1 + 0.5 log10(omega / 0.2),
# linear in log solid angle, so it crosses 1 at 0.2 sr exactly (between the members at 0.1 and 1).
RECT_OMEGAS = [0.01, 0.1, 1.0, 3.0]
RECT_CROSSING = 0.2
# distance: omega = 1 / param^2 (param = h / size), the ratio 1 + 0.5 log10(omega / 0.1): the
# crossing at 0.1 sr is at h / size = sqrt(10).
DIST_PARAMS = [0.1, 1.0, 10.0]
DIST_CROSSING = 0.1


def make_settings(out: str, *args: str):
    argv = ["study.py", "--report-only", "--out", out, "--depths", "global", "--integrators", "mixture",
            "--samplers", "independent", "--spp", "4", "16", "--seeds", "1", "2", *args]
    return resolve_settings(build_parser().parse_args(argv[1:]), argv)


def member(name: str, family: str, param: float, omega: float) -> SceneInfo:
    return SceneInfo(name=name, path=Path(f"/nowhere/{name}.json"), content_sha256="0" * 64, width=8,
                     height=8, max_depth=DEPTH, family=family, family_param=param, light_solid_angle=omega)


def rows_for(scene: str, ratios: dict[str, float]) -> list[dict]:
    """Area: MSE 1/spp, time 0.01 spp (efficiency 100); strategy s: efficiency 100 ratios[s]."""
    rows = []
    for strategy, r in {"area": 1.0, **ratios}.items():
        for spp in (4, 16):
            for seed, f in SEED_FACTOR.items():
                mse = f / (spp * r)
                rows.append({"scene": scene, "strategy": strategy, "integrator": "mixture",
                             "sampler": "independent", "max_depth": DEPTH, "spp": spp, "seed": seed,
                             "seconds": 0.01 * spp, "rmse": math.sqrt(mse), "mse": mse, "relmse": mse})
    return rows


def synthetic():
    scenes, rows = [], []
    for i, omega in enumerate(RECT_OMEGAS):
        sc = member(f"size_rect_m{i}", "size_rect", omega * 10, omega)
        scenes.append(sc)
        rows += rows_for(sc.name, {"solid-angle": 1 + 0.5 * math.log10(omega / RECT_CROSSING),
                                   "projected-solid-angle": 2.0, "auto": 0.5})
    for p in DIST_PARAMS:
        sc = member(f"distance_h{p:g}", "distance", p, 1 / p ** 2)
        scenes.append(sc)
        rows += rows_for(sc.name, {"solid-angle": 1 + 0.5 * math.log10(sc.light_solid_angle / DIST_CROSSING),
                                   "projected-solid-angle": 1.0 if p == 1.0 else 1.5, "auto": 0.5})
    # A scene outside any family is left out.
    scenes.append(SceneInfo(name="plain", path=Path("/nowhere/plain.json"), content_sha256="0" * 64,
                            width=8, height=8, max_depth=DEPTH, light_solid_angle=0.5))
    rows += rows_for("plain", {"solid-angle": 3.0, "projected-solid-angle": 3.0, "auto": 3.0})
    return scenes, rows


class FamilyCrossoverTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.settings = make_settings(self.tmp.name, "--strategies", "area", "solid-angle",
                                      "projected-solid-angle", "auto")
        self.scenes, rows = synthetic()
        self.analysis = analyse_configs(rows, self.settings, scene_panels(self.scenes, self.settings))
        self.found = family_crossovers(self.analysis, self.settings, self.scenes)

    def tearDown(self):
        self.tmp.cleanup()

    def entry(self, family: str, strategy: str) -> dict:
        return next(f for f in self.found if f["family"] == family and f["strategy"] == strategy)

    def test_families_of_the_run(self):
        families = run_families(self.scenes)
        self.assertEqual(list(families), ["size_rect", "distance"])
        # Members in increasing solid angle (distance: decreasing height).
        self.assertEqual([sc.name for sc in families["distance"]], ["distance_h10", "distance_h1", "distance_h0.1"])
        self.assertEqual(len(self.found), 2 * 3)  # two families x three strategies other than area

    def test_series_ratios_and_standard_errors(self):
        s = self.entry("size_rect", "solid-angle")["series"]
        self.assertEqual(s["solid_angle"], RECT_OMEGAS)
        for omega, r in zip(s["solid_angle"], s["ratio"]):
            self.assertAlmostEqual(r, 1 + 0.5 * math.log10(omega / RECT_CROSSING), places=9)
        # The seed factor is the same for both strategies: equal standard errors, added in quadrature.
        se = math.log(1.2)  # log-spread of the two seeds at each spp, pooled, over four renders
        for e in s["log_se"]:
            self.assertAlmostEqual(e, math.hypot(se * math.sqrt(2) / 2, se * math.sqrt(2) / 2), places=9)

    def test_crossing_at_the_known_solid_angle(self):
        e = self.entry("size_rect", "solid-angle")
        self.assertEqual(len(e["crossings"]), 1)
        self.assertAlmostEqual(e["crossings"][0], RECT_CROSSING, places=9)
        self.assertAlmostEqual(e["params"][0], RECT_CROSSING * 10, places=9)
        self.assertEqual(e["verdict"], "")
        e = self.entry("distance", "solid-angle")
        self.assertEqual(len(e["crossings"]), 1)
        self.assertAlmostEqual(e["crossings"][0], DIST_CROSSING, places=9)
        self.assertAlmostEqual(e["params"][0], math.sqrt(10), places=9)

    def test_verdicts_without_crossing(self):
        self.assertEqual(self.entry("size_rect", "projected-solid-angle")["verdict"], "always above")
        self.assertEqual(self.entry("size_rect", "auto")["verdict"], "always below")
        self.assertEqual(self.entry("distance", "projected-solid-angle")["verdict"], "none in range")
        self.assertEqual(crossover_verdict([], []), ([], "no points"))
        self.assertEqual(crossover_verdict([1.0, 2.0], [float("nan"), float("nan")]), ([], "no points"))

    def test_interp_param(self):
        self.assertAlmostEqual(interp_param(0.1, [0.01, 1.0], [10.0, 1.0]), math.sqrt(10), places=12)
        self.assertTrue(math.isnan(interp_param(5.0, [0.01, 1.0], [10.0, 1.0])))
        self.assertTrue(math.isnan(interp_param(0.1, [0.01, 1.0], [float("nan"), 1.0])))

    def test_no_area_no_crossovers(self):
        settings = make_settings(self.tmp.name, "--strategies", "solid-angle", "auto")
        self.assertEqual(family_crossovers(self.analysis, settings, self.scenes), [])

    def test_missing_points_are_left_out(self):
        sc = self.scenes[0]
        analysis = dict(self.analysis)
        analysis[(sc.name, DEPTH)] = {}
        s = family_series(analysis, run_families(self.scenes)["size_rect"], "global",
                          Config("area", "mixture", "independent"), Config("solid-angle", "mixture", "independent"))
        self.assertEqual(s["solid_angle"], RECT_OMEGAS[1:])

    def test_table_and_figures(self):
        figures = make_family_plots(self.found, self.settings)
        names = [n for n, _ in figures]
        self.assertEqual(names, [family_figure_name("size_rect", "global"), family_figure_name("distance", "global")])
        for name in names:
            data = (Path(self.tmp.name) / name).read_bytes()
            self.assertEqual(data[:8], b"\x89PNG\r\n\x1a\n", name)
        text = family_section(self.found, figures)
        self.assertIn("## Scene families: crossovers", text)
        self.assertIn("| size_rect | global, mixture, independent | solid-angle | 4 | 0.349 – 1.59 | 0.2 sr (2) |", text)
        self.assertIn("| distance | global, mixture, independent | solid-angle | 3 | 0.5 – 2.5 | 0.1 sr (3.16) |", text)
        self.assertIn("| always above |", text)
        self.assertIn("| always below |", text)
        self.assertIn("| none in range |", text)
        for name in names:
            self.assertIn(f"![{name}]({name})", text)
        self.assertEqual(family_section([], []), "")


if __name__ == "__main__":
    unittest.main()
