"""The generated pbrt-v4 families (pbrt_families.py): members, geometry, equal power, light
counts, stable files, their resolution and depth; the light-selection axis (CLI, CSV column and
its migration, point and reference keys, mcrt's refusals counted as unavailable)."""

import contextlib
import csv
import io
import importlib.util
import math
import os
import re
import tempfile
import unittest
from pathlib import Path

from mcrt_study.config import (
    CSV_COLUMNS, DEFAULT_LIGHT_SELECT, PRE_SELECT_CSV_COLUMNS, Config, build_parser, resolve_settings,
)
from mcrt_study.many_lights_scenes import scene_text as many_lights_text
from mcrt_study.mcrt import McrtError, run_mcrt
from mcrt_study.pbrt_families import (
    MANY_LIGHTS_POWER, TRI_AREA, TRI_POWER, many_lights_family, pbrt_file_settings, tri_aspect_family,
    tri_distance_family, tri_grazing_family, tri_size_family,
)
from mcrt_study.points import point_file_name
from mcrt_study.references import reference_key
from mcrt_study.results import point_key, read_csv, row_key
from mcrt_study.scenes import FAMILIES, family_member, load_scenes, member_text, triangle_solid_angle, write_member
from mcrt_study.config import SceneInfo
from mcrt_study.util import sha256_json

REPO = Path(__file__).resolve().parents[3]
TRIANGLE_FAMILIES = ("tri_size", "tri_distance", "tri_aspect", "tri_grazing")


def make_settings(out: Path, *args: str):
    argv = ["study.py", "--report-only", "--out", str(out), *args]
    return resolve_settings(build_parser().parse_args(argv[1:]), argv)


def numbers(text: str) -> list[float]:
    return [float(v) for v in text.split()]


def emitters(text: str) -> list[tuple[float, list, list]]:
    """(radiance, points, index triples) of every AreaLightSource block of a pbrt file."""
    found = []
    for block in re.findall(r"AttributeBegin\n(.*?)AttributeEnd\n", text, re.S):
        if "AreaLightSource" not in block:
            continue
        L = numbers(re.search(r'"rgb L" \[ ([^\]]*) \]', block).group(1))
        assert L[0] == L[1] == L[2], L
        p = numbers(re.search(r'"point3 P" \[ ([^\]]*) \]', block).group(1))
        idx = [int(v) for v in re.search(r'"integer indices" \[ ([^\]]*) \]', block).group(1).split()]
        points = [tuple(p[i:i + 3]) for i in range(0, len(p), 3)]
        found.append((L[0], points, [idx[i:i + 3] for i in range(0, len(idx), 3)]))
    return found


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def the_triangle(member) -> tuple[float, list]:
    """The radiance and corners of a triangle member's only light."""
    [(L, points, tris)] = emitters(member_text(member))
    assert tris == [[0, 1, 2]], tris
    return L, points


