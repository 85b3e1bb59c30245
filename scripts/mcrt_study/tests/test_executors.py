"""The sweep on its executors (runner.run_study with executors.open_pool) and the point files
(points.py), with a fake measurement in place of mcrt: the rows of --jobs 1, --jobs 2, an
executor that finishes points out of order and a Dask cluster in this process are those of the
sequential sweep, in its order; point files are merged (duplicates, temporary files, other run
keys) and a killed or crashed run resumes without rendering a finished point again."""

import contextlib
import json
import math
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import zlib
from concurrent.futures import Executor, Future
from pathlib import Path
from unittest import mock

from mcrt_study.config import DIRECT_MAX_DEPTH, Config, build_parser, resolve_settings
from mcrt_study.executors import (
    Backend, ByValueExecutor, InlineExecutor, PickledCall, Pool, add_arguments, backend_of, machine_cores,
    pickled_by_value, render_threads,
)
from mcrt_study.mcrt import McrtError
from mcrt_study.points import (
    POINTS_DIR, PointTask, merge_points, point_file_name, read_points, run_point, write_point,
)
from mcrt_study.references import reference_key
from mcrt_study.results import read_csv, row_key, state_key
from mcrt_study.runner import run_study
from mcrt_study.scenes import load_scenes

try:
    import distributed
except ImportError:  # the venv predates scripts/requirements.txt's distributed
    distributed = None

CALLS_ENV = "MCRT_STUDY_TEST_CALLS"  # directory where fake_measure leaves one file per call
FAILING = Config("solid-angle", "mis", "sobol")  # "not available" at max depth 1
SPP, SEEDS = [4, 8], [1, 2]


def fake_errors(config: Config, max_depth: int, spp: int, seed: int) -> tuple[float, dict]:
    """Deterministic stand-ins for render seconds and mcrt diff's errors."""
    h = zlib.crc32(f"{config.label}/{max_depth}/{spp}/{seed}".encode()) / 2**32
    rmse = (0.5 + h) / math.sqrt(spp)
    return 1e-3 * spp * (1 + h), {"rmse": rmse, "mse": rmse * rmse, "relmse": 0.3 * rmse * rmse}


def fake_measure(settings, scene, config, max_depth, spp, seed, image, reference):
    """A render and diff without mcrt: fails like an unavailable strategy for FAILING at depth 1;
    takes 0-8 ms so that parallel points finish out of order; notes each call in $CALLS_ENV."""
    assert reference.is_file(), reference
    calls = os.environ.get(CALLS_ENV)
    if calls:
        Path(calls, f"{config.label.replace('/', '_')}-{max_depth}-{spp}-{seed}-{time.monotonic_ns()}").touch()
    h = zlib.crc32(f"{config.label}{spp}{seed}{max_depth}".encode())
    time.sleep((h % 9) * 1e-3)
    if config == FAILING and max_depth == DIRECT_MAX_DEPTH:
        raise McrtError("solid-angle sampling is not available in this build", 2, True)
    return fake_errors(config, max_depth, spp, seed)


def threads_measure(settings, scene, config, max_depth, spp, seed, image, reference):
    """Reports the render threads a point was given, as its seconds."""
    return float(settings.threads or 0), {"rmse": 1.0, "mse": 1.0, "relmse": 1.0}


def make_settings(out: Path, *extra: str):
    argv = ["study.py", "--report-only", "--out", str(out), "--scenes", "cornell_rect",
            "--spp", *map(str, SPP), "--seeds", *map(str, SEEDS), "--integrators", "mixture", "mis",
            "--samplers", "sobol", "--strategies", "area", "solid-angle", "--width", "8", "--height", "8",
            "--mcrt", str(out / "no-mcrt"), "--no-bench", *extra]
    settings = resolve_settings(build_parser().parse_args(argv[1:]), argv)
    settings.report_only = False
    return settings


