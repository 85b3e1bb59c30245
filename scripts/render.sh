#!/usr/bin/env bash
# Set-up (Debian packages only), build the mcrt executable alone (not the
# tests or benchmarks), and render the default Cornell box to
# cornell_rect.png. Extra arguments go to `mcrt render` (e.g. --spp 400
# -o box.exr).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/configure.sh
cmake --build build -j"$(nproc)" --target mcrt_cli
build/mcrt render scenes/cornell_rect.json -o cornell_rect.png "$@"
