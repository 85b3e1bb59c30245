"""Running one case: write its files, start mcrt in its own process group,
watch its time and memory, then hand the outcome to ``classify``.

The watchdog is the worker thread itself: it polls the child every ~20 ms
with ``os.wait4(WNOHANG)`` (which also returns the child's ``ru_maxrss`` at
the end), reads ``VmRSS`` from /proc/PID/status, and kills the whole process
group when the case runs past the timeout (class ``hang``) or its RSS passes
twice the memory limit (class ``memory``, and the machine is protected).
Polling a child that has not been reaped yet cannot hit a recycled pid.
"""

from __future__ import annotations

import errno
import os
import shlex
import shutil
import signal
import stat
import subprocess
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from .classify import classify
from .model import SENTINEL, Case

POLL_SECONDS = 0.02
# How much of stdout and stderr is kept (the rest is counted, not read).
KEEP_OUTPUT = 1 << 20
# How long to wait for the executable when another engineer is rebuilding it.
BINARY_WAIT_SECONDS = 600


# Process groups running now, so that an interrupted run can kill them.
RUNNING: set[int] = set()
_RUNNING_LOCK = threading.Lock()


def kill_running() -> None:
    with _RUNNING_LOCK:
        for pid in list(RUNNING):
            kill_group(pid)


@dataclass
class Options:
    mcrt: str
    out: Path
    timeout: float
    mem_limit: int
    sanitizer: bool = False
    keep: bool = False


@dataclass
class Result:
    """What a run left behind; ``cls`` and ``reasons`` are filled by classify."""
    case: Case
    case_dir: Path
    argv: list[str]
    exit_status: int | None = None   # negative: killed by that signal
    timed_out: bool = False
    mem_killed: bool = False
    peak_rss: int = 0                 # bytes, from ru_maxrss and the watchdog's samples
    wall: float = 0.0
    stdout: bytes = b""
    stderr: bytes = b""
    stdout_size: int = 0
    stderr_size: int = 0
    before: dict = field(default_factory=dict)
    after: dict = field(default_factory=dict)
    cls: str = ""
    observed: str = ""                # the class before expectations are applied
    reasons: list[str] = field(default_factory=list)
    error: str = ""                   # a harness failure (the case could not run)

    @property
    def reproducer(self) -> str:
        return f"cd {shlex.quote(str(self.case_dir))} && " + " ".join(shlex.quote(a) for a in self.argv)

    @property
    def first_stderr_line(self) -> str:
        text = self.stderr[:4096].decode("utf-8", "replace")
        return text.split("\n", 1)[0].rstrip("\r")


# --------------------------------------------------------------------------
# Materialising a case


def case_dir_of(opts: Options, case: Case) -> Path:
    return opts.out / "cases" / case.id


def log_base(opts: Options, case: Case) -> Path:
    # Logs live beside the case directories, never inside them (a new file
    # inside would count as left behind).
    return opts.out / "logs" / case.id


def remove_tree(path: Path) -> None:
    """Remove a case directory (FIFOs, symlinks and all) without following links."""
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.exists():
        shutil.rmtree(path, ignore_errors=True)


def materialise(case: Case, d: Path) -> None:
    """Create the case's entries and the sentinel outputs in a fresh directory."""
    remove_tree(d)
    d.mkdir(parents=True)
    for e in case.entries:
        p = d / e.path
        p.parent.mkdir(parents=True, exist_ok=True)
        if e.kind == "file":
            p.write_bytes(e.content())
        elif e.kind == "fifo":
            os.mkfifo(p)
        elif e.kind == "symlink":
            os.symlink(e.target, p)
        elif e.kind == "dir":
            p.mkdir(exist_ok=True)
        elif e.kind == "sparse":
            p.write_bytes(e.content())
            os.truncate(p, e.size)
        else:
            raise ValueError(f"unknown entry kind {e.kind!r}")
    for o in case.sentinel_outputs():
        p = d / o
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(SENTINEL)
        except OSError:
            pass  # an output that cannot exist (a name too long, a parent that is a file)