class TriangleFamiliesTest(unittest.TestCase):
    def test_names_and_parameters(self):
        expected = {
            "tri_size": (["1of16", "1of4", "x1", "x2", "x4", "x8"], [1 / 16, 1 / 4, 1, 2, 4, 8]),
            "tri_distance": (["h0.01", "h0.03", "h0.1", "h0.3", "h1", "h3", "h10"], [0.01, 0.03, 0.1, 0.3, 1, 3, 10]),
            "tri_aspect": (["a1", "a10", "a100", "a1000", "a10000"], [1, 10, 100, 1000, 1e4]),
            "tri_grazing": (["c1", "c0.5", "c0.1", "c0.03", "c0.01", "c0.001"], [1, 0.5, 0.1, 0.03, 0.01, 0.001]),
        }
        for family, (tags, params) in expected.items():
            members = FAMILIES[family]()
            self.assertEqual([m.name for m in members], [f"{family}_{t}" for t in tags])
            self.assertEqual({(m.family, m.suffix) for m in members}, {(family, ".pbrt")})
            for m, p in zip(members, params):
                self.assertAlmostEqual(m.param, p, places=12)
                self.assertEqual(family_member(m.name).name, m.name)
        self.assertIsNone(family_member("tri_size_x3"))

    def test_equal_power(self):
        for family in TRIANGLE_FAMILIES:
            for m in FAMILIES[family]():
                L, (a, b, c) = the_triangle(m)
                area = 0.5 * norm(cross(sub(b, a), sub(c, a)))
                with self.subTest(member=m.name):
                    self.assertAlmostEqual(L * area / TRI_POWER, 1.0, delta=1e-6)

    def test_geometry(self):
        def corners(m):
            return the_triangle(m)[1]

        def normal(points):
            a, b, c = points
            n = cross(sub(b, a), sub(c, a))
            return [x / norm(n) for x in n]

        for m in tri_size_family():
            a, b, c = corners(m)
            with self.subTest(member=m.name):
                self.assertAlmostEqual(0.5 * norm(cross(sub(b, a), sub(c, a))) / (TRI_AREA * m.param), 1, delta=1e-5)
                edges = [norm(sub(b, a)), norm(sub(c, b)), norm(sub(a, c))]
                self.assertAlmostEqual(max(edges) / min(edges), 1, delta=1e-5)  # equilateral
                self.assertAlmostEqual((a[1] + b[1] + c[1]) / 3, 1, places=5)
                self.assertAlmostEqual(normal((a, b, c))[1], -1, places=9)  # emits downwards
        for m in tri_distance_family():
            a, b, c = corners(m)
            with self.subTest(member=m.name):
                self.assertAlmostEqual((a[1] + b[1] + c[1]) / 3, m.param, places=5)
                self.assertTrue(a[1] == b[1] == c[1])
        for m in tri_aspect_family():
            a, b, c = corners(m)
            base, height = norm(sub(b, a)), abs(c[2] - a[2])
            with self.subTest(member=m.name):
                self.assertAlmostEqual((base / height) / (2 / math.sqrt(3)) / m.param, 1, delta=2e-3)
                self.assertAlmostEqual(0.5 * base * height / TRI_AREA, 1, delta=2e-3)
        for m in tri_grazing_family():
            n = normal(corners(m))
            with self.subTest(member=m.name):
                self.assertAlmostEqual(-n[1], m.param, delta=2e-5)  # cos(normal, down)
                self.assertLessEqual(n[2], 1e-12)  # towards -z, away from the camera (-x, +z)
                self.assertGreater(min(p[1] for p in corners(m)), 0.4)  # above the floor

    def test_solid_angles(self):
        for family in TRIANGLE_FAMILIES:
            members = FAMILIES[family]()
            for m in members:
                with self.subTest(member=m.name):
                    self.assertAlmostEqual(m.solid_angle, triangle_solid_angle((0, 0, 0), *the_triangle(m)[1]),
                                           places=12)
            angles = [m.solid_angle for m in members]
            # Larger lights subtend more; higher, longer or more tilted ones less.
            self.assertEqual(angles, sorted(angles, reverse=family != "tri_size"), family)
        # A small light far away: area cos / d^2.
        far = tri_distance_family()[-1]
        self.assertAlmostEqual(far.solid_angle / (TRI_AREA / 100), 1, delta=0.01)

    def test_scene_file(self):
        text = member_text(family_member("tri_size_x1"))
        self.assertEqual(pbrt_file_settings(text), (600, 600, 50))
        self.assertIn('LookAt -5 7.071068 5  0 0 0  0 1 0\nCamera "perspective" "float fov" [ 40 ]\n', text)
        self.assertIn('Shape "trianglemesh" "point3 P" [ -200 0 -200  200 0 -200  200 0 200  -200 0 200 ]', text)
        self.assertEqual(text.count("AreaLightSource"), 1)
        self.assertEqual(pbrt_file_settings("WorldBegin\n"), (1280, 720, 5))  # pbrt-v4's defaults


