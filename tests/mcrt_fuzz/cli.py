"""The command line: choose the cases, run them in parallel, report."""

from __future__ import annotations

import argparse
import os
import platform
import signal
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from . import cases as structural
from . import mutate, report
from .runner import BINARY_WAIT_SECONDS, Options, discard, kill_running, run_case

# --quick: every structural case (644) and this many mutations: 744 runs in
# 95 s with --jobs 2 on the idle 2-core machine, 144 s with a compiler
# running beside it (mcrt's start-up alone is ~0.25 s of CPU per run, so the
# count, not the cases, sets the time).
QUICK_MUTATIONS = 100
# --quick keeps the hang threshold of every run, 30 s: the gzip bombs take
# 3-4 s to unpack to the 1 GiB bound on an idle machine, and ctest runs this
# beside other tests (a lower threshold would call a loaded machine a hang).
QUICK_TIMEOUT = 30.0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="fuzz.py", description="Black-box fuzzing of the mcrt executable.")
    p.add_argument("--mcrt", required=True, help="the mcrt executable")
    p.add_argument("--out", default="fuzz-out", help="work directory (cases/, logs/)")
    p.add_argument("--seed", type=int, default=1, help="seed of the random mutations (default 1)")
    p.add_argument("--mutations", type=int, default=None, help="random-mutation cases (default 300)")
    p.add_argument("--quick", action="store_true",
                   help=f"every structural case + {QUICK_MUTATIONS} mutations, timeout {QUICK_TIMEOUT:g} s "
                        "(about 2.5 min with --jobs 2)")
    p.add_argument("--jobs", type=int, default=2, help="cases run in parallel (default 2)")
    p.add_argument("--timeout", type=float, default=None, help="seconds before a case is a hang (default 30)")
    p.add_argument("--mem-limit", type=int, default=2 << 30, help="peak RSS limit in bytes (default 2 GiB)")
    p.add_argument("--report", help="write the JSON report here")
    p.add_argument("--markdown", help="write the Markdown report here")
    p.add_argument("--check", action="store_true", help="exit status 1 if any case is not ok")
    p.add_argument("--only", help="run only the cases whose id starts with this")
    p.add_argument("--list", action="store_true", help="list the case ids and exit")
    p.add_argument("--keep", action="store_true", help="keep the directories of ok cases too")
    p.add_argument("--sanitizer", action="store_true",
                   help="ASan/UBSan binary: sanitizer reports are crashes, timeout x5, memory limit x4")
    return p


def select_cases(args, n_mutations: int) -> list:
    cases = structural.all_cases() + mutate.mutation_cases(args.seed, n_mutations)
    if args.only:
        chosen = [c for c in cases if c.id.startswith(args.only)]
        # Replay one mutation beyond the run's count: it is rebuilt from (seed, id).
        if not chosen and mutate.ID_RE.match(args.only):
            try:
                chosen = [mutate.mutation_case(args.seed, args.only)]
            except ValueError as e:
                raise SystemExit(f"fuzz.py: --only: {e}")
        cases = chosen
    return cases


def wait_for_binary(path: str) -> str:
    deadline = time.monotonic() + BINARY_WAIT_SECONDS
    while not os.access(path, os.X_OK):
        if time.monotonic() > deadline:
            raise SystemExit(f"fuzz.py: {path}: not an executable file")
        print(f"fuzz.py: waiting for {path} (being rebuilt?)", file=sys.stderr)
        time.sleep(5)
    return os.path.abspath(path)


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(sys.argv[1:] if argv is None else argv)
    n_mut = args.mutations if args.mutations is not None else (QUICK_MUTATIONS if args.quick else 300)
    timeout = args.timeout if args.timeout is not None else (QUICK_TIMEOUT if args.quick else 30.0)
    mem_limit = args.mem_limit
    if args.sanitizer:
        timeout *= 5
        mem_limit *= 4
    cases = select_cases(args, n_mut)
    if args.list:
        for c in cases:
            print(c.id)
        return 0
    if not cases:
        print(f"fuzz.py: no case id starts with {args.only!r}", file=sys.stderr)
        return 2
    mcrt = wait_for_binary(args.mcrt)
    out = Path(args.out).resolve()
    (out / "cases").mkdir(parents=True, exist_ok=True)
    opts = Options(mcrt=mcrt, out=out, timeout=timeout, mem_limit=mem_limit, sanitizer=args.sanitizer,
                   keep=args.keep)
    binary_mtime = os.stat(mcrt).st_mtime
    # Cases that may run to the timeout start first, so that they overlap the rest.
    order = sorted(cases, key=lambda c: not c.slow)
    print(f"fuzz.py: {len(order)} cases ({sum(c.id.startswith('mutate/') for c in order)} mutations), "
          f"jobs {args.jobs}, timeout {timeout:g} s, memory limit {mem_limit / 2**30:g} GiB, out {out}",
          file=sys.stderr)
    t0 = time.monotonic()
    results = []
    # SIGTERM stops the run as Ctrl-C does: queued cases are dropped and the
    # running mcrt process groups killed.
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    pool = ThreadPoolExecutor(max_workers=max(1, args.jobs))
    try:
        futures = [pool.submit(run_case, c, opts) for c in order]
        for fut in as_completed(futures):
            res = fut.result()
            results.append(res)
            if res.cls in ("rendered", "clean_refusal"):
                discard(res, opts)
            else:
                print(f"  [{res.cls}] {res.case.id} ({res.wall:.1f} s): "
                      f"{'; '.join(res.reasons)[:100]} | {res.first_stderr_line[:120]}", file=sys.stderr)
            if len(results) % 100 == 0:
                print(f"fuzz.py: {len(results)}/{len(order)} done, {time.monotonic() - t0:.0f} s",
                      file=sys.stderr)
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)
        kill_running()
        print("fuzz.py: interrupted", file=sys.stderr)
        return 130
    pool.shutdown()
    wall = time.monotonic() - t0
    if os.path.exists(mcrt) and os.stat(mcrt).st_mtime != binary_mtime:
        print("fuzz.py: warning: the executable changed during the run", file=sys.stderr)
    results.sort(key=lambda r: r.case.id)
    meta = {"mcrt": mcrt, "seed": args.seed, "mutations": n_mut, "jobs": args.jobs, "timeout": timeout,
            "mem_limit": mem_limit, "sanitizer": args.sanitizer, "quick": args.quick, "only": args.only,
            "python": platform.python_version(), "out": str(out)}
    data = report.summary(results, wall, meta)
    if args.report:
        report.write_json(Path(args.report), data)
    if args.markdown:
        report.write_markdown(Path(args.markdown), data)
    report.print_summary(data, sys.stdout)
    bad = sum(1 for r in results if r.cls not in ("rendered", "clean_refusal"))
    return 1 if args.check and bad else 0


def run() -> int:
    """Entry point of tests/fuzz.py."""
    return main()
