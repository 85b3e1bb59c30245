#!/usr/bin/env bash
# Configures and builds everything (library, mcrt, tests, benchmarks) in build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --python
bash scripts/configure.sh
cmake --build build -j"$(nproc)"
