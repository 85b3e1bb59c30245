"""python -m mcrt_study (with scripts/ on the path): the same as scripts/study.py."""

import sys

from .cli import run

sys.exit(run())
