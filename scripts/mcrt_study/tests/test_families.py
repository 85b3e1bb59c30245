"""The generated scene families (scenes.py): members, geometry, power, solid angles, stable files,
selection by family name; and the CSV's family columns."""

import csv
import json
import math
import os
import random
import tempfile
import unittest
from pathlib import Path

from mcrt_study.config import CSV_COLUMNS, PRE_FAMILY_CSV_COLUMNS, build_parser, resolve_settings
from mcrt_study.results import read_csv, write_csv
from mcrt_study.scenes import (
    CORNELL_CENTRE, FAMILIES, distance_family, ellipse_solid_angle, family_member, light_solid_angle,
    load_scenes, polygon_solid_angle, scene_columns, scene_text, size_disk_family, size_rect_family,
    size_sphere_family, sphere_solid_angle, write_member,
)
from mcrt_study.util import sha256_file

SEED_POWER = 15 * 130 * 105
RATIOS = [1 / 16, 1 / 4, 1, 2, 4, 8]


def make_settings(out: Path, *scenes: str):
    argv = ["study.py", "--report-only", "--out", str(out), "--scenes", *scenes]
    return resolve_settings(build_parser().parse_args(argv[1:]), argv)


def parsed(member) -> dict:
    """The member's scene as read back from the text written to its file."""
    return json.loads(scene_text(member.scene))


def the_light(scene: dict) -> tuple[dict, float]:
    """The (only) light object of a scene and its emission (grey)."""
    lights = [o for o in scene["objects"] if scene["materials"][o["material"]]["type"] == "diffuse_light"]
    assert len(lights) == 1, lights
    emit = scene["materials"][lights[0]["material"]]["emit"]
    assert emit[0] == emit[1] == emit[2]
    return lights[0], float(emit[0])


def light_area(light: dict) -> float:
    """Area of a planar light, projected area (pi r^2) of a sphere."""
    if light["type"] == "xz_rect":
        return (light["x1"] - light["x0"]) * (light["z1"] - light["z0"])
    if light["type"] == "ellipse":
        return math.pi * math.hypot(*light["axis1"]) * math.hypot(*light["axis2"])
    if light["type"] == "sphere":
        return math.pi * light["radius"] ** 2
    raise AssertionError(light["type"])


def rect_on_axis(d: float, a: float, b: float) -> float:
    """Solid angle of an a x b rectangle from distance d on its central normal."""
    return 4 * math.asin(a * b / math.sqrt((a * a + 4 * d * d) * (b * b + 4 * d * d)))


def spherical_polygon_angle_sum(p, corners) -> float:
    """Solid angle of a convex polygon as the spherical excess: sum of the interior angles minus (n - 2) pi
    (for a rectangle, Urena et al. 2013's sum of gammas minus 2 pi)."""
    def unit(v):
        n = math.sqrt(sum(c * c for c in v))
        return [c / n for c in v]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    v = [unit([c[i] - p[i] for i in range(3)]) for c in corners]
    n = len(v)
    total = 0.0
    for i in range(n):
        prev, cur, nxt = v[i - 1], v[i], v[(i + 1) % n]
        t1 = unit(cross(cross(cur, prev), cur))  # tangent at cur towards prev
        t2 = unit(cross(cross(cur, nxt), cur))  # tangent at cur towards next
        total += math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(t1, t2)))))
    return total - (n - 2) * math.pi


