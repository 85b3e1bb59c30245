#!/usr/bin/env bash
# Set-up, build, and run every test (ctest; the slow ones too).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
