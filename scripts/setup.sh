#!/usr/bin/env bash
# Installs what mcrt needs on a fresh Debian 12 machine, and nothing that is
# already there: the compiler and CMake and the libraries (Debian packages);
# with --python also a Python virtual environment .venv with the study's
# packages (plots, Dask; from PyPI), which rendering does not need.
# Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."
python_env=0
for a in "$@"; do
  case "$a" in
    --python) python_env=1 ;;
    *) echo "setup: unknown option $a (expected --python)" >&2; exit 2 ;;
  esac
done

packages=(cmake g++ make ninja-build pkg-config libglm-dev libopenimageio-dev nlohmann-json3-dev libcli11-dev
          libgtest-dev libbenchmark-dev libboost-math-dev zlib1g-dev python3 python3-venv)
bash scripts/install_debian.sh "${packages[@]}"

# Python for scripts/ (the error-vs-time study, its plots and its Dask backend)
# and for the documentation check (cffconvert validates CITATION.cff).
# An existing .venv that lacks a package is upgraded in place.
[ "$python_env" = 1 ] || exit 0
if [ ! -x .venv/bin/python ] || [ ! -x .venv/bin/cffconvert ] || ! .venv/bin/python -c "import numpy, matplotlib, distributed" 2>/dev/null; then
  echo "setup: installing scripts/requirements.txt into .venv" >&2
  [ -x .venv/bin/python ] || python3 -m venv .venv
  .venv/bin/pip install -q --disable-pip-version-check --upgrade -r scripts/requirements.txt
fi
