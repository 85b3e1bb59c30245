"""Unit tests of the per-pixel efficiency maps' maths and of the EXR reader, on synthetic arrays.

    .venv/bin/python -m unittest discover -s scripts/mcrt_study/tests -t scripts
"""

import math
import struct
import tempfile
import unittest
import zlib
from pathlib import Path

import numpy as np

from mcrt_study.exr import ExrError, read_exr, read_rgb
from mcrt_study.pixelmaps import (
    PixelMap, box_filter, colorbar_ticks, compute_maps, efficiency_ratio_map, load_npz, log2_scale,
    pixel_map_section, pixel_map_seeds, pixel_squared_error, plot_pixel_map, save_npz, shown_mask, summarise,
)


class SquaredErrorTest(unittest.TestCase):
    def test_mean_over_channels(self):
        ref = np.zeros((2, 3, 3))
        img = np.zeros((2, 3, 3))
        img[0, 1] = [1.0, 2.0, 3.0]
        e = pixel_squared_error(img, ref)
        self.assertEqual(e.shape, (2, 3))
        self.assertAlmostEqual(e[0, 1], (1 + 4 + 9) / 3)
        self.assertEqual(e.sum(), e[0, 1])
        # The image MSE (as mcrt diff reports it) is the mean of the map.
        self.assertAlmostEqual(e.mean(), ((img - ref) ** 2).mean())

    def test_mask_is_the_non_black_reference(self):
        ref = np.zeros((2, 2, 3))
        ref[0, 0, 2] = 0.5
        ref[1, 1] = 1.0
        np.testing.assert_array_equal(shown_mask(ref), [[True, False], [False, True]])


class BoxFilterTest(unittest.TestCase):
    def test_constant_stays_constant(self):
        v = np.full((5, 6), 2.5)
        np.testing.assert_allclose(box_filter(v, np.ones_like(v, bool)), v)

    def test_window_mean_and_border(self):
        v = np.arange(16, dtype=float).reshape(4, 4)
        out = box_filter(v, np.ones_like(v, bool))
        self.assertAlmostEqual(out[1, 1], v[0:3, 0:3].mean())
        self.assertAlmostEqual(out[2, 2], v[1:4, 1:4].mean())
        self.assertAlmostEqual(out[0, 0], v[0:2, 0:2].mean())  # only the pixels inside the image
        self.assertAlmostEqual(out[3, 1], v[2:4, 0:3].mean())

    def test_masked_pixels_neither_count_nor_show(self):
        v = np.ones((3, 3))
        v[1, 1] = 10.0
        mask = np.ones((3, 3), bool)
        mask[0, 0] = False
        v[0, 0] = 1e9  # excluded: must not leak into its neighbours
        out = box_filter(v, mask)
        self.assertTrue(np.isnan(out[0, 0]))
        self.assertAlmostEqual(out[1, 1], (7 * 1 + 10) / 8)
        self.assertAlmostEqual(out[0, 1], (4 * 1 + 10) / 5)

    def test_size_one_is_the_identity_on_the_mask(self):
        v = np.random.default_rng(1).random((4, 5))
        mask = v > 0.3
        out = box_filter(v, mask, 1)
        np.testing.assert_allclose(out[mask], v[mask])
        self.assertTrue(np.all(np.isnan(out[~mask])))
        with self.assertRaises(ValueError):
            box_filter(v, mask, 2)