class ManyLightsTest(unittest.TestCase):
    def test_members(self):
        members = many_lights_family()
        self.assertEqual([m.name for m in members],
                         ["many_lights_n10", "many_lights_n100", "many_lights_n1000", "many_lights_n10000",
                          "many_lights_n100000", "many_lights_mesh"])
        self.assertEqual([m.param for m in members], [10, 100, 1000, 10000, 100000, 12800])
        self.assertEqual({m.suffix for m in members}, {".pbrt"})

    def test_counts_power_and_solid_angles(self):
        angles = []
        for name, lights in (("many_lights_n10", 10), ("many_lights_n100", 100), ("many_lights_n1000", 1000),
                             ("many_lights_mesh", 8 + 20)):
            m = family_member(name)
            text = member_text(m)
            found = emitters(text)
            triangles = sum(len(t) for _, _, t in found)
            power = sum(math.pi * L * 0.5 * norm(cross(sub(p[i[1]], p[i[0]]), sub(p[i[2]], p[i[0]])))
                        for L, p, tris in found for i in tris)
            with self.subTest(member=name):
                self.assertEqual(len(found), lights)
                self.assertAlmostEqual(power / MANY_LIGHTS_POWER, 1, delta=1e-4)
                self.assertEqual(pbrt_file_settings(text), (320, 240, 3))
                if name == "many_lights_mesh":
                    self.assertGreaterEqual(triangles, 10000)
                    self.assertEqual(sum(len(t) for _, _, t in found[:8]), 12800)
                self.assertGreater(m.solid_angle, 0)
            angles.append(m.solid_angle)
        # The lights shrink as 1 / sqrt(N): their solid angle as 1 / N.
        self.assertEqual(angles[:3], sorted(angles[:3], reverse=True))
        self.assertAlmostEqual(math.log10(angles[0] / angles[2]), 2, delta=0.5)

    def test_the_bench_scenes_up_to_a_radiance_scale(self):
        # The study's members are bench/many_lights.py's scenes (same generator), radiances scaled.
        spec = importlib.util.spec_from_file_location("bench_many_lights", REPO / "bench" / "many_lights.py")
        bench = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(bench)
        from mcrt_study import many_lights_scenes
        self.assertIs(bench.write_scenes, many_lights_scenes.write_scenes)
        ours, theirs = member_text(family_member("many_lights_n10")), many_lights_text("lights_10", (320, 240))
        strip = lambda t: re.sub(r'"rgb L" \[[^\]]*\]', "L", t)  # noqa: E731
        self.assertEqual(strip(ours), strip(theirs))
        ratios = {round(a[0] / b[0], 3) for a, b in zip(emitters(ours), emitters(theirs))}
        self.assertEqual(len(ratios), 1)


class FilesTest(unittest.TestCase):
    def test_byte_stable(self):
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            for name in ("tri_size_x2", "tri_distance_h0.01", "tri_aspect_a10000", "tri_grazing_c0.001",
                         "many_lights_n100"):
                pa = write_member(family_member(name), Path(a))
                before = pa.read_bytes()
                os.utime(pa, ns=(1, 1))
                self.assertEqual(write_member(family_member(name), Path(a)), pa)
                self.assertEqual(pa.stat().st_mtime_ns, 1)  # identical: left untouched
                pb = write_member(family_member(name), Path(b))
                self.assertEqual(pb.name, f"{name}.pbrt")
                self.assertEqual(pb.read_bytes(), before)

    def test_load_scenes(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp)
            settings = make_settings(out, "--scenes", "tri_aspect", "many_lights_n10")
            scenes = load_scenes(settings.scenes, settings)
            self.assertEqual([s.name for s in scenes], [m.name for m in tri_aspect_family()] + ["many_lights_n10"])
            for s in scenes:
                with self.subTest(scene=s.name):
                    self.assertEqual(s.path, (out / "scenes" / f"{s.name}.pbrt").resolve())
                    self.assertEqual(s.light_solid_angle, family_member(s.name).solid_angle)
                    self.assertEqual(s.family_param, family_member(s.name).param)
            self.assertEqual((scenes[0].width, scenes[0].height, scenes[0].max_depth), (300, 300, 50))
            self.assertEqual((scenes[-1].width, scenes[-1].height, scenes[-1].max_depth), (160, 120, 3))
            # A pbrt-v4 file by path: its Film and Integrator; no family.
            path = out / "mine.pbrt"
            path.write_text('Film "rgb" "integer xresolution" [ 64 ] "integer yresolution" 32\n'
                            'Integrator "path" "integer maxdepth" [ 7 ]\nWorldBegin\n', encoding="utf-8")
            [mine] = load_scenes([str(path)], settings)
            self.assertEqual((mine.name, mine.width, mine.height, mine.max_depth, mine.family), ("mine", 32, 16, 7, ""))
            self.assertIsNone(mine.light_solid_angle)
            # Bad input: one line, exit status 2.
            for bad in ("tri_size_x3", str(out / "missing.pbrt")):
                with self.subTest(bad=bad), contextlib.redirect_stderr(io.StringIO()) as err, \
                        self.assertRaises(SystemExit) as caught:
                    load_scenes([bad], settings)
                self.assertEqual(caught.exception.code, 2)
                self.assertEqual(err.getvalue(), f"study.py: scene not found: {bad}\n")


