"""--time-repeats: a render is run R times and its time is the median of its runs' render_seconds
(mcrt.render, with a stand-in executable that reports a different time on each run); R < 1 is
refused."""

import stat
import tempfile
import unittest
from pathlib import Path

from mcrt_study.config import Config, SceneInfo, build_parser, resolve_settings
from mcrt_study.mcrt import render

# Reports the next of TIMES (one per run, counted in a file beside it) in --stats.
FAKE_MCRT = """#!/usr/bin/env python3
import json, sys
from pathlib import Path
times = [0.9, 0.1, 0.5, 0.3, 0.2]  # median 0.3, mean 0.4, min 0.1
here = Path(sys.argv[0]).parent
count = here / "runs"
n = int(count.read_text()) if count.exists() else 0
count.write_text(str(n + 1))
args = sys.argv[1:]
stats = Path(args[args.index("--stats") + 1])
stats.write_text(json.dumps({"render_seconds": times[n % len(times)], "integrator": "nee",
                             "sampler": "sobol", "light_sampling": "area"}))
"""


class TimeRepeats(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)
        self.mcrt = self.dir / "mcrt"
        self.mcrt.write_text(FAKE_MCRT)
        self.mcrt.chmod(self.mcrt.stat().st_mode | stat.S_IXUSR)

    def tearDown(self):
        self.tmp.cleanup()

    def settings(self, *extra):
        argv = ["study.py", "--mcrt", str(self.mcrt), "--no-bench", "--out", str(self.dir / "out"), *extra]
        return resolve_settings(build_parser().parse_args(argv[1:]), argv)

    def render_seconds(self, settings):
        scene = SceneInfo("s", self.dir / "s.json", "0", 8, 8, 5)
        return render(settings, scene, Config("area", "nee", "sobol"), 5, 4, 1, self.dir / "img.exr")

    def test_median_of_the_runs(self):
        self.assertEqual(self.render_seconds(self.settings("--time-repeats", "5")), 0.3)
        self.assertEqual(int((self.dir / "runs").read_text()), 5)

    def test_one_run_by_default(self):
        self.assertEqual(self.render_seconds(self.settings()), 0.9)
        self.assertEqual(int((self.dir / "runs").read_text()), 1)

    def test_refused_below_one(self):
        with self.assertRaises(SystemExit):
            self.settings("--time-repeats", "0")


if __name__ == "__main__":
    unittest.main()