class MembersTest(unittest.TestCase):
    def test_counts_and_names(self):
        tags = ["1of16", "1of4", "x1", "x2", "x4", "x8"]
        sphere_tags = ["1of16", "1of8", "1of4", "1of2", "x1", "x2"]
        sphere_ratios = [1 / 16, 1 / 8, 1 / 4, 1 / 2, 1, 2]
        for family in ("size_rect", "size_disk", "size_sphere"):
            members = FAMILIES[family]()
            expected_tags, ratios = (sphere_tags, sphere_ratios) if family == "size_sphere" else (tags, RATIOS)
            self.assertEqual([m.name for m in members], [f"{family}_{t}" for t in expected_tags])
            self.assertEqual({m.family for m in members}, {family})
            for m, r in zip(members, ratios):
                self.assertAlmostEqual(m.param, r, places=9)
        # Every sphere stays above the tall box (top y = 330) and leaves the box's centre outside.
        for m in FAMILIES["size_sphere"]():
            light = next(o for o in m.scene["objects"] if o["type"] == "sphere")
            self.assertGreater(light["center"][1] - light["radius"], 330.0, m.name)
        members = distance_family()
        self.assertEqual([m.name for m in members],
                         ["distance_h0.01", "distance_h0.03", "distance_h0.1", "distance_h0.3", "distance_h1",
                          "distance_h3", "distance_h10"])
        self.assertEqual([m.param for m in members], [0.01, 0.03, 0.1, 0.3, 1, 3, 10])
        self.assertEqual(family_member("size_disk_x2").name, "size_disk_x2")
        self.assertIsNone(family_member("size_disk_x3"))
        self.assertIsNone(family_member("cornell_rect"))

    def test_only_the_light_differs_from_the_seed(self):
        seeds = {"size_rect": "cornell_rect", "size_disk": "cornell_disk", "size_sphere": "cornell_sphere"}
        scenes_dir = Path(__file__).resolve().parents[3] / "scenes"
        for family, seed_name in seeds.items():
            seed = json.loads((scenes_dir / f"{seed_name}.json").read_text(encoding="utf-8"))
            seed_light, _ = the_light(seed)
            for m in FAMILIES[family]():
                scene = parsed(m)
                light, _ = the_light(scene)
                with self.subTest(member=m.name):
                    self.assertEqual(scene["camera"], seed["camera"])
                    self.assertEqual(scene["render"], seed["render"])
                    self.assertEqual({k: v for k, v in scene["materials"].items() if k != "light"},
                                     {k: v for k, v in seed["materials"].items() if k != "light"})
                    self.assertEqual([o for o in scene["objects"] if o is not light],
                                     [o for o in seed["objects"] if o != seed_light])
                    self.assertEqual(light["type"], seed_light["type"])

    def test_equal_power_across_the_size_families(self):
        for family in ("size_rect", "size_disk", "size_sphere"):
            for m in FAMILIES[family]():
                light, emit = the_light(parsed(m))
                with self.subTest(member=m.name):
                    self.assertAlmostEqual(emit * light_area(light) / SEED_POWER, 1.0, delta=1e-6)

    def test_areas_match_the_rectangle_at_each_size(self):
        for rect, disk, ratio in zip(size_rect_family(), size_disk_family(), RATIOS):
            rect_area = light_area(the_light(parsed(rect))[0])
            with self.subTest(ratio=ratio):
                self.assertAlmostEqual(rect_area / (13650 * ratio), 1.0, delta=1e-6)
                self.assertAlmostEqual(light_area(the_light(parsed(disk))[0]) / rect_area, 1.0, delta=1e-6)
        # The sphere's projected area is the rectangle's at the same ratio.
        for sphere in size_sphere_family():
            with self.subTest(sphere=sphere.name):
                self.assertAlmostEqual(light_area(the_light(parsed(sphere))[0]) / (13650 * sphere.param), 1.0, delta=1e-6)
                light = the_light(parsed(rect))[0]
                self.assertAlmostEqual((light["x1"] - light["x0"]) / (light["z1"] - light["z0"]), 130 / 105, places=6)

    def test_lights_stay_inside_the_ceiling(self):
        for m in size_rect_family() + size_disk_family() + size_sphere_family():
            light, _ = the_light(parsed(m))
            with self.subTest(member=m.name):
                if light["type"] == "xz_rect":
                    box = (light["x0"], light["x1"], light["z0"], light["z1"])
                    self.assertEqual(light["k"], 554)
                    self.assertTrue(light["flip"])
                    self.assertAlmostEqual((light["x0"] + light["x1"]) / 2, 278, places=5)
                    self.assertAlmostEqual((light["z0"] + light["z1"]) / 2, 279.5, places=5)
                else:
                    cx, cy, cz = light["center"]
                    r = light.get("radius") or math.hypot(*light["axis1"])
                    box = (cx - r, cx + r, cz - r, cz + r)
                    self.assertEqual((cx, cz), (278, 279.5))
                    if light["type"] == "sphere":
                        self.assertAlmostEqual(cy, 554 - r - 1, places=5)
                    else:
                        self.assertEqual(cy, 554)
                        n = [light["axis1"][1] * light["axis2"][2] - light["axis1"][2] * light["axis2"][1],
                             light["axis1"][2] * light["axis2"][0] - light["axis1"][0] * light["axis2"][2],
                             light["axis1"][0] * light["axis2"][1] - light["axis1"][1] * light["axis2"][0]]
                        self.assertLess(n[1], 0)  # facing down
                self.assertGreaterEqual(min(box), 0)
                self.assertLessEqual(max(box), 555)

    def test_distance_heights_and_occluders(self):
        for m in distance_family():
            scene = parsed(m)
            light, emit = the_light(scene)
            h = light["k"]
            with self.subTest(member=m.name):
                self.assertAlmostEqual(h / 130, m.param, places=9)
                self.assertEqual(emit, 15)
                self.assertEqual((light["x1"] - light["x0"], light["z1"] - light["z0"]), (130, 105))
                self.assertTrue(light["flip"])
                boxes = [o for o in scene["objects"] if o["type"] == "box"]
                self.assertEqual(len(boxes), 0 if h < 20 else 2)
                for b in boxes:
                    self.assertLessEqual(b["max"][1], h / 2 + 1e-6)
                floor = scene["objects"][0]
                self.assertEqual((floor["x1"] - floor["x0"], floor["z1"] - floor["z0"], floor["k"]), (4000, 4000, 0))
                self.assertEqual(scene["camera"]["lookat"], [278, 0, 279.5])
                # The camera looks down and is not inside the light's slab.
                self.assertGreater(scene["camera"]["lookfrom"][1], 0)
                self.assertNotAlmostEqual(scene["camera"]["lookfrom"][1], h, delta=50)


