"""The report's provenance and links: the renderer's commit is the last commit of the renderer's
sources, marked as changed only by changes to those sources (not by documentation, tests or the
study's own outputs); the report links only the figures git keeps beside it.
"""

import datetime
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path
from unittest import mock

from mcrt_study import report
from mcrt_study.config import build_parser, resolve_settings


def git(repo: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t", *args],
                          check=True, capture_output=True, text=True).stdout.strip()


@unittest.skipUnless(shutil.which("git"), "git not installed")
class RendererCommitTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        repo = self.repo = Path(self.tmp.name)
        for name, text in (("include/mcrt/a.hpp", "a\n"), ("src/main.cpp", "m\n"), ("CMakeLists.txt", "c\n"),
                           ("README.md", "r\n"), ("tests/t.cpp", "t\n"), ("results/README.md", "old\n")):
            (repo / name).parent.mkdir(parents=True, exist_ok=True)
            (repo / name).write_text(text)
        git(repo, "init", "-q")
        git(repo, "add", ".")
        git(repo, "commit", "-q", "-m", "renderer")
        self.renderer = git(repo, "log", "-1", "--format=%h")
        (repo / "README.md").write_text("documentation, committed later\n")
        git(repo, "commit", "-q", "-am", "docs")
        self.patch = mock.patch.object(report, "REPO_ROOT", repo)
        self.patch.start()

    def tearDown(self):
        self.patch.stop()
        self.tmp.cleanup()

    def test_names_the_last_commit_of_the_renderers_sources(self):
        self.assertNotEqual(git(self.repo, "log", "-1", "--format=%h"), self.renderer)
        self.assertEqual(report.renderer_commit(self.repo / "results"), (self.renderer, False))

    def test_changes_elsewhere_do_not_count(self):
        (self.repo / "README.md").write_text("being edited\n")
        (self.repo / "tests" / "t.cpp").write_text("being edited\n")
        (self.repo / "results" / "README.md").write_text("the run's new report\n")
        (self.repo / "docs.md").write_text("new page\n")
        self.assertEqual(report.renderer_commit(self.repo / "results"), (self.renderer, False))

    def test_changes_to_the_sources_count(self):
        for change in (lambda: (self.repo / "src" / "main.cpp").write_text("changed\n"),
                       lambda: (self.repo / "include" / "mcrt" / "new.hpp").write_text("new\n"),
                       lambda: (self.repo / "CMakeLists.txt").write_text("changed\n")):
            change()
            self.assertEqual(report.renderer_commit(self.repo / "results"), (self.renderer, True))
            git(self.repo, "checkout", "-q", "--", ".")
            git(self.repo, "clean", "-fdq")
            self.assertEqual(report.renderer_commit(self.repo / "results"), (self.renderer, False))

    def test_outputs_inside_the_sources_are_the_runs(self):
        # A study's output directory among the renderer's sources: what the run rewrites there is
        # its own output, not a change of the renderer; the same change counts when that
        # directory is not named, and an output directory outside the repository excludes nothing.
        out = self.repo / "src" / "study"
        out.mkdir()
        (out / "README.md").write_text("old report\n")
        git(self.repo, "add", ".")
        git(self.repo, "commit", "-q", "-m", "a report among the sources")
        renderer = git(self.repo, "log", "-1", "--format=%h")
        (out / "README.md").write_text("the run's new report\n")
        self.assertEqual(report.renderer_commit(out), (renderer, False))
        self.assertEqual(report.renderer_commit(), (renderer, True))
        with tempfile.TemporaryDirectory() as elsewhere:
            self.assertEqual(report.renderer_commit(Path(elsewhere)), (renderer, True))
        (self.repo / "src" / "main.cpp").write_text("changed renderer\n")
        self.assertEqual(report.renderer_commit(out), (renderer, True))

    def test_outside_a_repository(self):
        with tempfile.TemporaryDirectory() as elsewhere, mock.patch.object(report, "REPO_ROOT", Path(elsewhere)):
            self.assertEqual(report.renderer_commit(), ("unknown", False))


@unittest.skipUnless(shutil.which("git"), "git not installed")
class FigureLinksTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        repo = self.repo = Path(self.tmp.name)
        (repo / ".gitignore").write_text("*.png\n!results/kept_*.png\nscratch/\n")
        for d in ("results", "scratch"):
            (repo / d).mkdir()
            (repo / d / "README.md").write_text("report\n")
            for name in ("kept_a.png", "other.png"):
                (repo / d / name).write_bytes(b"png")
        git(repo, "init", "-q")
        git(repo, "add", ".")
        git(repo, "commit", "-q", "-m", "c")

    def tearDown(self):
        self.tmp.cleanup()

    def test_unkept_figures(self):
        names = ["kept_a.png", "other.png"]
        self.assertEqual(report.unkept_figures(self.repo / "results", names), ["other.png"])
        # A report git ignores keeps every figure beside it; so does one outside any repository.
        self.assertEqual(report.unkept_figures(self.repo / "scratch", names), [])
        with tempfile.TemporaryDirectory() as elsewhere:
            self.assertEqual(report.unkept_figures(Path(elsewhere), names), [])

    def test_drop_figure_links(self):
        text = ("## Families\n\n| table |\n\n![kept_a.png](kept_a.png)\n\ncaption a\n"
                "\n![other.png](other.png)\n\ncaption other\n\nmore text\n")
        dropped = report.drop_figure_links(text, ["other.png"])
        self.assertNotIn("other.png", dropped)
        self.assertNotIn("caption other", dropped)
        self.assertIn("![kept_a.png](kept_a.png)\n\ncaption a\n", dropped)
        self.assertIn("more text", dropped)

    def test_the_report_links_only_kept_figures(self):
        out = self.repo / "results"
        argv = ["study.py", "--report-only", "--out", str(out), "--mcrt", sys.executable, "--no-bench",
                "--scenes", "cornell_rect"]
        settings = resolve_settings(build_parser().parse_args(argv[1:]), argv)
        tables = "### Families\n\n![other.png](other.png)\n\nin the tables\n"
        figures = [("kept_a.png", "caption kept"), ("other.png", "caption other")]
        with mock.patch.object(report, "REPO_ROOT", self.repo):
            report.write_report(settings, [], tables, figures, datetime.datetime.now(datetime.timezone.utc))
        text = (out / "README.md").read_text()
        self.assertIn("![kept_a.png](kept_a.png)", text)
        self.assertNotIn("](other.png)", text)
        self.assertNotIn("](other.png)", (out / "tables.md").read_text())
        self.assertIn("not kept by git (so not linked): `other.png`", text)
        self.assertRegex(text, r"- Renderer: commit `[0-9a-f]{7,}` \(mcrt sha256 [0-9a-f]{12}…")
        self.assertRegex(text, r"- Machine: \d+-core .*machine, CPU ")


if __name__ == "__main__":
    unittest.main()
