"""Classification of a finished run (see the package docstring for the classes).

Order: hang, memory, crash (signal, 134/136/139, "terminate called", a
sanitizer report), then by exit status: 0 is a success that must have left
the right outputs (``rendered``, ``nonfinite`` or ``bad_output``), anything
else a refusal that is ``clean_refusal`` only if it keeps every rule.
Finally a case's declared expectation turns an ok class it did not expect
into ``unexpected``.
"""

from __future__ import annotations

import json
import math
import os
import re

from .model import BUG_CLASSES, OK_CLASSES, SENTINEL

CRASH_STATUSES = {134, 136, 139}
SANITIZER_MARKERS = ("ERROR: AddressSanitizer", "runtime error:", "LeakSanitizer", "ERROR: ThreadSanitizer",
                     "ERROR: MemorySanitizer")
# Text that is a library's own message or a C++ exception's name, not mcrt's
# (regular expressions).  CLI11's messages about flags name the flag and
# are accepted.
LIBRARY_MARKERS = (r"libpng", r"\bzlib\b", r"what\(\):", r"std::", r"basic_string", r"bad_alloc",
                   r"\bsto(i|f|d|l|ul|ull|ll)\b", r"json\.exception", r"vector::", r"\b_M_", r"Assertion",
                   r"doesn't know about", r"Iex::")
# Messages that give no reason.
VAGUE_MARKERS = ("no reason given", "unknown error", "Unknown error")
MAX_LINE = 1000
MAGIC = {".png": (b"\x89PNG\r\n\x1a\n",), ".exr": (b"\x76\x2f\x31\x01",), ".ppm": (b"P6", b"P3")}
NONFINITE_LINE = "non-finite radiance samples were dropped"
CSV_HEADER = "u1,u2,dx,dy,dz,px,py,pz,pdf"
DIFF_KEYS = ("rmse", "mse", "relmse", "mean_diff_percent")


def classify(res, opts) -> None:
    """Set res.observed, res.cls and res.reasons."""
    case = res.case
    err = res.stderr.decode("utf-8", "replace")
    reasons: list[str] = []
    if res.timed_out:
        cls = "hang"
        reasons.append(f"still running after {opts.timeout:g} s")
    elif res.mem_killed or res.peak_rss > opts.mem_limit:
        cls = "memory"
        reasons.append(f"peak RSS {res.peak_rss / 2**20:.0f} MiB > {opts.mem_limit / 2**20:.0f} MiB")
    elif res.exit_status is not None and (res.exit_status < 0 or res.exit_status in CRASH_STATUSES):
        cls = "crash"
        reasons.append(f"signal {-res.exit_status}" if res.exit_status < 0 else f"exit status {res.exit_status}")
    elif "terminate called" in err:
        cls = "crash"
        reasons.append("terminate called")
    elif opts.sanitizer and any(m in err for m in SANITIZER_MARKERS):
        cls = "crash"
        reasons.append("sanitizer report: " + next(m for m in SANITIZER_MARKERS if m in err))
    elif res.exit_status == 0:
        cls = _success(res, err, reasons)
    else:
        cls = "clean_refusal" if not _refusal_faults(res, err, reasons) else "dirty_refusal"
    res.observed = cls
    if cls in OK_CLASSES and case.expect and cls not in case.expect:
        reasons.insert(0, f"expected {'/'.join(case.expect)}, got {cls}")
        cls = "unexpected"
    res.cls = cls
    res.reasons = reasons


# --------------------------------------------------------------------------
# Exit status 0


def _success(res, err: str, reasons: list[str]) -> str:
    case, d = res.case, res.case_dir
    bad: list[str] = []
    nonfinite: list[str] = []
    if case.kind == "render":
        _check_image(d, case.image, bad)
        if case.stats:
            stats = _read_json(d / case.stats, bad, "stats")
            if isinstance(stats, dict):
                n = stats.get("nonfinite_samples")
                if not isinstance(n, (int, float)):
                    bad.append("stats: no nonfinite_samples")
                elif n != 0:
                    nonfinite.append(f"nonfinite_samples = {n}")
    elif case.kind == "samples" and case.csv:
        _check_csv(d / case.csv, bad, nonfinite)
    elif case.kind == "diff":
        _check_diff(res, bad, nonfinite)
    if NONFINITE_LINE in err:
        nonfinite.append("stderr: " + NONFINITE_LINE)
    new = _new_entries(res)
    if new:
        bad.append("left behind: " + ", ".join(new[:5]))
    if bad:
        reasons.extend(bad)
        return "bad_output"
    if nonfinite:
        reasons.extend(nonfinite)
        return "nonfinite"
    return "rendered"


def _check_image(d, image: str | None, bad: list[str]) -> None:
    if not image:
        return
    p = d / image
    try:
        head = open(p, "rb").read(16)
    except OSError as e:
        bad.append(f"{image}: not written ({e.strerror})")
        return
    if head == SENTINEL:
        bad.append(f"{image}: still the sentinel")
        return
    ext = os.path.splitext(image)[1].lower()
    if ext in MAGIC and not any(head.startswith(m) for m in MAGIC[ext]):
        bad.append(f"{image}: not a {ext[1:].upper()} file")


