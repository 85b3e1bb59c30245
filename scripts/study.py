#!/usr/bin/env python3
"""Error against run time of the renderer's configurations: the command.

    .venv/bin/python scripts/study.py --help

The study is the package scripts/mcrt_study/; its method, options and outputs
are documented in scripts/mcrt_study/__init__.py.
"""

import sys
from pathlib import Path

_SCRIPTS = str(Path(__file__).resolve().parent)
if _SCRIPTS not in sys.path:
    sys.path.insert(0, _SCRIPTS)

from mcrt_study.cli import main, run  # noqa: E402

__all__ = ["main", "run"]

if __name__ == "__main__":
    sys.exit(run())
