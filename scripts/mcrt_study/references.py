"""Reference images: their cache keys, the cache lookup, rendering them."""

from __future__ import annotations

import datetime
import json

from .config import (
    Config, DEFAULT_LIGHT_SELECT, LEGACY_INTEGRATOR, LEGACY_SAMPLER, REFERENCES_DIR, REF_STRATEGY_PREFERENCE,
    Reference, SceneInfo, Settings,
)
from .mcrt import McrtError, render
from .util import Progress, log, sha256_json, write_text_atomic


def reference_strategies(settings: Settings) -> list[str]:
    """The strategies a reference may use, preferred first (auto: solid angle, then area)."""
    return list(REF_STRATEGY_PREFERENCE) if settings.ref_strategy == "preferred" else [settings.ref_strategy]


def reference_key(settings: Settings, scene: SceneInfo, max_depth: int, strategy: str,
                  binary_hash: str) -> str:
    """Cache key of a reference: scene content, resolution, spp, depth, seed, strategy,
    integrator, sampler and light selection.

    Integrator and sampler enter the key only when they differ from the
    earlier study's (mixture, independent), and the light selection only when
    it is not the default, so that the references cached before keep their keys.
    """
    key = {
        "scene_sha256": scene.content_sha256,
        "width": scene.width,
        "height": scene.height,
        "spp": settings.ref_spp,
        "max_depth": max_depth,
        "seed": settings.ref_seed,
        "strategy": strategy,
    }
    if (settings.ref_integrator, settings.ref_sampler) != (LEGACY_INTEGRATOR, LEGACY_SAMPLER):
        key["integrator"] = settings.ref_integrator
        key["sampler"] = settings.ref_sampler
    if settings.ref_light_select != DEFAULT_LIGHT_SELECT:
        key["light_select"] = settings.ref_light_select
    if settings.ref_key_binary:
        key["mcrt_sha256"] = binary_hash
    return sha256_json(key)[:16]


def find_cached_reference(settings: Settings, scene: SceneInfo, mode: str, binary_hash: str) -> Reference | None:
    """A cached reference for the scene and depth mode, if any matches the current settings.

    With --ref-strategy preferred a solid-angle reference is preferred, then area.
    """
    max_depth = scene.depth(mode)
    for strategy in reference_strategies(settings):
        key = reference_key(settings, scene, max_depth, strategy, binary_hash)
        image = settings.out / REFERENCES_DIR / f"{scene.name}-{key}.exr"
        meta = image.with_suffix(".json")
        if image.is_file() and meta.is_file():
            info = json.loads(meta.read_text(encoding="utf-8"))
            return Reference(scene=scene.name, mode=mode, max_depth=max_depth, path=image, key=key,
                             strategy=strategy, integrator=settings.ref_integrator,
                             sampler=settings.ref_sampler, spp=settings.ref_spp, seed=settings.ref_seed,
                             seconds=float(info.get("render_seconds", float("nan"))), cached=True,
                             light_select=settings.ref_light_select)
    return None


def make_reference(settings: Settings, scene: SceneInfo, mode: str, binary_hash: str,
                   progress: Progress | None) -> Reference:
    """Render (or find in the cache) the reference image of a scene in a depth mode.

    Solid-angle sampling is tried first with --ref-strategy preferred; if this
    build lacks it for the scene, area sampling is used and the reason noted.
    """
    max_depth = scene.depth(mode)
    cached = find_cached_reference(settings, scene, mode, binary_hash)
    order = reference_strategies(settings)
    if cached is not None and (cached.strategy == order[0] or settings.report_only):
        return cached
    if settings.report_only:
        raise SystemExit(f"study.py: --report-only: no cached reference for {scene.name} ({mode})")
    refdir = settings.out / REFERENCES_DIR
    refdir.mkdir(parents=True, exist_ok=True)
    last_error: McrtError | None = None
    for strategy in order:
        if cached is not None and cached.strategy == strategy:
            return cached
        key = reference_key(settings, scene, max_depth, strategy, binary_hash)
        image = refdir / f"{scene.name}-{key}.exr"
        config = Config(strategy, settings.ref_integrator, settings.ref_sampler, settings.ref_light_select)
        say = progress.message if progress else log
        say(f"reference {scene.name} ({mode}, max depth {max_depth}): {settings.ref_spp} spp, "
            f"{scene.width}x{scene.height}, {config.label}, seed {settings.ref_seed}")
        try:
            seconds = render(settings, scene, config, max_depth, settings.ref_spp, settings.ref_seed, image)
        except McrtError as err:
            last_error = err
            if err.unavailable and strategy != order[-1]:
                say(f"reference {scene.name}: {strategy} unavailable ({err}); falling back")
                continue
            raise
        meta = {
            "scene": scene.name, "scene_file": str(scene.path), "scene_sha256": scene.content_sha256,
            "width": scene.width, "height": scene.height, "spp": settings.ref_spp, "mode": mode,
            "max_depth": max_depth, "seed": settings.ref_seed, "strategy": strategy,
            "integrator": config.integrator, "sampler": config.sampler, "light_select": config.light_select,
            "render_seconds": seconds, "mcrt": str(settings.mcrt), "mcrt_sha256": binary_hash,
            "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        }
        write_text_atomic(image.with_suffix(".json"), json.dumps(meta, indent=2) + "\n")
        return Reference(scene=scene.name, mode=mode, max_depth=max_depth, path=image, key=key,
                         strategy=strategy, integrator=config.integrator, sampler=config.sampler,
                         spp=settings.ref_spp, seed=settings.ref_seed, seconds=seconds, cached=False,
                         light_select=config.light_select)
    assert last_error is not None
    raise last_error
