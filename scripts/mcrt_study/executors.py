"""Where the sweep's renders run: here one after another, a local process pool, or a Dask cluster.

Every backend is a concurrent.futures-style executor (submit, futures with
result and add_done_callback), so the sweep has one code path:

- local, --jobs 1 (the default): each point runs in this process when it is
  submitted, in the sweep's order, as the study always did;
- local, --jobs N: a pool of N processes on this machine;
- dask, --scheduler ADDRESS: the workers of a Dask distributed cluster
  (``dask scheduler`` / ``dask worker``, or dask-jobqueue and dask-kubernetes
  clusters), through Client.get_executor. Each point travels as bytes that
  hold this package's code (cloudpickle, by value), so the scheduler and
  workers need Python with distributed but not this package: the code they run
  is the driver's. They need the mcrt binary at the same path and OUT on
  storage they share with the driver.
"""

from __future__ import annotations

import argparse
import os
import pickle
import sys
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Callable, Iterator

BACKENDS = ["local", "dask"]


@dataclass(frozen=True)
class Backend:
    """Where the renders run: backend name, jobs at once, the Dask scheduler's address."""

    name: str = "local"
    jobs: int = 1
    scheduler: str | None = None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options --jobs, --backend and --scheduler."""
    group = parser.add_argument_group("where the renders run")
    group.add_argument("--jobs", type=int, default=1, metavar="N",
                       help="sweep points rendered at once (default: 1, one after another); with "
                       "N > 1 each render gets max(1, cores // N) threads unless --threads is given; "
                       "with --backend dask, the least number of points kept in flight")
    group.add_argument("--backend", choices=BACKENDS, default="local",
                       help="local: this machine (a process pool with --jobs N > 1); dask: the "
                       "workers of a Dask distributed cluster, see --scheduler (default: local)")
    group.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="address of the Dask scheduler, e.g. tcp://host:8786 (with --backend dask); "
                       "OUT and the mcrt binary must be on storage the workers share")


def backend_of(args: argparse.Namespace) -> Backend:
    """The backend of the parsed options; exits with a message when they do not fit together."""
    problems = []
    if args.jobs < 1:
        problems.append("--jobs must be positive")
    if args.backend == "dask" and not args.scheduler:
        problems.append("--backend dask needs --scheduler ADDRESS (e.g. tcp://host:8786)")
    if args.backend != "dask" and args.scheduler:
        problems.append("--scheduler is for --backend dask")
    if problems:
        raise SystemExit("study.py: " + "; ".join(problems))
    return Backend(args.backend, args.jobs, args.scheduler)


def machine_cores() -> int:
    """The cores this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def render_threads(threads: int | None, backend: Backend, cores: int) -> int | None:
    """The --threads of each sweep render: --threads when given; with --jobs N > 1 on this machine
    max(1, cores // N); else None (mcrt's default, all hardware threads; a Dask worker shares its
    own cores, see points.dask_worker_render_threads)."""
    if threads is not None:
        return threads
    if backend.name == "local" and backend.jobs > 1:
        return max(1, cores // backend.jobs)
    return None


class InlineExecutor(Executor):
    """An executor that runs each call in this process as it is submitted (--jobs 1)."""

    def submit(self, fn: Callable, /, *args, **kwargs) -> Future:
        """Run fn now; a finished future holds its result or its exception."""
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as err:  # KeyboardInterrupt and SystemExit go straight through
            future.set_exception(err)
        return future


@dataclass
class Pool:
    """An executor and how many points to keep in flight on it."""

    executor: Executor
    capacity: Callable[[], int]


@contextmanager
def open_pool(backend: Backend) -> Iterator[Pool]:
    """The executor of a backend, shut down (pending points cancelled) on the way out."""
    if backend.name == "dask":
        with dask_pool(backend) as pool:
            yield pool
        return
    if backend.jobs == 1:
        yield Pool(InlineExecutor(), lambda: 1)
        return
    executor = ProcessPoolExecutor(max_workers=backend.jobs)
    try:
        yield Pool(executor, lambda: backend.jobs)
    except BaseException:
        executor.shutdown(wait=False, cancel_futures=True)
        raise
    executor.shutdown(wait=True)


class PickledCall:
    """fn(*args), pickled so that unpickling it makes the call (and returns its result)."""

    def __init__(self, fn: Callable, args: tuple) -> None:
        self.fn = fn
        self.args = args

    def __reduce__(self) -> tuple[Callable, tuple]:
        return self.fn, self.args


class ByValueExecutor(Executor):
    """Submits fn(*args) to another executor as pickle.loads of cloudpickled bytes, with this
    package's functions and classes in them by value: whoever runs it needs no copy of this package."""

    def __init__(self, inner: Executor) -> None:
        self.inner = inner

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> Future:
        """Submit the call; its future holds fn's result."""
        import cloudpickle
        assert not kwargs, "positional arguments only"
        return self.inner.submit(pickle.loads, cloudpickle.dumps(PickledCall(fn, args)))

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        """Shut the inner executor down."""
        self.inner.shutdown(wait=wait, cancel_futures=cancel_futures)


@contextmanager
def pickled_by_value() -> Iterator[None]:
    """While inside: cloudpickle pickles this package's functions and classes by value."""
    import cloudpickle
    package = sys.modules[__name__.partition(".")[0]]
    cloudpickle.register_pickle_by_value(package)
    try:
        yield
    finally:
        cloudpickle.unregister_pickle_by_value(package)


@contextmanager
def dask_pool(backend: Backend) -> Iterator[Pool]:
    """A Dask client's executor; points in flight: the cluster's worker threads now (at least --jobs)."""
    try:
        from distributed import Client
    except ImportError as err:
        raise SystemExit(f"study.py: --backend dask needs the Python package distributed "
                         f"(scripts/setup.sh --python installs it): {err}") from err
    client = Client(backend.scheduler, set_as_default=False)
    try:
        with pickled_by_value():
            executor = ByValueExecutor(client.get_executor(pure=False))
            yield Pool(executor, lambda: max(backend.jobs, sum(client.nthreads().values())))
    finally:
        client.close()
