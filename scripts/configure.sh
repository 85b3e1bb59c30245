#!/usr/bin/env bash
# Configures build/ for a Release build, with Ninja where it is installed
# (scripts/setup.sh installs it) and Make otherwise; a build/ configured
# before keeps its generator. Extra arguments go to cmake (-D options).
set -euo pipefail
cd "$(dirname "$0")/.."
generator=()
if [ ! -f build/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then
  generator=(-G Ninja)
fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
