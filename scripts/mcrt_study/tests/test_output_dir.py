"""Where a run writes: without --out a new directory (study-out/<UTC time>/ under the current
directory, ignored by git through its own .gitignore); a directory that holds files tracked by
git (the committed results under bench/results/) only with --overwrite-committed, else the
command exits with status 2 and one line on stderr, having written nothing.
"""

import contextlib
import datetime
import io
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from mcrt_study import cli
from mcrt_study.config import (
    COMMITTED_RESULTS, NEW_OUT_PARENT, QUICK_OUT, REPO_ROOT, build_parser, committed_files,
    make_new_output_dir, new_output_dir, output_refusal, resolve_settings,
)

STUDY = REPO_ROOT / "scripts" / "study.py"


def git(repo: Path, *args: str) -> None:
    subprocess.run(["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t", *args],
                   check=True, capture_output=True)


def parsed(*args: str):
    """The parsed arguments and settings of a command line (mcrt: this Python, an executable file)."""
    argv = ["study.py", "--mcrt", sys.executable, "--no-bench", *args]
    parsed_args = build_parser().parse_args(argv[1:])
    return parsed_args, resolve_settings(parsed_args, argv)


@contextlib.contextmanager
def working_directory(path: Path):
    before = os.getcwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(before)


class DefaultOutputTest(unittest.TestCase):
    def test_without_out_a_new_directory_under_the_current_one(self):
        with tempfile.TemporaryDirectory() as tmp, working_directory(Path(tmp)):
            _, first = parsed()
            self.assertTrue(first.out_is_new)
            self.assertEqual(first.out.parent, (Path(tmp) / NEW_OUT_PARENT).resolve())
            self.assertFalse(first.out.exists())
            make_new_output_dir(first.out)
            self.assertTrue(first.out.is_dir())
            self.assertEqual((first.out.parent / ".gitignore").read_text().splitlines()[-1], "*")
            _, second = parsed()
            self.assertNotEqual(second.out, first.out)
            self.assertFalse(second.out.exists())
            self.assertFalse(committed_files(second.out))

    def test_never_the_committed_results(self):
        with tempfile.TemporaryDirectory() as tmp, working_directory(Path(tmp)):
            _, settings = parsed()
            self.assertFalse(settings.out.resolve().is_relative_to(COMMITTED_RESULTS.resolve()))

    def test_names_are_times_made_unique(self):
        with tempfile.TemporaryDirectory() as tmp:
            now = datetime.datetime(2026, 12, 1, 9, 5, 7, tzinfo=datetime.timezone.utc)
            first = new_output_dir(Path(tmp), now)
            self.assertEqual(first.name, "2026-12-01T090507Z")
            first.mkdir()
            self.assertEqual(new_output_dir(Path(tmp), now).name, "2026-12-01T090507Z-2")

    def test_given_out_and_quick_keep_their_directories(self):
        with tempfile.TemporaryDirectory() as tmp:
            _, given = parsed("--out", tmp)
            self.assertEqual(given.out, Path(tmp).resolve())
            self.assertFalse(given.out_is_new)
            _, quick = parsed("--quick")
            self.assertEqual(quick.out, QUICK_OUT.resolve())
            self.assertFalse(quick.out_is_new)


@unittest.skipUnless(shutil.which("git"), "git not installed")
class CommittedOutputTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.repo = Path(self.tmp.name)
        (self.repo / "results").mkdir()
        (self.repo / "results" / "README.md").write_text("committed report\n")
        (self.repo / "results" / "results.csv").write_text("committed,csv\n")
        git(self.repo, "init", "-q")
        git(self.repo, "add", ".")
        git(self.repo, "commit", "-q", "-m", "c")
        self.results = self.repo / "results"

    def tearDown(self):
        self.tmp.cleanup()

    def contents(self) -> dict:
        return {p.name: p.read_bytes() for p in sorted(self.results.rglob("*"))}

    def test_refused_without_the_flag_exit_status_2_one_line(self):
        before = self.contents()
        for mode in ([], ["--report-only"]):
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                status = cli.main(["study.py", "--mcrt", sys.executable, "--no-bench", "--out", str(self.results),
                                   *mode])
            self.assertEqual(status, 2)
            lines = err.getvalue().splitlines()
            self.assertEqual(len(lines), 1, lines)
            self.assertIn("committed results", lines[0])
            self.assertIn("--overwrite-committed", lines[0])
            self.assertEqual(self.contents(), before)  # nothing written

    def test_the_command_exits_2(self):
        before = self.contents()
        run = subprocess.run([sys.executable, str(STUDY), "--report-only", "--no-bench", "--out", str(self.results)],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(run.returncode, 2, run.stderr)
        self.assertEqual(len(run.stderr.splitlines()), 1, run.stderr)
        self.assertTrue(run.stderr.startswith("study.py: "))
        self.assertEqual(self.contents(), before)

    def test_allowed_with_the_flag(self):
        args, settings = parsed("--out", str(self.results))
        self.assertTrue(output_refusal(args, settings))
        args, settings = parsed("--out", str(self.results), "--overwrite-committed")
        self.assertEqual(output_refusal(args, settings), "")

    def test_untracked_and_outside_directories_are_not_committed(self):
        (self.repo / "scratch").mkdir()
        (self.repo / "scratch" / "README.md").write_text("not committed\n")
        for out in (self.repo / "scratch", self.repo / "results" / "new", self.repo / "new"):
            args, settings = parsed("--out", str(out))
            self.assertEqual(output_refusal(args, settings), "", out)
        with tempfile.TemporaryDirectory() as elsewhere:
            args, settings = parsed("--out", elsewhere)
            self.assertEqual(output_refusal(args, settings), "")
        # A directory that holds tracked files deeper down is refused too.
        args, settings = parsed("--out", str(self.repo))
        self.assertTrue(output_refusal(args, settings))

    def test_report_only_needs_out(self):
        err = io.StringIO()
        with tempfile.TemporaryDirectory() as tmp, working_directory(Path(tmp)), contextlib.redirect_stderr(err):
            self.assertEqual(cli.main(["study.py", "--report-only", "--no-bench"]), 2)
            self.assertFalse((Path(tmp) / NEW_OUT_PARENT).exists())
        self.assertEqual(len(err.getvalue().splitlines()), 1)

    @unittest.skipUnless((REPO_ROOT / ".git").exists(), "not a git checkout")
    def test_the_repositorys_committed_results_are_refused(self):
        self.assertTrue(committed_files(COMMITTED_RESULTS))
        for sub in ("", "strategy_map", "auto"):
            out = COMMITTED_RESULTS / sub
            if committed_files(out):
                args, settings = parsed("--out", str(out))
                self.assertIn("--overwrite-committed", output_refusal(args, settings))


if __name__ == "__main__":
    unittest.main()
