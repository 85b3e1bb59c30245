"""Small helpers: hashes, atomic writes, logging, the progress bar."""

from __future__ import annotations

import hashlib
import json
import math
import sys
import time
from pathlib import Path


def sha256_file(path: Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def sha256_json(obj: object) -> str:
    """Hex SHA-256 of a JSON value (sorted keys), used for cache keys."""
    return hashlib.sha256(json.dumps(obj, sort_keys=True).encode()).hexdigest()


def write_text_atomic(path: Path, text: str) -> None:
    """Write a text file through a temporary name so it is never half-written."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)


def log(message: str) -> None:
    """A message on stderr."""
    print(f"study: {message}", file=sys.stderr, flush=True)


def bad_input(message: str) -> SystemExit:
    """Print one line, 'study.py: MESSAGE', on stderr and return the SystemExit (status 2) to raise."""
    print(f"study.py: {message}", file=sys.stderr, flush=True)
    return SystemExit(2)


def format_duration(seconds: float) -> str:
    """Seconds as H:MM:SS or M:SS."""
    seconds = max(0, int(round(seconds)))
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class Progress:
    """A plain-text progress bar on stderr, weighted by work (samples).

    On a terminal the bar is redrawn in place; otherwise (logs, ctest) one
    line is printed at most every few seconds and at the end.
    """

    def __init__(self, total_work: float, width: int = 30) -> None:
        self.total = max(total_work, 1e-9)
        self.done = 0.0
        self.width = width
        self.start = time.monotonic()
        self.tty = sys.stderr.isatty()
        self.last_print = 0.0
        self.last_len = 0

    def add_work(self, work: float) -> None:
        """Grow the total (work found on the way, e.g. a reference to render again)."""
        self.total += work

    def advance(self, work: float, label: str) -> None:
        """Count `work` as done and redraw with `label` (the point just finished)."""
        self.done = min(self.total, self.done + work)
        self.draw(label)

    def draw(self, label: str, force: bool = False) -> None:
        """Draw the bar now (on a terminal) or when enough time has passed (elsewhere)."""
        now = time.monotonic()
        frac = self.done / self.total
        elapsed = now - self.start
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        filled = int(round(frac * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        eta_text = format_duration(eta) if math.isfinite(eta) else "?"
        line = f"[{bar}] {frac * 100:5.1f}% elapsed {format_duration(elapsed)} eta {eta_text}  {label}"
        if self.tty:
            pad = " " * max(0, self.last_len - len(line))
            sys.stderr.write("\r" + line + pad)
            sys.stderr.flush()
            self.last_len = len(line)
        elif force or now - self.last_print >= 5.0 or self.done >= self.total:
            print(line, file=sys.stderr, flush=True)
            self.last_print = now

    def message(self, text: str) -> None:
        """Print a line without breaking the bar."""
        if self.tty and self.last_len:
            sys.stderr.write("\r" + " " * self.last_len + "\r")
            self.last_len = 0
        log(text)

    def finish(self) -> None:
        """End the bar's line."""
        if self.tty and self.last_len:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.last_len = 0