class RatioTest(unittest.TestCase):
    def test_ratio_of_efficiencies(self):
        mse_area = np.array([[4.0, 1.0], [0.0, 0.0]])
        mse_s = np.array([[1.0, 4.0], [1.0, 0.0]])
        r = efficiency_ratio_map(mse_area, 2.0, mse_s, 4.0)
        self.assertAlmostEqual(r[0, 0], (4 * 2) / (1 * 4))  # 2x: the strategy is more efficient
        self.assertAlmostEqual(r[0, 1], (1 * 2) / (4 * 4))
        self.assertEqual(r[1, 0], 0.0)  # only the baseline is exact
        self.assertTrue(np.isnan(r[1, 1]))  # neither has any error
        self.assertEqual(efficiency_ratio_map(np.array([1.0]), 1.0, np.array([0.0]), 1.0)[0], np.inf)

    def test_compute_maps(self):
        # Area: MSE 2 everywhere, 1 s; solid angle: MSE 1 on the left half, 4 on the right, 1 s;
        # the reference is black in its first row.
        h, w = 6, 8
        ref = np.ones((h, w, 3))
        ref[0] = 0.0
        sa = np.where(np.arange(w) < w // 2, 1.0, 4.0) * np.ones((h, 1))
        mask, ratios = compute_maps(ref, {"area": np.full((h, w), 2.0), "solid-angle": sa},
                                    {"area": 1.0, "solid-angle": 1.0})
        r = ratios["solid-angle"]
        self.assertEqual(list(ratios), ["solid-angle"])
        self.assertTrue(np.all(np.isnan(r[0])))
        np.testing.assert_allclose(r[1:, :3], 2.0)  # away from the edge between the halves
        np.testing.assert_allclose(r[1:, 5:], 0.5)
        self.assertAlmostEqual(r[3, 3], 2.0 / ((6 * 1 + 3 * 4) / 9))  # the filter straddles the edge
        s = summarise(r, mask)
        self.assertAlmostEqual(s["better"], 3 / 8)  # columns 0-2; column 3 is at 1 after filtering
        # Times enter as area's over the strategy's.
        _, slow = compute_maps(ref, {"area": np.full((h, w), 2.0), "solid-angle": sa},
                               {"area": 1.0, "solid-angle": 2.0})
        np.testing.assert_allclose(slow["solid-angle"][1:, :3], 1.0)


class ColourScaleTest(unittest.TestCase):
    def test_centre_ends_and_clipping(self):
        self.assertEqual(float(log2_scale(1.0)), 0.5)
        self.assertEqual(float(log2_scale(8.0)), 1.0)
        self.assertEqual(float(log2_scale(1 / 8)), 0.0)
        self.assertEqual(float(log2_scale(100.0)), 1.0)
        self.assertEqual(float(log2_scale(1e-6)), 0.0)
        self.assertEqual(float(log2_scale(np.inf)), 1.0)
        self.assertEqual(float(log2_scale(0.0)), 0.0)
        self.assertTrue(np.isnan(log2_scale(np.nan)))
        # Symmetric in log: 2x and 1/2x sit equally far from the centre.
        self.assertAlmostEqual(float(log2_scale(2.0)) - 0.5, 0.5 - float(log2_scale(0.5)))
        self.assertAlmostEqual(float(log2_scale(2.0, clip=4.0)), 0.75)

    def test_colorbar_ticks(self):
        ticks = colorbar_ticks(8.0)
        self.assertEqual([label for _, label in ticks], ["1/8×", "1/4×", "1/2×", "1×", "2×", "4×", "8×"])
        self.assertEqual(ticks[3][0], 0.5)
        self.assertEqual([t for t, _ in ticks], sorted(t for t, _ in ticks))

    def test_seeds_leave_out_the_reference_seed(self):
        self.assertEqual(pixel_map_seeds(4, 7919), [1, 2, 3, 4])
        self.assertEqual(pixel_map_seeds(4, 2), [1, 3, 4, 5])


def synthetic_map() -> PixelMap:
    h, w = 10, 12
    ref = np.ones((h, w, 3)) * 0.3
    ref[:2] = 0.0
    errors = {"area": np.full((h, w), 2.0), "solid-angle": np.linspace(0.1, 40, h * w).reshape(h, w),
              "auto": np.full((h, w), 1.0)}
    seconds = {"area": 1.0, "solid-angle": 1.5, "auto": 1.2}
    mask, ratios = compute_maps(ref, errors, seconds)
    return PixelMap(scene="toy", mode="global", max_depth=50, integrator="mis", sampler="sobol", spp=4,
                    seeds=[1, 2, 3], width=w, height=h, strategies=["area", "solid-angle", "auto"],
                    seconds=seconds, mse={s: float(e.mean()) for s, e in errors.items()}, ratios=ratios,
                    mask=mask, reference=ref, key="abc")


class MapFilesTest(unittest.TestCase):
    def test_npz_round_trip_png_and_section(self):
        pm = synthetic_map()
        with tempfile.TemporaryDirectory() as tmp:
            npz = Path(tmp) / f"{pm.stem}.npz"
            save_npz(pm, npz)
            back = load_npz(npz)
            self.assertEqual((back.scene, back.key, back.seeds, back.strategies), ("toy", "abc", [1, 2, 3],
                                                                                 ["area", "solid-angle", "auto"]))
            for s in ("solid-angle", "auto"):
                np.testing.assert_allclose(back.ratios[s], pm.ratios[s], rtol=1e-6)
            np.testing.assert_array_equal(back.mask, pm.mask)
            self.assertIsNone(load_npz(Path(tmp) / "missing.npz"))
            png = Path(tmp) / f"{pm.stem}.png"
            plot_pixel_map(back, png)
            self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
        text = pixel_map_section([pm])
        self.assertIn("## Per-pixel efficiency against area sampling", text)
        self.assertIn("![pixelmap_toy_global.png](pixelmap_toy_global.png)", text)
        # auto: MSE 1 against area's 2 at 1.2 s against 1 s: 2/1.2 everywhere shown.
        self.assertIn("| toy | global, mis, sobol | auto | 4 × 3 | 1.2 | 1 | 1.67 | 1.67 | 100 % |", text)
        self.assertEqual(pixel_map_section([]), "")


def exr_bytes(planes: dict, compression: int, lines_per_chunk: int, half: bool = False) -> bytes:
    """A scanline OpenEXR file written the way the format's documentation describes (test writer)."""
    names = sorted(planes)
    h, w = planes[names[0]].shape
    dtype = np.dtype("<f2" if half else "<f4")

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", 1 if half else 2, 0, 1, 1) for n in names) + b"\0"
    header = struct.pack("<iI", 20000630, 2)
    header += attr("channels", "chlist", chlist)
    header += attr("compression", "compression", bytes([compression]))
    header += attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    header += attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    header += attr("lineOrder", "lineOrder", b"\0")
    header += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    header += b"\0"
    chunks = []
    for y0 in range(0, h, lines_per_chunk):
        raw = b"".join(planes[n][y].astype(dtype).tobytes() for y in range(y0, min(h, y0 + lines_per_chunk))
                       for n in names)
        if compression:
            b = np.frombuffer(raw, np.uint8)
            split = np.concatenate([b[0::2], b[1::2]]).astype(np.int64)
            pred = split.copy()
            pred[1:] = (split[1:] - split[:-1] + 128) & 0xFF
            packed = zlib.compress(pred.astype(np.uint8).tobytes())
            data = packed if len(packed) < len(raw) else raw
        else:
            data = raw
        chunks.append(struct.pack("<ii", y0, len(data)) + data)
    start = len(header) + 8 * len(chunks)
    offsets, at = [], start
    for c in chunks:
        offsets.append(at)
        at += len(c)
    return header + struct.pack(f"<{len(chunks)}Q", *offsets) + b"".join(chunks)


class ExrReaderTest(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(3)
        h, w = 37, 21  # not a multiple of the 16 lines of a ZIP chunk
        self.planes = {c: rng.random((h, w)).astype(np.float32) * 10 for c in "RGB"}
        self.planes["G"][5:9] = 0.25  # compressible runs

    def check(self, data: bytes, half: bool = False):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "t.exr"
            path.write_bytes(data)
            rgb = read_rgb(path)
            planes = read_exr(path)
        want = np.stack([self.planes[c] for c in "RGB"], axis=-1)
        if half:
            want = want.astype(np.float16).astype(np.float32)
        np.testing.assert_array_equal(rgb, want)
        self.assertEqual(sorted(planes), ["B", "G", "R"])

    def test_uncompressed(self):
        self.check(exr_bytes(self.planes, 0, 1))

    def test_zips_and_zip(self):
        self.check(exr_bytes(self.planes, 2, 1))
        self.check(exr_bytes(self.planes, 3, 16))

    def test_chunk_stored_raw(self):
        noise = {c: np.random.default_rng(9).random((3, 2)).astype(np.float32) for c in "RGB"}
        self.planes = noise  # too small and random to compress: the writer stores it raw
        self.check(exr_bytes(noise, 3, 16))

    def test_half(self):
        self.check(exr_bytes(self.planes, 3, 16, half=True), half=True)

    def test_rejects_other_files(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "t.exr"
            path.write_bytes(b"P6\n1 1\n255\n\0\0\0")
            with self.assertRaises(ExrError):
                read_exr(path)
            path.write_bytes(exr_bytes(self.planes, 4, 32))  # PIZ
            with self.assertRaises(ExrError):
                read_exr(path)


if __name__ == "__main__":
    unittest.main()
