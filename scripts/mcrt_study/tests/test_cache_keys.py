"""The cache keys of references and of a scene's points must not change by accident: a
changed key renders every cached reference again and drops every point of a study.

The expected values were computed with scripts/study.py before it became this package.
"""

import tempfile
import unittest
from pathlib import Path

from mcrt_study.config import Reference, SceneInfo, build_parser, resolve_settings
from mcrt_study.references import reference_key, reference_strategies
from mcrt_study.results import scene_run_key


def make_settings(*args: str):
    argv = ["study.py", "--report-only", "--out", tempfile.gettempdir(), *args]
    return resolve_settings(build_parser().parse_args(argv[1:]), argv)


SCENE = SceneInfo("box", Path("/nowhere/box.json"), "ab" * 32, 64, 48, 7)
BINARY = "cd" * 32


class CacheKeyTest(unittest.TestCase):
    def test_reference_keys(self):
        for args, global_key, direct_key in [
            ((), "199134292869b216", "c47c4189bab85c8c"),
            # mixture + independent: the earlier study's key (no integrator, no sampler in it).
            (("--ref-integrator", "mixture", "--ref-sampler", "independent"), "ddaa769ed47fdcc6", "a94c51037cb3c989"),
            (("--ref-key-binary",), "987e27ff537a2e50", "8676f1861c64c130"),
        ]:
            with self.subTest(args=args):
                settings = make_settings(*args)
                self.assertEqual(reference_key(settings, SCENE, 7, "solid-angle", BINARY), global_key)
                self.assertEqual(reference_key(settings, SCENE, 1, "area", BINARY), direct_key)

    def test_reference_strategy_preference(self):
        self.assertEqual(reference_strategies(make_settings()), ["solid-angle", "area"])
        self.assertEqual(reference_strategies(make_settings("--ref-strategy", "area")), ["area"])

    def test_scene_run_key(self):
        ref = Reference("box", "global", 7, Path("/r.exr"), "0123456789abcdef", "solid-angle", "mis", "sobol",
                        4096, 7919, 1.0, True)
        self.assertEqual(scene_run_key(SCENE, 7, ref), "17bc2f3adade94e4")


if __name__ == "__main__":
    unittest.main()
