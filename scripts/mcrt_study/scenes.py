"""The scenes of the study: scene files by name or path, their size and depth.

Every --scenes entry becomes one SceneInfo in load_scene. Scene families generated
by the study (variants of a scene file written on the fly) belong in this module,
as another way for an entry to become SceneInfo objects (see the section at the end).
"""

from __future__ import annotations

import json
from pathlib import Path

from .config import DEFAULT_SCALE, MCRT_DEFAULT_MAX_DEPTH, SCENES_DIR, SceneInfo, Settings
from .util import sha256_file


def scene_path(spec: str) -> Path:
    """A scene's file from its name (scenes/NAME.json) or path."""
    path = Path(spec)
    return SCENES_DIR / f"{spec}.json" if not path.suffix else path


def scene_file_max_depth(path: Path) -> int:
    """The max depth a scene file asks for (mcrt's default when it gives none)."""
    render = json.loads(path.read_text(encoding="utf-8")).get("render", {})
    return int(render.get("max_depth", MCRT_DEFAULT_MAX_DEPTH))


def load_scene(spec: str, settings: Settings) -> SceneInfo:
    """Find a scene by name or path, and read its size and depth (with the overrides applied)."""
    path = scene_path(spec)
    if not path.is_file():
        raise SystemExit(f"study.py: scene not found: {spec}")
    data = json.loads(path.read_text(encoding="utf-8"))
    camera = data.get("camera", {})
    width = settings.width or int(round(int(camera.get("width", 0)) * DEFAULT_SCALE))
    height = settings.height or int(round(int(camera.get("height", 0)) * DEFAULT_SCALE))
    if width <= 0 or height <= 0:
        raise SystemExit(f"study.py: {path}: no camera width/height; pass --width and --height")
    max_depth = settings.max_depth or scene_file_max_depth(path)
    return SceneInfo(name=path.stem, path=path.resolve(), content_sha256=sha256_file(path),
                     width=width, height=height, max_depth=max_depth)


# Generated scene families: none yet. A family would expand one --scenes entry into
# several scene files (written under the output directory, so that their content
# hash keys the references and the state as for any scene file) and return their
# SceneInfo objects; cli.main would call it where it calls load_scene now.
