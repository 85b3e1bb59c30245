"""Running the mcrt executable: a render with its time (--stats), an image's error (diff)."""

from __future__ import annotations

import json
import statistics
import subprocess
from pathlib import Path

from .config import DEFAULT_LIGHT_SELECT, NOT_AVAILABLE_MARKERS, Config, SceneInfo, Settings


class McrtError(RuntimeError):
    """An mcrt invocation failed; ``unavailable`` marks a strategy this build lacks (or lacks for
    that kind of scene file)."""

    def __init__(self, message: str, returncode: int, unavailable: bool) -> None:
        super().__init__(message)
        self.returncode = returncode
        self.unavailable = unavailable


def run_mcrt(settings: Settings, args: list[str]) -> subprocess.CompletedProcess:
    """Run mcrt with arguments; raise McrtError with its message on failure."""
    cmd = [str(settings.mcrt), *args]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        message = proc.stderr.strip().splitlines()
        text = message[-1] if message else f"exit status {proc.returncode}"
        unavailable = proc.returncode == 2 and any(m in proc.stderr for m in NOT_AVAILABLE_MARKERS)
        raise McrtError(text, proc.returncode, unavailable)
    return proc


def render(settings: Settings, scene: SceneInfo, config: Config, max_depth: int, spp: int,
           seed: int, image: Path) -> float:
    """Render one image; return render_seconds from --stats (the median over
    settings.time_repeats runs of the same render, which give the same image).

    The integrator, sampler, max depth, strategy and light selection that
    --stats reports are checked against those asked for, so a binary that
    ignored one cannot go unnoticed. The default light selection passes no
    --light-select (the scene's own).
    """
    stats = image.with_suffix(".stats.json")
    args = ["render", str(scene.path), "-o", str(image), "--spp", str(spp), "--seed", str(seed),
            "--width", str(scene.width), "--height", str(scene.height),
            "--max-depth", str(max_depth), "--light-sampling", config.strategy,
            "--integrator", config.integrator, "--sampler", config.sampler,
            "--stats", str(stats), "--quiet"]
    checked = [("integrator", config.integrator), ("sampler", config.sampler), ("max_depth", max_depth),
               ("light_sampling", config.strategy)]
    if config.light_select != DEFAULT_LIGHT_SELECT:
        args += ["--light-select", config.light_select]
        checked.append(("light_select", config.light_select))
    if settings.threads is not None:
        args += ["--threads", str(settings.threads)]
    seconds = []
    for _ in range(max(1, settings.time_repeats)):
        run_mcrt(settings, args)
        data = json.loads(stats.read_text(encoding="utf-8"))
        stats.unlink(missing_ok=True)
        for name, asked in checked:
            if name in data and data[name] != asked:
                raise McrtError(f"--stats reports {name} {data[name]!r}, asked for {asked!r}", 0, False)
        seconds.append(float(data["render_seconds"]))
    return statistics.median(seconds)


def diff(settings: Settings, image: Path, reference: Path) -> dict[str, float]:
    """Error of an image against a reference (mcrt diff --json)."""
    proc = run_mcrt(settings, ["diff", str(image), str(reference), "--json"])
    data = json.loads(proc.stdout)
    return {k: float(data[k]) for k in ("rmse", "mse", "relmse")}
