"""Per-pixel efficiency maps: where in the image a strategy beats area sampling.

For each scene of --pixel-maps, in the run's slice (integrator, sampler, depth
mode: analysis.slice_of), area sampling and every other selected strategy are
rendered at one spp (--pixel-map-spp, default the sweep's largest) with K seeds
(--pixel-map-seeds), seed after seed with the strategies in turn. Against the
cached reference (references.py) each render's squared error per pixel (mean
over R, G, B) is averaged over the seeds, box-filtered (3x3, over the pixels
shown only) to tame the noise, and turned into the per-pixel efficiency ratio

    eff_s / eff_area = (MSE_area * t_area) / (MSE_s * t_s)

with t each strategy's mean render seconds (--stats). The figure shows it in
false colour on a log2 scale, a diverging colour map centred at 1 and clipped
at 1/8 and 8, one panel per strategy beside the reference; pixels where the
reference is black, or where neither strategy has any error, are grey. The
arrays go to pixelmap_<scene>_<mode>.npz beside pixelmap_<scene>_<mode>.png in
OUT; a map whose inputs (scene, size, spp, seeds, slice, strategies, reference)
are unchanged is read back from its .npz instead of rendered again (so
--report-only redraws it).
"""

from __future__ import annotations

import json
import math
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from .analysis import slice_of
from .config import Config, STRATEGY_STYLE, SceneInfo, Settings
from .util import log, sha256_file, sha256_json

CLIP = 8.0  # the colour scale spans 1/CLIP .. CLIP
FILTER_SIZE = 3
BASE_STRATEGY = "area"
COLORMAP = "RdBu"  # red: worse than area sampling, blue: better
MASK_GREY = "#8c8c8c"
COLORBAR_LABEL = "efficiency vs area (×)"


# --------------------------------------------------------------------------
# The maths, on arrays.
# --------------------------------------------------------------------------

def pixel_squared_error(image, reference):
    """Per pixel, the squared error of an RGB image against the reference, averaged over the
    three channels (height x width, float64): the image's MSE is its mean."""
    import numpy as np

    d = np.asarray(image, np.float64) - np.asarray(reference, np.float64)
    return (d * d).mean(axis=-1)


def shown_mask(reference):
    """True where the reference is not black (some channel above 0): the pixels a map shows."""
    import numpy as np

    return np.asarray(reference).max(axis=-1) > 0


def box_filter(values, mask, size: int = FILTER_SIZE):
    """The mean of `values` over a size x size window around every pixel, counting only the
    pixels where `mask` is True (at the image's border, only those inside it); nan where the
    mask is False or the window holds no masked pixel."""
    import numpy as np

    if size < 1 or size % 2 == 0:
        raise ValueError("box_filter: size must be odd and positive")
    values = np.asarray(values, np.float64)
    weight = np.asarray(mask, bool).astype(np.float64)
    r = size // 2
    v = np.pad(np.where(weight > 0, values, 0.0), r)
    w = np.pad(weight, r)
    total = np.zeros_like(values)
    count = np.zeros_like(values)
    h, wd = values.shape
    for dy in range(size):
        for dx in range(size):
            total += v[dy:dy + h, dx:dx + wd]
            count += w[dy:dy + h, dx:dx + wd]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = total / count
    out[~np.asarray(mask, bool) | (count == 0)] = np.nan
    return out


def efficiency_ratio_map(mse_base, seconds_base: float, mse, seconds: float):
    """Per pixel, a strategy's efficiency over the baseline's: (MSE_base t_base) / (MSE t).

    inf where only the strategy has no error, 0 where only the baseline has none, nan where
    neither has any (or an input is nan)."""
    import numpy as np

    num = np.asarray(mse_base, np.float64) * float(seconds_base)
    den = np.asarray(mse, np.float64) * float(seconds)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = num / den
    ratio[(num == 0) & (den == 0)] = np.nan
    return ratio


