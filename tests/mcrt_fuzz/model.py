"""What a fuzz case is: its input files, its command and what it expects.

A case is pure data plus lazily built file contents, so that listing the
cases (``--list``) costs nothing and every case can be rebuilt from the run's
seed and its own id alone (``case_rng``).
"""

from __future__ import annotations

import hashlib
import random
from dataclasses import dataclass, field
from typing import Callable, Union

# The classes a case can end in.  ``ok`` ones first, then the bugs.
OK_CLASSES = ("rendered", "clean_refusal")
BUG_CLASSES = ("crash", "hang", "memory", "nonfinite", "dirty_refusal", "bad_output")
# ``unexpected``: an ok class, but not the one the case declared it must end in.
ALL_CLASSES = OK_CLASSES + BUG_CLASSES + ("unexpected",)

SENTINEL = b"sentinel"

# File contents may be given as bytes, str (written as UTF-8) or a callable
# returning either (built only when the case is materialised).
Content = Union[bytes, str, Callable[[], Union[bytes, str]]]


@dataclass
class Entry:
    """One thing a case creates in its directory before mcrt runs.

    kind: ``file`` (``data``), ``fifo`` (os.mkfifo), ``symlink`` (to
    ``target``), ``dir`` (an empty directory), ``sparse`` (``data`` then
    zeros up to ``size`` bytes, a hole that takes no disk space).  ``path``
    is relative to the case directory; parent directories are made as needed.
    """
    kind: str
    path: str
    data: Content | None = None
    target: str | None = None
    size: int = 0

    def content(self) -> bytes:
        d = self.data() if callable(self.data) else self.data
        if d is None:
            return b""
        return d.encode("utf-8") if isinstance(d, str) else bytes(d)


def file(path: str, data: Content) -> Entry:
    return Entry("file", path, data=data)


def fifo(path: str) -> Entry:
    return Entry("fifo", path)


def symlink(path: str, target: str) -> Entry:
    return Entry("symlink", path, target=target)


def directory(path: str) -> Entry:
    return Entry("dir", path)


def sparse(path: str, head: Content, size: int) -> Entry:
    return Entry("sparse", path, data=head, size=size)


@dataclass
class Case:
    """One run of mcrt.

    id        "family/name", unique; also the case's directory under cases/.
    family    the attack family (the id's first part).
    entries   files to create in the case directory.
    argv      the command after the executable, run with cwd = the case dir.
    kind      render | samples | diff | other: what a success must leave
              behind (other: nothing in particular).
    outputs   paths pre-created with the sentinel (outputs mcrt may write).
    image     the image a successful render must write (magic by extension).
    stats     the statistics file a successful render must write, or None.
    csv       the CSV a successful ``samples`` must write, or None.
    names     the names one of which a refusal line must contain (the scene,
              the corrupted file, the flag, the image).
    expect    the classes the case must end in; None: any ok class.
    note      one line saying what is attacked (for the report).
    slow      a hint: may run to the timeout (FIFOs, /dev/zero, bombs); such
              cases start first so that they overlap the quick ones.
    """
    id: str
    entries: list[Entry]
    argv: list[str]
    kind: str = "render"
    outputs: list[str] = field(default_factory=list)
    image: str | None = None
    stats: str | None = None
    csv: str | None = None
    names: list[str] = field(default_factory=list)
    expect: tuple[str, ...] | None = None
    note: str = ""
    slow: bool = False
    # With ``mcrt diff`` of images that hold NaN, a NaN result is right.
    allow_nonfinite: bool = False

    @property
    def family(self) -> str:
        return self.id.split("/", 1)[0]

    def sentinel_outputs(self) -> list[str]:
        """The outputs that get the sentinel: relative ones the case's own
        entries do not already provide."""
        made = {e.path for e in self.entries}
        return [o for o in self.outputs
                if o and not o.startswith("/") and o not in made and o.rstrip("/") not in made]


# The default render flags: a tiny, quick image on one thread.
RENDER_FLAGS = ["--width", "8", "--height", "8", "--spp", "1", "--threads", "1", "--quiet"]


def render_case(case_id: str, scene: str, entries: list[Entry], *, extra: list[str] | None = None,
                flags: list[str] | None = None, names: list[str] | None = None,
                expect: tuple[str, ...] | None = None, note: str = "", slow: bool = False) -> Case:
    """A ``mcrt render SCENE -o out.png ... --stats stats.json`` case.

    ``flags`` replaces the default size/spp/threads flags (for cases that
    test those flags); ``extra`` is appended to them.
    """
    base = RENDER_FLAGS if flags is None else flags
    argv = ["render", scene, "-o", "out.png", *base, "--stats", "stats.json", *(extra or [])]
    return Case(case_id, entries, argv, kind="render", outputs=["out.png", "stats.json"],
                image="out.png", stats="stats.json", names=[scene, *(names or [])],
                expect=expect, note=note, slow=slow)


def samples_case(case_id: str, scene: str, entries: list[Entry], args: list[str], *,
                 names: list[str] | None = None, expect: tuple[str, ...] | None = None,
                 note: str = "") -> Case:
    """A ``mcrt samples SCENE ARGS -o out.csv`` case."""
    argv = ["samples", scene, *args, "-o", "out.csv"]
    return Case(case_id, entries, argv, kind="samples", outputs=["out.csv"], csv="out.csv",
                names=[scene, *(names or [])], expect=expect, note=note)


def diff_case(case_id: str, image: str, reference: str, entries: list[Entry], *,
              expect: tuple[str, ...] | None = None, note: str = "", slow: bool = False,
              allow_nonfinite: bool = False) -> Case:
    """A ``mcrt diff IMAGE REFERENCE`` case (it writes nothing)."""
    return Case(case_id, entries, ["diff", image, reference], kind="diff",
                names=[image, reference], expect=expect, note=note, slow=slow,
                allow_nonfinite=allow_nonfinite)


def case_rng(seed: int, case_id: str) -> random.Random:
    """The case's own random stream: a hash of the run's seed and the case id,
    so that any case can be replayed alone (never a shared stream)."""
    h = hashlib.sha256(f"{seed}\0{case_id}".encode("utf-8")).digest()
    return random.Random(int.from_bytes(h[:8], "big"))
