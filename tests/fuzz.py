#!/usr/bin/env python3
"""Black-box fuzzing of the mcrt executable: the command.

    python3 tests/fuzz.py --mcrt build/mcrt --quick --out /tmp/fuzz --report /tmp/fuzz/report.json

The harness is the package tests/mcrt_fuzz/; its method, cases, classes,
options and outputs are documented in tests/mcrt_fuzz/__init__.py.
Standard library only.
"""

import sys
from pathlib import Path

_TESTS = str(Path(__file__).resolve().parent)
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)

from mcrt_fuzz.cli import main, run  # noqa: E402

__all__ = ["main", "run"]

if __name__ == "__main__":
    sys.exit(run())