def log2_scale(ratio, clip: float = CLIP):
    """Ratios on the colour scale: log2 of the ratio clipped to [1/clip, clip], mapped to [0, 1];
    1 is the centre (0.5), 1/clip and below 0, clip and above 1; nan stays nan."""
    import numpy as np

    ratio = np.asarray(ratio, np.float64)
    limit = math.log2(clip)
    with np.errstate(invalid="ignore", divide="ignore"):
        value = np.clip(np.log2(ratio), -limit, limit)
    return 0.5 + 0.5 * value / limit


def colorbar_ticks(clip: float = CLIP) -> list[tuple[float, str]]:
    """(position on the colour scale, label) at the powers of two from 1/clip to clip."""
    k = int(round(math.log2(clip)))
    ticks = []
    for e in range(-k, k + 1):
        label = f"{2 ** e:g}×" if e >= 0 else f"1/{2 ** -e:g}×"
        ticks.append((float(log2_scale(2.0 ** e, clip)), label))
    return ticks


def pixel_map_seeds(count: int, ref_seed: int) -> list[int]:
    """The first `count` seeds from 1 up, leaving out the references' seed."""
    seeds, s = [], 1
    while len(seeds) < count:
        if s != ref_seed:
            seeds.append(s)
        s += 1
    return seeds


def summarise(ratio, mask) -> dict:
    """Median of a ratio map over the pixels it shows and the share of them where the strategy is
    better than the baseline (ratio above 1)."""
    import numpy as np

    shown = np.asarray(ratio)[np.asarray(mask, bool)]
    shown = shown[~np.isnan(shown)]
    if not len(shown):
        return {"median": float("nan"), "better": float("nan")}
    return {"median": float(np.median(shown)), "better": float((shown > 1).mean())}


# --------------------------------------------------------------------------
# One map: render, compute, save, draw.
# --------------------------------------------------------------------------

@dataclass
class PixelMap:
    """One scene's per-pixel efficiency maps (the .npz's contents)."""

    scene: str
    mode: str
    max_depth: int
    integrator: str
    sampler: str
    spp: int
    seeds: list[int]
    width: int
    height: int
    strategies: list[str]  # the baseline first, then those compared with it
    seconds: dict[str, float]  # mean render seconds over the seeds
    mse: dict[str, float]  # image MSE (mean over pixels and seeds)
    ratios: dict[str, object] = field(default_factory=dict)  # filtered ratio maps, nan where not shown
    mask: object = None  # pixels shown
    reference: object = None  # the reference image (for the figure)
    key: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def stem(self) -> str:
        return f"pixelmap_{self.scene}_{self.mode}"


def compute_maps(reference, errors: dict[str, object], seconds: dict[str, float],
                 base: str = BASE_STRATEGY, size: int = FILTER_SIZE) -> tuple[object, dict]:
    """From each strategy's seed-averaged per-pixel squared error and mean seconds: the mask of
    pixels shown and, for every strategy but the baseline, its filtered efficiency ratio map."""
    import numpy as np

    mask = shown_mask(reference)
    filtered = {s: box_filter(e, mask, size) for s, e in errors.items()}
    ratios = {}
    for s in errors:
        if s == base:
            continue
        ratio = efficiency_ratio_map(filtered[base], seconds[base], filtered[s], seconds[s])
        ratio[~mask] = np.nan
        ratios[s] = ratio
    return mask, ratios


def map_key(settings: Settings, scene: SceneInfo, mode: str, config_strategies: list[str], spp: int,
            seeds: list[int], reference_key: str, binary_hash: str = "") -> str:
    """What a map depends on, hashed: its .npz is reused only when this matches (the renderer's
    binary included: a map made by another build is made again)."""
    integrator, sampler, _ = slice_of(settings)
    return sha256_json({
        "scene_sha256": scene.content_sha256, "width": scene.width, "height": scene.height,
        "max_depth": scene.depth(mode), "integrator": integrator, "sampler": sampler,
        "strategies": config_strategies, "spp": spp, "seeds": seeds, "reference": reference_key,
        "filter": FILTER_SIZE, "mcrt_sha256": binary_hash,
    })[:16]