def snapshot(d: Path) -> dict:
    """relative path -> (kind, size, mtime_ns, inode), not following links
    and never opening anything (FIFOs stay closed)."""
    out = {}
    for root, dirs, files in os.walk(d, followlinks=False):
        for name in dirs + files:
            p = os.path.join(root, name)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            kind = ("dir" if stat.S_ISDIR(st.st_mode) else "link" if stat.S_ISLNK(st.st_mode)
                    else "fifo" if stat.S_ISFIFO(st.st_mode) else "file")
            out[os.path.relpath(p, d)] = (kind, st.st_size, st.st_mtime_ns, st.st_ino)
    return out


# --------------------------------------------------------------------------
# Running


def vm_rss(pid: int) -> int:
    """The process's resident set in bytes (0 once it has exited)."""
    try:
        with open(f"/proc/{pid}/status", "rb") as fh:
            for line in fh:
                if line.startswith(b"VmRSS:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def kill_group(pid: int) -> None:
    try:
        os.killpg(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def start(argv: list[str], cwd: Path, out_fh, err_fh) -> subprocess.Popen:
    """Popen, waiting and retrying while the executable is missing or being
    rewritten (another engineer rebuilds it from time to time)."""
    deadline = time.monotonic() + BINARY_WAIT_SECONDS
    while True:
        try:
            return subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out_fh, stderr=err_fh,
                                    start_new_session=True, close_fds=True)
        except OSError as e:
            if e.errno not in (errno.ENOENT, errno.ETXTBSY, errno.ENOEXEC, errno.EACCES) \
                    or time.monotonic() > deadline:
                raise
            time.sleep(1.0)


def read_capped(path: Path) -> tuple[bytes, int]:
    size = path.stat().st_size
    with open(path, "rb") as fh:
        return fh.read(KEEP_OUTPUT), size


def run_case(case: Case, opts: Options) -> Result:
    d = case_dir_of(opts, case)
    argv = [opts.mcrt, *case.argv]
    res = Result(case, d, argv)
    try:
        materialise(case, d)
    except OSError as e:
        return _harness_error(res, f"cannot write the case's files: {e}")
    res.before = snapshot(d)
    logs = log_base(opts, case)
    logs.parent.mkdir(parents=True, exist_ok=True)
    out_path, err_path = Path(str(logs) + ".stdout"), Path(str(logs) + ".stderr")
    hard_limit = 2 * opts.mem_limit
    t0 = time.monotonic()
    with open(out_path, "wb") as out_fh, open(err_path, "wb") as err_fh:
        try:
            proc = start(argv, d, out_fh, err_fh)
        except OSError as e:
            return _harness_error(res, f"cannot start {opts.mcrt}: {e}")
        with _RUNNING_LOCK:
            RUNNING.add(proc.pid)
        rusage = None
        status = 0
        while True:
            pid, status, rusage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            elapsed = time.monotonic() - t0
            rss = vm_rss(proc.pid)
            res.peak_rss = max(res.peak_rss, rss)
            if rss > hard_limit:
                res.mem_killed = True
            elif elapsed > opts.timeout:
                res.timed_out = True
            if res.mem_killed or res.timed_out:
                kill_group(proc.pid)
                _, status, rusage = os.wait4(proc.pid, 0)
                break
            # Poll fast at first: most cases end within a fraction of a second.
            time.sleep(0.005 if elapsed < 0.2 else POLL_SECONDS)
        proc.returncode = os.waitstatus_to_exitcode(status)
        # (No kill after reaping: the pid could in principle be reused.)
        with _RUNNING_LOCK:
            RUNNING.discard(proc.pid)
    res.wall = time.monotonic() - t0
    res.exit_status = proc.returncode
    if rusage is not None:
        res.peak_rss = max(res.peak_rss, rusage.ru_maxrss * 1024)
    res.stdout, res.stdout_size = read_capped(out_path)
    res.stderr, res.stderr_size = read_capped(err_path)
    res.after = snapshot(d)
    classify(res, opts)
    return res


def _harness_error(res: Result, why: str) -> Result:
    """The case could not run at all: reported, never counted as ok."""
    res.error = why
    res.cls = res.observed = "harness_error"
    res.reasons = [why]
    return res


def discard(res: Result, opts: Options) -> None:
    """Delete an ok case's directory and logs (kept with --keep)."""
    if opts.keep:
        return
    remove_tree(res.case_dir)
    logs = log_base(opts, res.case)
    for suffix in (".stdout", ".stderr"):
        try:
            os.unlink(str(logs) + suffix)
        except OSError:
            pass