class LightSelectTest(unittest.TestCase):
    ROW = {"scene": "tri_size_x1", "strategy": "area", "integrator": "mis", "sampler": "sobol", "max_depth": 1,
           "spp": 4, "seed": 1, "seconds": "0.5", "rmse": "0.1", "mse": "0.01", "relmse": "0.02",
           "family": "tri_size", "family_param": "1", "light_solid_angle": "0.386"}

    def test_axis(self):
        with tempfile.TemporaryDirectory() as tmp:
            settings = make_settings(Path(tmp))
            self.assertEqual(settings.light_selects, [DEFAULT_LIGHT_SELECT])
            self.assertFalse(settings.varies_light_select)
            settings = make_settings(Path(tmp), "--light-selects", "pbrt-bvh", "power", "--strategies", "area", "pbrt",
                                     "--integrators", "nee", "--samplers", "sobol")
            self.assertEqual(settings.light_selects, ["power", "pbrt-bvh"])  # canonical order
            self.assertEqual(settings.configs, [Config("area", "nee", "sobol", "power"),
                                                Config("pbrt", "nee", "sobol", "power"),
                                                Config("area", "nee", "sobol", "pbrt-bvh"),
                                                Config("pbrt", "nee", "sobol", "pbrt-bvh")])
            self.assertEqual(Config("area", "nee", "sobol", "bvh").label, "nee/sobol/area/bvh")
            self.assertEqual(Config("area", "nee", "sobol").label, "nee/sobol/area")

    def test_csv_without_the_column_is_read_and_rewritten(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "results.csv"
            with path.open("w", newline="", encoding="utf-8") as f:
                writer = csv.DictWriter(f, fieldnames=PRE_SELECT_CSV_COLUMNS)
                writer.writeheader()
                writer.writerow(self.ROW)
            [row] = read_csv(path, lambda name: 50)
            self.assertEqual(row["light_select"], DEFAULT_LIGHT_SELECT)
            self.assertEqual((row["family"], row["family_param"]), ("tri_size", 1.0))
            with path.open(newline="", encoding="utf-8") as f:
                self.assertEqual(next(csv.reader(f)), CSV_COLUMNS)
            self.assertEqual(read_csv(path, lambda name: 50), [row])
            self.assertEqual(CSV_COLUMNS[-1], "light_select")

    def test_keys(self):
        row = {**self.ROW, "max_depth": 1, "spp": 4, "seed": 1}
        legacy = ("tri_size_x1", "area", "mis", "sobol", 1, 4, 1)
        # The default selection keeps the point files' names from before the axis.
        self.assertEqual(point_file_name(row_key(row)), sha256_json(list(legacy))[:20] + ".json")
        bvh = point_key("tri_size_x1", Config("area", "mis", "sobol", "bvh"), 1, 4, 1)
        self.assertEqual(bvh, (*legacy, "bvh"))
        self.assertNotEqual(point_file_name(bvh), point_file_name(row_key(row)))
        scene = SceneInfo("box", Path("/nowhere/box.pbrt"), "ab" * 32, 64, 48, 7)
        with tempfile.TemporaryDirectory() as tmp:
            plain = reference_key(make_settings(Path(tmp)), scene, 7, "solid-angle", "")
            bvh_ref = reference_key(make_settings(Path(tmp), "--ref-light-select", "bvh"), scene, 7, "solid-angle", "")
            self.assertEqual(plain, "199134292869b216")  # test_cache_keys' value: unchanged
            self.assertNotEqual(bvh_ref, plain)

    def test_refusals_for_pbrt_scenes_count_as_unavailable(self):
        with tempfile.TemporaryDirectory() as tmp:
            fake = Path(tmp) / "mcrt"
            fake.write_text("#!/bin/sh\necho \"mcrt: $2:15: --light-sampling auto: not available for pbrt-v4 scenes "
                            "(a triangle light)\" >&2\nexit 2\n", encoding="utf-8")
            fake.chmod(0o755)
            settings = make_settings(Path(tmp), "--mcrt", str(fake))
            with self.assertRaises(McrtError) as caught:
                run_mcrt(settings, ["render", "x.pbrt"])
            self.assertTrue(caught.exception.unavailable)
            fake.write_text("#!/bin/sh\necho 'mcrt: x.pbrt:3: Shape \"curve\": not supported' >&2\nexit 2\n",
                            encoding="utf-8")
            with self.assertRaises(McrtError) as caught:
                run_mcrt(settings, ["render", "x.pbrt"])
            self.assertFalse(caught.exception.unavailable)


if __name__ == "__main__":
    unittest.main()