def save_npz(pm: PixelMap, path: Path) -> None:
    """The map's arrays and metadata in a compressed .npz (no pickled objects)."""
    import numpy as np

    meta = {k: getattr(pm, k) for k in ("scene", "mode", "max_depth", "integrator", "sampler", "spp", "seeds",
                                        "width", "height", "strategies", "seconds", "mse", "key", "notes")}
    arrays = {f"ratio_{s}": np.asarray(r, np.float32) for s, r in pm.ratios.items()}
    tmp = path.with_name(f".{path.stem}.tmp.npz")
    np.savez_compressed(tmp, meta=np.array(json.dumps(meta)), mask=np.asarray(pm.mask, bool),
                        reference=np.asarray(pm.reference, np.float32), **arrays)
    tmp.replace(path)


def load_npz(path: Path) -> PixelMap | None:
    """A map saved by save_npz (None if the file is missing or unreadable)."""
    import numpy as np

    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            pm = PixelMap(**meta)
            pm.mask = data["mask"]
            pm.reference = data["reference"]
            pm.ratios = {s: data[f"ratio_{s}"].astype(np.float64) for s in pm.strategies[1:] if f"ratio_{s}" in data}
            return pm
    except (OSError, KeyError, ValueError, TypeError):
        return None


def display_rgb(reference):
    """The reference for display: clipped to [0, 1] after a gamma 2.2 encoding."""
    import numpy as np

    return np.clip(np.asarray(reference, np.float64), 0.0, 1.0) ** (1 / 2.2)


