"""The report's commit line: a study rewrites its own outputs, which may be tracked files of
the repository (bench/results/...); those changes are the run's, not the renderer's, and must
not mark the commit as having uncommitted changes. A change anywhere else must.
"""

import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path
from unittest import mock

from mcrt_study import report


def git(repo: Path, *args: str) -> None:
    subprocess.run(["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t", *args],
                   check=True, capture_output=True)


@unittest.skipUnless(shutil.which("git"), "git not installed")
class ReportCommitTest(unittest.TestCase):
    def test_outputs_of_the_study_are_not_uncommitted_changes(self):
        with tempfile.TemporaryDirectory() as tmp:
            repo = Path(tmp)
            (repo / "results").mkdir()
            (repo / "results" / "README.md").write_text("old report\n")
            (repo / "src.txt").write_text("renderer\n")
            git(repo, "init", "-q")
            git(repo, "add", ".")
            git(repo, "commit", "-q", "-m", "c")
            with mock.patch.object(report, "REPO_ROOT", repo):
                clean = report.machine_info(repo / "results")["commit"]
                self.assertRegex(clean, r"^[0-9a-f]{40}$")
                (repo / "results" / "README.md").write_text("new report\n")
                self.assertEqual(report.machine_info(repo / "results")["commit"], clean)
                # Without the output directory named, the same change counts.
                self.assertTrue(report.machine_info()["commit"].endswith("(with uncommitted changes)"))
                (repo / "src.txt").write_text("changed renderer\n")
                self.assertTrue(report.machine_info(repo / "results")["commit"].endswith("(with uncommitted changes)"))
                # An output directory outside the repository excludes nothing.
                with tempfile.TemporaryDirectory() as elsewhere:
                    self.assertTrue(report.machine_info(Path(elsewhere))["commit"].endswith(
                        "(with uncommitted changes)"))


if __name__ == "__main__":
    unittest.main()