def cache_references(settings, scenes) -> None:
    """Fake cached references (solid angle, the preferred strategy), so no reference is rendered."""
    refdir = settings.out / "references"
    refdir.mkdir(parents=True, exist_ok=True)
    for scene in scenes:
        for _, depth in scene.depth_modes(settings.depths):
            image = refdir / f"{scene.name}-{reference_key(settings, scene, depth, 'solid-angle', '')}.exr"
            image.write_bytes(b"not an image")
            image.with_suffix(".json").write_text(json.dumps({"render_seconds": 1.0}))


def sequential_rows(settings, scene) -> list[dict]:
    """The rows the study made before it had executors: one point after another, the
    configurations rotated, a failed configuration skipped at its depth from then on."""
    configs, rows, dead, turn = settings.configs, [], set(), 0
    for seed in settings.seeds:
        for spp in settings.spp:
            for depth in (scene.max_depth, DIRECT_MAX_DEPTH):
                shift, turn = turn % len(configs), turn + 1
                for config in configs[shift:] + configs[:shift]:
                    if (depth, config) in dead:
                        continue
                    if config == FAILING and depth == DIRECT_MAX_DEPTH:
                        dead.add((depth, config))
                        continue
                    seconds, errors = fake_errors(config, depth, spp, seed)
                    rows.append({"scene": scene.name, "strategy": config.strategy,
                                 "integrator": config.integrator, "sampler": config.sampler,
                                 "max_depth": depth, "spp": spp, "seed": seed, "seconds": seconds, **errors,
                                 "family": "", "family_param": None, "light_solid_angle": scene.light_solid_angle,
                                 "light_select": "default"})
    return rows


@contextlib.contextmanager
def quiet():
    """No progress bar and log lines on stderr."""
    with open(os.devnull, "w") as devnull, contextlib.redirect_stderr(devnull):
        yield