def plot_pixel_map(pm: PixelMap, path: Path) -> None:
    """The reference beside one false-colour panel per strategy (log2 scale centred at 1, clipped
    at 1/CLIP and CLIP, grey where nothing is shown) and a colour bar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    strategies = [s for s in pm.strategies[1:] if s in pm.ratios]
    n = 1 + len(strategies)
    aspect = pm.height / max(pm.width, 1)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 1.2, 3.6 * aspect + 1.1), squeeze=False)
    axes = list(axes.flat)
    axes[0].imshow(display_rgb(pm.reference), interpolation="nearest")
    axes[0].set_title(f"reference ({pm.width}×{pm.height})", fontsize=9)
    cmap = matplotlib.colormaps[COLORMAP].with_extremes(bad=MASK_GREY)
    image = None
    for ax, s in zip(axes[1:], strategies):
        scaled = np.ma.masked_invalid(log2_scale(pm.ratios[s]))
        image = ax.imshow(scaled, cmap=cmap, vmin=0.0, vmax=1.0, interpolation="nearest")
        stats = summarise(pm.ratios[s], pm.mask)
        whole = (pm.mse[BASE_STRATEGY] * pm.seconds[BASE_STRATEGY]) / (pm.mse[s] * pm.seconds[s]) \
            if pm.mse.get(s, 0) > 0 and pm.seconds.get(s, 0) > 0 else float("nan")
        ax.set_title(f"{STRATEGY_STYLE.get(s, {'label': s})['label']}\nimage {whole:.3g}×, "
                     f"median pixel {stats['median']:.3g}×", fontsize=9)
    for ax in axes:
        ax.set_xticks([])
        ax.set_yticks([])
    if image is not None:
        bar = fig.colorbar(image, ax=axes[1:], fraction=0.046 / max(1, len(strategies)) ** 0.5, pad=0.02,
                           shrink=0.85)
        ticks = colorbar_ticks()
        bar.set_ticks([t for t, _ in ticks])
        bar.set_ticklabels([label for _, label in ticks])
        bar.set_label(COLORBAR_LABEL)
    fig.suptitle(f"{pm.scene}, {pm.mode} (max depth {pm.max_depth}), {pm.integrator}, {pm.sampler}: "
                 f"{pm.spp} spp × {len(pm.seeds)} seeds", fontsize=10)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def render_errors(settings: Settings, scene: SceneInfo, mode: str, strategies: list[str], spp: int,
                  seeds: list[int], reference, tmpdir: Path) -> tuple[dict, dict, list[str]]:
    """Render every strategy with every seed (seed after seed, strategies in turn); return each
    strategy's per-pixel squared error averaged over the seeds, its mean render seconds, and
    notes on strategies this build lacks (left out)."""
    import numpy as np

    from .exr import read_rgb
    from .mcrt import McrtError, render

    integrator, sampler, _ = slice_of(settings)
    sums = {s: np.zeros(reference.shape[:2]) for s in strategies}
    times: dict[str, list[float]] = {s: [] for s in strategies}
    notes: list[str] = []
    left = list(strategies)
    for seed in seeds:
        for s in list(left):
            image = tmpdir / f"{scene.name}-{s}-{seed}.exr"
            try:
                times[s].append(render(settings, scene, Config(s, integrator, sampler), scene.depth(mode), spp,
                                       seed, image))
            except McrtError as err:
                if not err.unavailable:
                    raise
                notes.append(f"{s}: not available in this build ({err})")
                left.remove(s)
                continue
            sums[s] += pixel_squared_error(read_rgb(image), reference)
            image.unlink(missing_ok=True)
    return ({s: sums[s] / len(seeds) for s in left}, {s: float(np.mean(times[s])) for s in left}, notes)


def make_pixel_map(settings: Settings, scene: SceneInfo, spp: int, seeds: list[int]) -> PixelMap | None:
    """One scene's map in the run's slice: read back from its .npz when its inputs are unchanged,
    else rendered (not with --report-only); drawn to its PNG. None when it cannot be made."""
    from .exr import read_rgb
    from .references import find_cached_reference, make_reference

    integrator, sampler, mode = slice_of(settings)
    if mode not in [m for m, _ in scene.depth_modes(settings.depths)]:
        mode = scene.depth_modes(settings.depths)[0][0]
    strategies = [BASE_STRATEGY, *[s for s in settings.strategies if s != BASE_STRATEGY]]
    binary_hash = sha256_file(settings.mcrt) if settings.mcrt.is_file() else ""
    if settings.report_only:
        ref = find_cached_reference(settings, scene, mode, binary_hash)
    else:
        ref = make_reference(settings, scene, mode, binary_hash, None)
    if ref is None:
        log(f"pixel map {scene.name}: no cached reference ({mode}); not made")
        return None
    key = map_key(settings, scene, mode, strategies, spp, seeds, ref.key, binary_hash)
    stem = f"pixelmap_{scene.name}_{mode}"
    npz = settings.out / f"{stem}.npz"
    pm = load_npz(npz)
    if pm is None or pm.key != key:
        if settings.report_only:
            log(f"pixel map {scene.name}: {npz.name} missing or made with other settings; not rendered "
                "with --report-only")
            return None
        log(f"pixel map {scene.name} ({mode}, {integrator}, {sampler}): {len(strategies)} strategies × "
            f"{len(seeds)} seeds at {spp} spp, {scene.width}x{scene.height}")
        reference = read_rgb(ref.path)
        tmpdir = Path(tempfile.mkdtemp(prefix=".pixelmap-", dir=settings.out))
        try:
            errors, seconds, notes = render_errors(settings, scene, mode, strategies, spp, seeds, reference, tmpdir)
        finally:
            shutil.rmtree(tmpdir, ignore_errors=True)
        if BASE_STRATEGY not in errors:
            log(f"pixel map {scene.name}: area sampling not available; not made")
            return None
        mask, ratios = compute_maps(reference, errors, seconds)
        pm = PixelMap(scene=scene.name, mode=mode, max_depth=scene.depth(mode), integrator=integrator,
                      sampler=sampler, spp=spp, seeds=seeds, width=scene.width, height=scene.height,
                      strategies=[s for s in strategies if s in errors], seconds=seconds,
                      mse={s: float(e.mean()) for s, e in errors.items()}, ratios=ratios, mask=mask,
                      reference=reference, key=key, notes=notes)
        save_npz(pm, npz)
    plot_pixel_map(pm, settings.out / f"{stem}.png")
    return pm


def make_pixel_maps(settings: Settings) -> list[PixelMap]:
    """The maps of every scene of --pixel-maps (none by default)."""
    from .scenes import load_scene

    if not settings.pixel_maps:
        return []
    if not [s for s in settings.strategies if s != BASE_STRATEGY]:
        log("pixel maps: only area sampling selected, nothing to compare; not made")
        return []
    spp = settings.pixel_map_spp or max(settings.spp)
    seeds = pixel_map_seeds(settings.pixel_map_seeds, settings.ref_seed)
    maps = []
    for name in dict.fromkeys(settings.pixel_maps):
        pm = make_pixel_map(settings, load_scene(name, settings), spp, seeds)
        if pm is not None:
            maps.append(pm)
    return maps


def pixel_map_figures(maps: list[PixelMap]) -> list[tuple[str, str]]:
    """(PNG name, caption) of every map."""
    return [(f"{pm.stem}.png", f"{pm.scene}: per-pixel efficiency over area sampling ({pm.mode} depth mode, "
             f"{pm.integrator}, {pm.sampler}, {pm.spp} spp, {len(pm.seeds)} seeds); arrays in {pm.stem}.npz.")
            for pm in maps]


def pixel_map_section(maps: list[PixelMap]) -> str:
    """The report's section on the maps (empty without any)."""
    from .report import fmt, md_table

    if not maps:
        return ""
    parts = [
        "\n## Per-pixel efficiency against area sampling\n\n"
        "For each scene of `--pixel-maps`, in the slice of the area-against-solid-angle tables "
        "(integrator, sampler, depth mode), area sampling and every other strategy rendered at one spp with "
        "several seeds (seed after seed, the strategies in turn); per pixel the squared error against "
        "the reference (mean over R, G, B), averaged over the seeds and box-filtered (3×3, over the "
        "pixels shown), gives the efficiency ratio (MSE_area · t_area) / (MSE_s · t_s), t the mean "
        "render seconds. Colour: log2 of the ratio, blue where the strategy beats area sampling, red "
        f"where it loses, clipped at 1/{CLIP:g}× and {CLIP:g}×; grey: the reference is black there, or "
        "neither strategy has any error. The table gives the whole image's ratio (from the image MSE), "
        "the median over the pixels shown and the share of them where the strategy is better.\n\n"]
    rows = []
    for pm in maps:
        for s in pm.strategies:
            whole = ((pm.mse[BASE_STRATEGY] * pm.seconds[BASE_STRATEGY]) / (pm.mse[s] * pm.seconds[s])
                     if pm.mse[s] > 0 and pm.seconds[s] > 0 else float("nan"))
            stats = summarise(pm.ratios[s], pm.mask) if s in pm.ratios else {"median": 1.0, "better": float("nan")}
            better = f"{fmt(100 * stats['better'], 3)} %" if math.isfinite(stats["better"]) else "–"
            rows.append([pm.scene, f"{pm.mode}, {pm.integrator}, {pm.sampler}", s, f"{pm.spp} × {len(pm.seeds)}",
                         fmt(pm.seconds[s], 3), fmt(pm.mse[s], 4), fmt(whole, 3), fmt(stats["median"], 3), better])
    parts.append(md_table(["scene", "slice", "strategy", "spp × seeds", "mean seconds", "image MSE",
                           "image ratio", "median pixel ratio", "pixels better"], rows, 3))
    for pm in maps:
        if pm.notes:
            parts.append("\n" + "\n".join(f"- {pm.scene}: {n}" for n in pm.notes) + "\n")
        name = f"{pm.stem}.png"
        parts.append(f"\n![{name}]({name})\n\n{pixel_map_figures([pm])[0][1]}\n")
    return "".join(parts)
