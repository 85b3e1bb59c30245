#!/usr/bin/env bash
# Configures and builds everything (library, mcrt, tests, benchmarks) in build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --python
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