class SolidAngleTest(unittest.TestCase):
    def test_rectangle_against_independent_formulas(self):
        square = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]
        # On the central normal: 4 asin(ab / sqrt((a^2 + 4d^2)(b^2 + 4d^2))).
        for d in (0.01, 0.5, 1, 3, 100):
            self.assertAlmostEqual(polygon_solid_angle((0, -d, 0), square), rect_on_axis(d, 2, 2), places=9)
        # Anywhere: the spherical excess.
        rng = random.Random(5)
        for _ in range(20):
            p = (rng.uniform(-3, 3), rng.uniform(-3, -0.05), rng.uniform(-3, 3))
            self.assertAlmostEqual(polygon_solid_angle(p, square), spherical_polygon_angle_sum(p, square), places=9)
        # A tiny rectangle: area cos / d^2.
        tiny = [(10, 5, 7), (10.001, 5, 7), (10.001, 5, 7.002), (10, 5, 7.002)]
        p = (0, 0, 0)
        d2 = 10 ** 2 + 5 ** 2 + 7 ** 2
        self.assertAlmostEqual(polygon_solid_angle(p, tiny) / (0.001 * 0.002 * 5 / math.sqrt(d2) / d2), 1, places=3)

    def test_light_objects(self):
        # The seed's ceiling light from the box's centre, as xz_rect and as rect.
        xz = {"type": "xz_rect", "x0": 213, "x1": 343, "z0": 227, "z1": 332, "k": 554}
        expected = rect_on_axis(554 - 278, 130, 105)
        self.assertAlmostEqual(light_solid_angle(xz, CORNELL_CENTRE), expected, places=9)
        rect = {"type": "rect_sa", "corner": [213, 554, 227], "edge1": [130, 0, 0], "edge2": [0, 0, 105]}
        self.assertAlmostEqual(light_solid_angle(rect, CORNELL_CENTRE), expected, places=9)
        xy = {"type": "xy_rect", "x0": -1, "x1": 1, "y0": -1, "y1": 1, "k": 4}
        self.assertAlmostEqual(light_solid_angle(xy, (0, 0, 0)), rect_on_axis(4, 2, 2), places=9)
        yz = {"type": "yz_rect_sa", "y0": -1, "y1": 1, "z0": -2, "z1": 2, "k": -3}
        self.assertAlmostEqual(light_solid_angle(yz, (0, 0, 0)), rect_on_axis(3, 2, 4), places=9)
        self.assertIsNone(light_solid_angle({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, (5, 5, 5)))

    def test_disk(self):
        # The polygon path on the axis against the closed form 2 pi (1 - h / sqrt(h^2 + R^2)).
        for h, r in ((1, 1), (276, 65), (0.1, 3), (100, 0.5)):
            closed = 2 * math.pi * (1 - h / math.sqrt(h * h + r * r))
            self.assertAlmostEqual(ellipse_solid_angle((0, 0, 0), (0, h, 0), (r, 0, 0), (0, 0, r)) / closed, 1,
                                   delta=1e-6)
            disk = {"type": "ellipse", "center": [0, h, 0], "axis1": [r, 0, 0], "axis2": [0, 0, r]}
            self.assertAlmostEqual(light_solid_angle(disk, (0, 0, 0)), closed, places=12)
        # A tiny ellipse off the axis: area cos / d^2 (the polygon path).
        small = {"type": "ellipse_sa", "center": [3, 4, 12], "axis1": [0.01, 0, 0], "axis2": [0, 0, 0.02]}
        d = 13.0
        self.assertAlmostEqual(light_solid_angle(small, (0, 0, 0)) / (math.pi * 0.01 * 0.02 * 4 / d / d ** 2), 1,
                               places=4)

    def test_sphere(self):
        # A small sphere: pi r^2 / d^2; any: 2 pi (1 - cos) with sin = r / d.
        self.assertAlmostEqual(sphere_solid_angle(1000, 1) / (math.pi / 1000 ** 2), 1, places=5)
        self.assertAlmostEqual(sphere_solid_angle(2, 1), 2 * math.pi * (1 - math.cos(math.pi / 6)), places=12)
        self.assertEqual(sphere_solid_angle(1, 2), 4 * math.pi)

    def test_members_solid_angles(self):
        for m, ratio in zip(size_rect_family(), RATIOS):
            k = math.sqrt(ratio)
            self.assertAlmostEqual(m.solid_angle, rect_on_axis(276, 130 * k, 105 * k), places=6)
        for m, ratio in zip(size_disk_family(), RATIOS):
            r = math.sqrt(13650 * ratio / math.pi)
            self.assertAlmostEqual(m.solid_angle, 2 * math.pi * (1 - 276 / math.hypot(276, r)), places=6)
        for m in size_sphere_family():
            r = math.sqrt(13650 * m.param / math.pi)
            d = 554 - r - 1 - 278
            expected = 4 * math.pi if d <= r else 2 * math.pi * (1 - math.sqrt(d * d - r * r) / d)
            self.assertAlmostEqual(m.solid_angle, expected, places=5)
        for m in distance_family():
            self.assertAlmostEqual(m.solid_angle, rect_on_axis(130 * m.param, 130, 105), places=9)
        # Monotone: larger lights, nearer lights subtend more.
        for family in (size_rect_family(), size_disk_family(), size_sphere_family()):
            angles = [m.solid_angle for m in family]
            self.assertEqual(angles, sorted(angles))
        angles = [m.solid_angle for m in distance_family()]
        self.assertEqual(angles, sorted(angles, reverse=True))

    def test_shipped_scenes(self):
        self.assertAlmostEqual(scene_columns("cornell_rect")["light_solid_angle"], rect_on_axis(276, 130, 105),
                               places=9)
        self.assertAlmostEqual(scene_columns("cornell_disk")["light_solid_angle"],
                               2 * math.pi * (1 - 276 / math.hypot(276, 65)), places=9)
        self.assertAlmostEqual(scene_columns("cornell_sphere")["light_solid_angle"],
                               2 * math.pi * (1 - math.sqrt(182 ** 2 - 50 ** 2) / 182), places=9)
        self.assertEqual(scene_columns("cornell_rect")["family"], "")
        self.assertIsNone(scene_columns("cornell_rect")["family_param"])
        self.assertIsNone(scene_columns("no_such_scene")["light_solid_angle"])


class FilesAndSelectionTest(unittest.TestCase):
    def test_byte_stable(self):
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            for name in ("size_rect_x2", "size_disk_1of16", "size_sphere_x2", "distance_h0.3"):
                pa = write_member(family_member(name), Path(a))
                before = (pa.read_bytes(), pa.stat().st_mtime_ns)
                os.utime(pa, ns=(1, 1))
                pa2 = write_member(family_member(name), Path(a))  # again: left untouched
                self.assertEqual(pa2, pa)
                self.assertEqual(pa.stat().st_mtime_ns, 1)
                pb = write_member(family_member(name), Path(b))  # elsewhere, from scratch
                self.assertEqual(pb.read_bytes(), before[0])
                self.assertEqual(pb.name, f"{name}.json")
                self.assertEqual(scene_text(family_member(name).scene).encode(), before[0])

    def test_family_names_expand_in_scene_selection(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp)
            settings = make_settings(out, "size_rect", "cornell_rect", "size_rect_x2", "distance_h0.01")
            scenes = load_scenes(settings.scenes, settings)
            self.assertEqual([s.name for s in scenes],
                             [m.name for m in size_rect_family()] + ["cornell_rect", "distance_h0.01"])
            for s in scenes:
                with self.subTest(scene=s.name):
                    if s.name == "cornell_rect":
                        self.assertEqual((s.family, s.family_param), ("", None))
                        self.assertAlmostEqual(s.light_solid_angle, rect_on_axis(276, 130, 105), places=9)
                        self.assertEqual(s.path.parent.name, "scenes")
                        self.assertNotEqual(s.path.parent, out / "scenes")
                    else:
                        self.assertEqual(s.path, (out / "scenes" / f"{s.name}.json").resolve())
                        self.assertEqual(s.content_sha256, sha256_file(s.path))
                        self.assertEqual(s.family, family_member(s.name).family)
                        self.assertEqual(s.light_solid_angle, family_member(s.name).solid_angle)
                    self.assertEqual((s.width, s.height, s.max_depth), (300, 300, 50))
            self.assertEqual(sorted(p.name for p in (out / "scenes").iterdir()),
                             sorted(f"{s.name}.json" for s in scenes if s.name != "cornell_rect"))
            # Every family by name.
            for family, make in FAMILIES.items():
                self.assertEqual([s.name for s in load_scenes([family], settings)], [m.name for m in make()])


class CsvColumnsTest(unittest.TestCase):
    ROW = {"scene": "cornell_rect", "strategy": "area", "integrator": "mis", "sampler": "sobol", "max_depth": 1,
           "spp": 4, "seed": 1, "seconds": "0.5", "rmse": "0.1", "mse": "0.01", "relmse": "0.02"}

    def test_csv_without_the_family_columns_is_read_and_rewritten(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "results.csv"
            with path.open("w", newline="", encoding="utf-8") as f:
                writer = csv.DictWriter(f, fieldnames=PRE_FAMILY_CSV_COLUMNS)
                writer.writeheader()
                writer.writerow(self.ROW)
                writer.writerow({**self.ROW, "scene": "size_disk_x4"})
            rows = read_csv(path, lambda name: 50)
            self.assertEqual(rows[0]["family"], "")
            self.assertIsNone(rows[0]["family_param"])
            self.assertAlmostEqual(rows[0]["light_solid_angle"], rect_on_axis(276, 130, 105), places=9)
            self.assertEqual((rows[1]["family"], rows[1]["family_param"]), ("size_disk", 4.0))
            with path.open(newline="", encoding="utf-8") as f:
                self.assertEqual(next(csv.reader(f)), CSV_COLUMNS)
            again = read_csv(path, lambda name: 50)  # reads back the same (9 significant digits)
            self.assertEqual([{k: v for k, v in r.items() if k != "light_solid_angle"} for r in again],
                             [{k: v for k, v in r.items() if k != "light_solid_angle"} for r in rows])
            for r, s in zip(again, rows):
                self.assertAlmostEqual(r["light_solid_angle"], s["light_solid_angle"], places=8)

    def test_empty_columns_round_trip(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "results.csv"
            row = {**self.ROW, "seconds": 0.5, "rmse": 0.1, "mse": 0.01, "relmse": 0.02, "family": "",
                   "family_param": None, "light_solid_angle": None}
            write_csv(path, [row, {**row, "scene": "distance_h3", "family": "distance", "family_param": 3.0,
                                   "light_solid_angle": 0.0877}])
            text = path.read_text(encoding="utf-8").splitlines()
            self.assertTrue(text[1].endswith(",,,,default"), text[1])
            self.assertTrue(text[2].endswith(",distance,3,0.0877,default"), text[2])
            row["light_select"] = "default"
            self.assertEqual(read_csv(path, lambda name: 50), [row, {**row, "scene": "distance_h3", "family": "distance",
                                                                     "family_param": 3.0, "light_solid_angle": 0.0877}])


if __name__ == "__main__":
    unittest.main()