def _read_json(p, bad: list[str], what: str):
    try:
        data = p.read_bytes()
    except OSError as e:
        bad.append(f"{what}: not written ({e.strerror})")
        return None
    if data == SENTINEL:
        bad.append(f"{what}: still the sentinel")
        return None
    try:
        return json.loads(data)
    except ValueError as e:
        bad.append(f"{what}: invalid JSON ({e})")
        return None


def _finite(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return True  # not a number at all: checked elsewhere


def _check_csv(p, bad: list[str], nonfinite: list[str]) -> None:
    try:
        text = p.read_text("utf-8", "replace")
    except OSError as e:
        bad.append(f"{p.name}: not written ({e.strerror})")
        return
    lines = text.splitlines()
    if not lines or lines[0] != CSV_HEADER:
        bad.append(f"{p.name}: no CSV header")
        return
    for i, line in enumerate(lines[1:], 2):
        fields = line.split(",")
        if len(fields) != 9:
            bad.append(f"{p.name}:{i}: {len(fields)} fields")
            return
        if not all(_finite(v) for v in fields):
            nonfinite.append(f"{p.name}:{i}: non-finite value: {line[:120]}")
            return


def _check_diff(res, bad: list[str], nonfinite: list[str]) -> None:
    text = res.stdout.decode("utf-8", "replace")
    values = {}
    if "--json" in res.argv:
        try:
            values = json.loads(text)
        except ValueError:
            bad.append("diff --json: invalid JSON")
            return
    else:
        for line in text.splitlines():
            k, _, v = line.partition(" ")
            values[k] = v
    missing = [k for k in DIFF_KEYS if k not in values]
    if missing:
        bad.append("diff: missing " + ", ".join(missing))
    elif not res.case.allow_nonfinite and not all(_finite(str(values[k])) for k in DIFF_KEYS):
        nonfinite.append("diff: non-finite value")


# --------------------------------------------------------------------------
# Refusals


def _refusal_faults(res, err: str, reasons: list[str]) -> bool:
    """Append every rule the refusal breaks; True if it breaks any."""
    case = res.case
    start = len(reasons)
    if res.exit_status != 2:
        reasons.append(f"exit status {res.exit_status} (bad input must give 2)")
    line = err[:-1] if err.endswith("\n") else err
    if not line:
        reasons.append("nothing on stderr")
    else:
        if "\n" in line:
            reasons.append(f"{line.count(chr(10)) + 1} lines on stderr")
        if "\r" in line:
            reasons.append("carriage return on stderr")
        if not line.startswith("mcrt: "):
            reasons.append("does not start with 'mcrt: '")
        if len(line) > MAX_LINE or res.stderr_size > MAX_LINE * 4 + 1:
            reasons.append(f"stderr of {res.stderr_size} bytes (> {MAX_LINE} characters)")
        if re.search(r"[\x00-\x08\x0b-\x1f\x7f]", line):
            reasons.append("control characters on stderr")
        first = line.split("\n", 1)[0]
        names = [n for n in case.names if n]
        if names and not any(form in first for n in names for form in _name_forms(n)):
            reasons.append("names no file/flag (" + ", ".join(os.path.basename(n) or n for n in names[:3]) + ")")
        if "<input>" in first:
            reasons.append("says <input> instead of the file's name")
        libs = [m.replace("\\b", "").replace("\\", "") for m in LIBRARY_MARKERS if re.search(m, line)]
        if libs:
            reasons.append("library message (" + ", ".join(libs) + ")")
        if any(m in line for m in VAGUE_MARKERS):
            reasons.append("gives no reason")
    if res.stdout_size:
        reasons.append(f"{res.stdout_size} bytes on stdout")
    # Outputs: still the sentinel, the same file.
    sentinels = case.sentinel_outputs()
    for o in sentinels:
        before = res.before.get(o)
        after = res.after.get(o)
        if before is None or before[0] != "file":
            continue
        try:
            same = (res.case_dir / o).read_bytes() == SENTINEL
        except OSError:
            same = False
        if not same or after is None or after[2:] != before[2:]:
            reasons.append(f"output {o} touched")
    new = _new_entries(res)
    if new:
        reasons.append("left behind: " + ", ".join(new[:5]))
    for path, b in res.before.items():
        a = res.after.get(path)
        if a is None:
            reasons.append(f"removed {path}")
        elif a != b and path not in sentinels and b[0] == "file":
            reasons.append(f"modified {path}")
    return len(reasons) > start


def _name_forms(name: str) -> set[str]:
    """The ways a message may spell a name: as given, its last part, and
    with control characters escaped (a newline as \\n)."""
    forms = {name, os.path.basename(name.rstrip("/"))}
    forms |= {f.encode("unicode_escape").decode("ascii") for f in list(forms)}
    return {f for f in forms if f}


def _new_entries(res) -> list[str]:
    """Files in the case directory that neither the case nor a successful
    run's declared outputs account for (a leftover temporary file)."""
    allowed = set(res.before) | set(res.case.outputs)
    return sorted(p for p in res.after if p not in allowed)


def is_ok(cls: str) -> bool:
    return cls in OK_CLASSES


def is_bug(cls: str) -> bool:
    return cls in BUG_CLASSES
