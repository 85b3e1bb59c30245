#!/usr/bin/env bash
# Set-up, build, and render the default Cornell box to cornell_rect.png.
# Extra arguments go to `mcrt render` (e.g. --spp 400 -o box.exr).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
build/mcrt render scenes/cornell_rect.json -o cornell_rect.png "$@"
