#!/usr/bin/env bash
# Set-up, build, and run every test (ctest; the slow ones too).
#   scripts/test.sh            every test (what CI runs)
#   scripts/test.sh --quick    all but the `slow` label (the fuzz of the
#                              executable, the study's quick run, the 10^6-
#                              configuration hunts)
# Other arguments go to ctest (e.g. -R Sphere, -L unit).
set -euo pipefail
cd "$(dirname "$0")/.."
args=()
for a in "$@"; do
  if [ "$a" = --quick ]; then args+=(-LE slow); else args+=("$a"); fi
done
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "${args[@]}"
