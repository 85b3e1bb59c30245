"""Validation of the translation: the two converged references must agree
within their own noise, max_depth must map as D -> D + 1, and the XML must
load to the same scene as the dict."""
import numpy as np

from . import images, translate, writers

Z_MAX, RMSE_RATIO_MAX = 4.0, 1.2


def silhouette(lights_only, scene):
    """Pixels that see part of a light in an mcrt --max-depth 0 image (neither
    black, nor the background, nor a light's full radiance), grown by one pixel."""
    v = lights_only.astype(np.float64)
    plain = [m["emit"] for m in scene["materials"].values() if m["type"] == "diffuse_light"]
    plain.append(scene.get("render", {}).get("background", [0, 0, 0]))
    whole = np.zeros(v.shape[:2], bool) | ~v.any(axis=2)
    for e in np.asarray(plain, dtype=np.float64):
        whole |= np.all(np.abs(v - e) <= 1e-6 * max(e.max(), 1e-30), axis=2)
    grown = partial = ~whole
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown = grown | np.roll(np.roll(partial, dy, 0), dx, 1)
    return grown


def lights_only(scene_path, mcrt, tmp, size, spp=256):
    out = tmp / "lights-only.exr"
    mcrt.render(scene_path, out, spp, 9, size[0], size[1], max_depth=0, purpose="light silhouette mask")
    img = images.read_exr(out)
    out.unlink()
    return img


def compare_references(mc, mc_meta, mi_img, mi_meta, mcrt_diff, noise_maps=None, mask=None):
    """Mitsuba's reference against mcrt's (signs: Mitsuba relative to mcrt).
    With the references' noise maps and a light-silhouette mask, the RMSE ratio
    is also given without the silhouette pixels, where mcrt's camera (ray
    directions built from absolute float positions) shifts edges by ~1e-3 px."""
    mc64, mi64 = mc.astype(np.float64), mi_img.astype(np.float64)
    mean = mc64.mean()
    d = mi64 - mc64
    se = 100 * np.sqrt(mc_meta["var_of_mean"] + mi_meta["var_of_mean"]) / mean
    mdp = 100 * (mi64.mean() - mean) / mean
    rmse = float(np.sqrt(np.mean(d ** 2)))
    expected = float(np.sqrt(mc_meta["noise_mse"] + mi_meta["noise_mse"]))
    r = {
        "mean_diff_percent": float(mdp), "mean_diff_se_percent": float(se), "z": float(mdp / se),
        "channel_mean_diff_percent": [float(x) for x in 100 * d.mean(axis=(0, 1)) / mc64.mean(axis=(0, 1))],
        "rmse": rmse, "rmse_over_mean": rmse / mean,
        "expected_rmse_from_noise": expected, "expected_rmse_over_mean": expected / mean,
        "rmse_ratio": rmse / expected,
        "red_wall_side": {"mcrt": images.red_side(mc), "mitsuba": images.red_side(mi_img)},
        "mcrt_diff": mcrt_diff,
    }
    r["rmse_ratio_off_silhouettes"] = None
    if noise_maps is not None and mask is not None:
        keep = ~mask
        var = noise_maps[0].astype(np.float64) + noise_maps[1].astype(np.float64)
        r["silhouette_pixels"] = int(mask.sum())
        r["rmse_ratio_noise_maps"] = float(np.sqrt(np.mean(d ** 2) / np.mean(var)))
        r["rmse_ratio_off_silhouettes"] = float(np.sqrt(np.mean(d[keep] ** 2) / np.mean(var[keep])))
        r["silhouette_share_of_d2"] = float(np.sum(d[mask] ** 2) / np.sum(d ** 2))
    ratio = r["rmse_ratio_off_silhouettes"] or r["rmse_ratio"]
    r["agree"] = bool(abs(r["z"]) < Z_MAX and ratio < RMSE_RATIO_MAX
                      and r["red_wall_side"]["mcrt"] == r["red_wall_side"]["mitsuba"])
    return r


def depth_check(scene_path, scene, mcrt, mitsuba, tmp, size, spp, depths=(0, 1, 2, 3)):
    """Image means of mcrt --max-depth D against Mitsuba max_depth D + 1 (the
    mapping used) and D (the mapping if both counted the same thing)."""
    rows = []
    w, h = size
    for dep in depths:
        out = tmp / f"depth{dep}.exr"
        mcrt.render(scene_path, out, spp, 7, w, h, max_depth=dep, purpose="depth check, D = " + ", ".join(map(str, depths)))
        m = float(images.read_exr(out).astype(np.float64).mean())
        out.unlink()
        row = {"mcrt_max_depth": dep, "mcrt_mean": m}
        for label, mdep in (("mitsuba_D+1", dep + 1), ("mitsuba_D", dep)):
            if mdep == 0:
                row[label] = None
                continue
            desc = translate.describe(scene, w, h, spp=spp, max_depth=mdep - 1)
            sc = mitsuba.mi.load_dict(writers.to_dict(desc, mitsuba.mi))
            img, _, _ = mitsuba.render(sc, spp, 7)
            mm = float(img.astype(np.float64).mean())
            row[label] = {"max_depth": mdep, "mean": mm,
                          "diff_percent": 100 * (mm - m) / m if m else None}
        rows.append(row)
    return rows


def xml_check(desc, mitsuba, spp=4, seed=5):
    """Renders the dict and the XML of one description with the same seed."""
    a, _, _ = mitsuba.render(mitsuba.mi.load_dict(writers.to_dict(desc, mitsuba.mi)), spp, seed)
    b, _, _ = mitsuba.render(mitsuba.load_xml(writers.to_xml(desc)), spp, seed)
    return {"max_abs_diff_over_mean": float(np.abs(a - b).max() / max(a.mean(), 1e-30)),
            "resolution": [desc["camera"]["width"], desc["camera"]["height"]], "spp": spp}