def rounded(rows: list[dict]) -> list[dict]:
    """Rows with their numbers as the CSV prints them (9 significant digits)."""
    return [{k: float(f"{v:.9g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]


class ReversingExecutor(Executor):
    """Runs what it is given in batches, last submitted first (a batch: 3 points, or what is
    pending after 20 ms without a new one); records the order it ran them in."""

    def __init__(self) -> None:
        self.pending: list = []
        self.ran: list = []
        self.lock = threading.Condition()
        self.closed = False
        self.thread = threading.Thread(target=self.loop, daemon=True)
        self.thread.start()

    def submit(self, fn, /, *args, **kwargs) -> Future:
        future: Future = Future()
        with self.lock:
            self.pending.append((future, fn, args))
            self.lock.notify()
        return future

    def loop(self) -> None:
        while True:
            with self.lock:
                while len(self.pending) < 3 and not self.closed:
                    if not self.lock.wait(0.02) and self.pending:
                        break
                if self.closed and not self.pending:
                    return
                batch, self.pending = self.pending, []
            for future, fn, args in reversed(batch):
                self.ran.append(args[0].spp * 100 + args[0].seed * 10 + args[0].max_depth)
                try:
                    future.set_result(fn(*args))
                except Exception as err:
                    future.set_exception(err)

    def shutdown(self, wait=True, *, cancel_futures=False) -> None:
        with self.lock:
            self.closed = True
            self.lock.notify()
        self.thread.join()


class ExecutorTestCase(unittest.TestCase):
    def setUp(self) -> None:
        self.tmp = Path(tempfile.mkdtemp(prefix="mcrt-study-executors-"))
        self.addCleanup(shutil.rmtree, self.tmp, ignore_errors=True)

    def study(self, name: str, backend: Backend = Backend(), measure=fake_measure, *extra: str):
        """Run the study in OUT=tmp/name with the fake measurement; (rows, settings, CSV text)."""
        settings = make_settings(self.tmp / name, *extra)
        scenes = load_scenes(settings.scenes, settings)
        cache_references(settings, scenes)
        with quiet():
            rows = run_study(settings, scenes, backend, measure)
        return rows, settings, (settings.out / "results.csv").read_text()


class SameRowsTest(ExecutorTestCase):
    def check_against_sequential(self, rows, settings, csv_text, expected, expected_csv) -> None:
        self.assertEqual(rows, expected)
        self.assertEqual(csv_text, expected_csv)
        self.assertEqual([(f.strategy, f.integrator, f.sampler, f.max_depth, f.unavailable)
                          for f in settings.failures], [("solid-angle", "mis", "sobol", 1, True)])
        points = read_points(settings.out / POINTS_DIR)
        self.assertEqual(sorted(row_key(r) for _, r in points), sorted(row_key(r) for r in expected))
        self.assertEqual(sorted(os.listdir(settings.out / POINTS_DIR)),
                         sorted(point_file_name(row_key(r)) for r in expected))

    def test_jobs_and_dask_give_the_sequential_rows(self) -> None:
        rows, settings, csv_text = self.study("jobs1")
        scene = load_scenes(settings.scenes, settings)[0]
        expected = sequential_rows(settings, scene)
        # 2 depths x 4 configurations x 2 spp x 2 seeds, less the failing configuration's 4 direct points.
        self.assertEqual(len(expected), 28)
        self.check_against_sequential(rows, settings, csv_text, expected, csv_text)
        self.assertEqual([r["seconds"] for r in read_csv(settings.out / "results.csv", lambda s: 0)],
                         [float(f"{r['seconds']:.9g}") for r in expected])

        rows2, settings2, csv2 = self.study("jobs2", Backend("local", 2))
        self.check_against_sequential(rows2, settings2, csv2, expected, csv_text)

        reversing = ReversingExecutor()

        @contextlib.contextmanager
        def reversing_pool(backend):
            yield Pool(reversing, lambda: 3)
            reversing.shutdown()
        with mock.patch("mcrt_study.runner.open_pool", reversing_pool):
            rows3, settings3, csv3 = self.study("reversed")
        self.assertNotEqual(reversing.ran, sorted(reversing.ran))  # out of order indeed
        self.check_against_sequential(rows3, settings3, csv3, expected, csv_text)

        if distributed is None:
            self.skipTest("distributed is not installed (scripts/setup.sh --python installs it)")
        with distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=2,
                                      dashboard_address=None) as cluster:
            rows4, settings4, csv4 = self.study("dask", Backend("dask", 1, cluster.scheduler_address))
        self.check_against_sequential(rows4, settings4, csv4, expected, csv_text)

    def test_render_threads(self) -> None:
        self.assertIsNone(render_threads(None, Backend(), 8))
        self.assertEqual(render_threads(None, Backend("local", 2), 8), 4)
        self.assertEqual(render_threads(None, Backend("local", 3), 8), 2)
        self.assertEqual(render_threads(None, Backend("local", 16), 8), 1)
        self.assertEqual(render_threads(3, Backend("local", 2), 8), 3)
        self.assertIsNone(render_threads(None, Backend("dask", 4, "tcp://h:8786"), 8))
        rows, _, _ = self.study("threads", Backend("local", 2), threads_measure)
        self.assertEqual({r["seconds"] for r in rows}, {float(max(1, machine_cores() // 2))})
        rows, _, _ = self.study("threads-given", Backend("local", 2), threads_measure, "--threads", "5")
        self.assertEqual({r["seconds"] for r in rows}, {5.0})

    def test_options(self) -> None:
        parser = build_parser()
        add_arguments(parser)
        self.assertEqual(backend_of(parser.parse_args([])), Backend("local", 1, None))
        self.assertEqual(backend_of(parser.parse_args(["--jobs", "3"])), Backend("local", 3, None))
        self.assertEqual(backend_of(parser.parse_args(["--backend", "dask", "--scheduler", "tcp://h:8786"])),
                         Backend("dask", 1, "tcp://h:8786"))
        for bad in (["--jobs", "0"], ["--backend", "dask"], ["--scheduler", "tcp://h:8786"]):
            with self.subTest(bad=bad), self.assertRaises(SystemExit):
                backend_of(parser.parse_args(bad))


def point_row(spp: int, seed: int, seconds: float = 1.0, scene: str = "s") -> dict:
    return {"scene": scene, "strategy": "area", "integrator": "nee", "sampler": "sobol", "max_depth": 1,
            "spp": spp, "seed": seed, "seconds": seconds, "rmse": 0.5, "mse": 0.25, "relmse": 0.125,
            "family": "", "family_param": None, "light_solid_angle": 0.25, "light_select": "default"}


class PointFilesTest(ExecutorTestCase):
    def test_write_and_read(self) -> None:
        points = self.tmp / "points"
        row = point_row(8, 1, seconds=0.1 + 0.2)
        path = write_point(points, row, "k1")
        self.assertEqual(os.listdir(points), [path.name])  # no temporary file left
        self.assertEqual(path.name, point_file_name(row_key(row)))
        self.assertEqual(read_points(points), [("k1", row)])  # full precision
        write_point(points, {**row, "seconds": 2.0}, "k1")  # the same point again: replaced
        self.assertEqual(read_points(points), [("k1", {**row, "seconds": 2.0})])

    def test_half_written_and_foreign_files_are_ignored(self) -> None:
        points = self.tmp / "points"
        write_point(points, point_row(8, 1), "k1")
        text = json.dumps({"version": 1, "run_key": "k1", "row": point_row(16, 1)})
        (points / ".0123456789abcdef0123.json.host-1-ab.tmp").write_text(text[: len(text) // 2])
        (points / ".0123456789abcdef0123.json").write_text(text[: len(text) // 2])
        (points / "0000truncated.json").write_text(text[:-20])
        (points / "0001other.json").write_text('{"something": "else"}')
        with quiet():
            found = read_points(points)
        self.assertEqual(found, [("k1", point_row(8, 1))])

    def test_merge(self) -> None:
        keys = {state_key("s", 1): "k1"}
        csv_rows = [point_row(8, 1, seconds=1.0)]
        points = [("k1", point_row(32, 1)), ("k1", point_row(8, 1, seconds=9.0)),  # already in the CSV
                  ("k1", point_row(16, 2, seconds=2.0)), ("k1", point_row(16, 2, seconds=3.0)),  # duplicate
                  ("old", point_row(64, 1)),  # made with other settings
                  ("k1", point_row(8, 1, scene="t"))]  # a scene and depth without a run key
        merged = merge_points(csv_rows, points, keys)
        self.assertEqual(merged, [point_row(8, 1, seconds=1.0), point_row(16, 2, seconds=2.0), point_row(32, 1)])
        self.assertEqual(merge_points(csv_rows, list(reversed(points[:2])) + points[2:], keys), merged)
        self.assertEqual(merge_points([], [], keys), [])


class ResumeTest(ExecutorTestCase):
    def calls(self) -> list[str]:
        return sorted(p.name.rsplit("-", 1)[0] for p in (self.tmp / "calls").iterdir())

    def setUp(self) -> None:
        super().setUp()
        (self.tmp / "calls").mkdir()
        patcher = mock.patch.dict(os.environ, {CALLS_ENV: str(self.tmp / "calls")})
        patcher.start()
        self.addCleanup(patcher.stop)

    def split_failing(self) -> tuple[list[str], list[str]]:
        """The calls, as (the failing configuration's at depth 1, the others). With two workers
        a second point of the failing configuration may already be in flight when the first
        one's failure comes back (only points not yet submitted are skipped), so how many of
        its points are called depends on timing: at least one, and only its depth-1 points."""
        prefix = FAILING.label.replace("/", "_") + f"-{DIRECT_MAX_DEPTH}-"
        calls = self.calls()
        return [c for c in calls if c.startswith(prefix)], [c for c in calls if not c.startswith(prefix)]

    def test_crashed_run_resumes_from_its_point_files(self) -> None:
        rows, settings, _ = self.study("run", Backend("local", 2))
        failing_calls, others = self.split_failing()
        self.assertEqual(len(others), 28)  # 28 points, and one or more of the failing configuration's
        self.assertTrue(1 <= len(failing_calls) <= len(SPP) * len(SEEDS), failing_calls)
        # The driver died: no CSV; five points were never finished; a half-written point file; a
        # stray copy of a point with another time.
        out, points = settings.out, settings.out / POINTS_DIR
        (out / "results.csv").unlink()
        lost = sorted(points.iterdir())[:5]
        lost_rows = [json.loads(p.read_text())["row"] for p in lost]
        for path in lost:
            path.unlink()
        kept = sorted(points.iterdir())[0]
        (points / f".{lost[0].name}.host-7-cd.tmp").write_text(lost[0].name[:10])
        copy = json.loads(kept.read_text())
        copy["row"]["seconds"] = 123.0
        (points / "zz-copy.json").write_text(json.dumps(copy))
        shutil.rmtree(self.tmp / "calls")
        (self.tmp / "calls").mkdir()

        rows2, settings2, csv2 = self.study("run", Backend("local", 2))
        again = [f"{r['integrator']}_{r['sampler']}_{r['strategy']}-{r['max_depth']}-{r['spp']}-{r['seed']}"
                 for r in lost_rows]
        failing_calls, others = self.split_failing()
        self.assertEqual(others, sorted(again))
        failing = f"{FAILING.label.replace('/', '_')}-1-4-1"
        self.assertIn(failing, failing_calls)
        self.assertLessEqual(len(failing_calls), len(SPP) * len(SEEDS))
        self.assertEqual(sorted(rows2, key=row_key), sorted(rows, key=row_key))
        self.assertEqual(len(csv2.splitlines()), 1 + len(rows))
        copied = [r for r in rows2 if row_key(r) == row_key(copy["row"])]
        self.assertEqual(len(copied), 1)
        self.assertNotEqual(copied[0]["seconds"], 123.0)

        # Once complete, nothing is rendered again, and --report-only reads the same rows.
        shutil.rmtree(self.tmp / "calls")
        (self.tmp / "calls").mkdir()
        rows3, _, csv3 = self.study("run")
        self.assertEqual(self.calls(), [failing])
        self.assertEqual(csv3, csv2)
        self.assertEqual(len(rows3), len(rows))

    def test_killed_run_resumes(self) -> None:
        state = {"left": 7}

        def interrupting(*args):
            state["left"] -= 1
            if state["left"] == 0:
                raise KeyboardInterrupt
            return fake_measure(*args)
        with self.assertRaises(KeyboardInterrupt):
            self.study("killed", Backend(), interrupting)
        out = self.tmp / "killed"
        self.assertEqual(len(read_csv(out / "results.csv", lambda s: 0)), 6)
        self.assertEqual(len(read_points(out / POINTS_DIR)), 6)
        self.assertEqual([p for p in out.iterdir() if p.name.startswith(".sweep-")], [])
        shutil.rmtree(self.tmp / "calls")
        (self.tmp / "calls").mkdir()
        rows, settings, _ = self.study("killed")
        self.assertEqual(len(self.calls()), 29 - 6)
        scene = load_scenes(settings.scenes, settings)[0]
        self.assertEqual(rounded(rows), rounded(sequential_rows(settings, scene)))

    def test_changed_settings_drop_the_point_files(self) -> None:
        self.study("changed")
        out = self.tmp / "changed"
        # Other references (their key changes with --ref-spp), and spp 4 alone: the points of both
        # depths are made again; the old point files are neither merged nor kept.
        shutil.rmtree(self.tmp / "calls")
        (self.tmp / "calls").mkdir()
        rows, settings, csv_text = self.study("changed", Backend(), fake_measure, "--ref-spp", "64", "--spp", "4")
        self.assertEqual(len(self.calls()), 15)  # 2 seeds x (4 + 3) points, the failing configuration
        self.assertEqual(len(rows), 14)
        self.assertEqual(len(csv_text.splitlines()), 1 + 14)
        self.assertEqual(len(os.listdir(out / POINTS_DIR)), 14)
        run_keys = {json.loads(p.read_text())["run_key"] for p in (out / POINTS_DIR).iterdir()}
        state = json.loads((out / "study_state.json").read_text())
        self.assertEqual(run_keys, {run["run_key"] for run in state["runs"].values()})
        self.assertEqual(len(run_keys), 2)


class CaptureExecutor(Executor):
    """Keeps what it is given instead of running it."""

    def __init__(self) -> None:
        self.calls: list = []

    def submit(self, fn, /, *args, **kwargs) -> Future:
        self.calls.append((fn, args))
        return Future()


# Run a pickled call in a Python that cannot import mcrt_study (-I: no PYTHONPATH, no script
# directory); print the modules of the package it imported and the result.
UNPICKLE = ("import pickle, sys; result = pickle.loads(sys.stdin.buffer.read()); "
            "print(sorted(m for m in sys.modules if m.startswith('mcrt_study')), repr(result))")


class ByValueTest(ExecutorTestCase):
    def test_a_worker_needs_no_copy_of_the_package(self) -> None:
        settings = make_settings(self.tmp / "by-value")
        scene = load_scenes(settings.scenes, settings)[0]
        reference = self.tmp / "reference.exr"
        reference.write_bytes(b"not an image")
        task = PointTask(settings, scene, Config("area", "nee", "sobol"), 1, 8, 2, self.tmp / "image.exr",
                         reference, self.tmp / "points", "k1", {"family": "", "family_param": None,
                                                                 "light_solid_angle": 0.5})
        capture = CaptureExecutor()
        with pickled_by_value():
            ByValueExecutor(capture).submit(run_point, task, fake_measure)
        [(fn, (payload,))] = capture.calls
        self.assertIs(fn, pickle.loads)
        proc = subprocess.run([sys.executable, "-I", "-c", UNPICKLE], input=payload, capture_output=True,
                              cwd=self.tmp, timeout=60)
        self.assertEqual(proc.returncode, 0, proc.stderr.decode())
        self.assertTrue(proc.stdout.startswith(b"[] {'row': {"), proc.stdout)
        seconds, errors = fake_errors(Config("area", "nee", "sobol"), 1, 8, 2)
        self.assertEqual(read_points(self.tmp / "points"),
                         [("k1", {"scene": scene.name, "strategy": "area", "integrator": "nee", "sampler": "sobol",
                                  "max_depth": 1, "spp": 8, "seed": 2, "seconds": seconds, **errors,
                                  "family": "", "family_param": None, "light_solid_angle": 0.5,
                                  "light_select": "default"})])
        # Pickled the ordinary way (by reference), the same call needs the package.
        plain = subprocess.run([sys.executable, "-I", "-c", UNPICKLE], capture_output=True, cwd=self.tmp,
                               input=pickle.dumps(PickledCall(run_point, (task, fake_measure))), timeout=60)
        self.assertNotEqual(plain.returncode, 0)
        self.assertIn(b"No module named 'mcrt_study'", plain.stderr)


class InlineExecutorTest(unittest.TestCase):
    def test_runs_at_once_and_keeps_exceptions(self) -> None:
        seen = []
        future = InlineExecutor().submit(seen.append, 1)
        self.assertTrue(future.done())
        self.assertEqual(seen, [1])
        self.assertIsInstance(InlineExecutor().submit(lambda: 1 / 0).exception(), ZeroDivisionError)
        with self.assertRaises(KeyboardInterrupt):
            InlineExecutor().submit(lambda: (_ for _ in ()).throw(KeyboardInterrupt()))


if __name__ == "__main__":
    unittest.main()
