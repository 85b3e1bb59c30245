#!/usr/bin/env bash
# The whole-program fuzz of mcrt (tests/fuzz.py; docs/tests.md):
#   scripts/fuzz.sh                 the long run: every structural attack and
#                                   3000 seeded mutations on build/mcrt
#                                   (about 8 minutes on 2 cores)
#   scripts/fuzz.sh --sanitize      the quick run (every attack, 100 mutations)
#                                   on an AddressSanitizer + UBSan build of the
#                                   executable in build-asan/ (built here; the
#                                   first build takes 15-20 minutes)
#   scripts/fuzz.sh --sanitize --long   the long run on that build
# Extra arguments go to tests/fuzz.py (--seed N, --mutations N, --jobs J, ...).
# The report is written to fuzz-out/ (report.json, report.md); the status is
# 1 if any case is not ok.
set -euo pipefail
cd "$(dirname "$0")/.."
sanitize=0
long=0
args=()
for a in "$@"; do
  case "$a" in
    --sanitize) sanitize=1 ;;
    --long) long=1 ;;
    *) args+=("$a") ;;
  esac
done
if [ "$sanitize" = 1 ]; then
  bash scripts/setup.sh
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMCRT_NATIVE=OFF \
    -DMCRT_BUILD_BENCH=OFF -DMCRT_BUILD_EXAMPLES=OFF \
    -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" >/dev/null
  cmake --build build-asan -j2 --target mcrt_cli
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
  # Leaks inside libraries, each with its reason (tests/lsan.supp); the list
  # of suppressions used is not printed (it would break the one-line rule).
  export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
  mode=(--quick)
  [ "$long" = 1 ] && mode=(--mutations 3000)
  exec python3 tests/fuzz.py --mcrt build-asan/mcrt --sanitizer "${mode[@]}" --check --out fuzz-out/sanitize \
    --report fuzz-out/sanitize/report.json --markdown fuzz-out/sanitize/report.md "${args[@]}"
fi
[ -x build/mcrt ] || { bash scripts/setup.sh; cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null; cmake --build build -j2 --target mcrt_cli; }
exec python3 tests/fuzz.py --mcrt build/mcrt --mutations 3000 --check --out fuzz-out/long \
  --report fuzz-out/long/report.json --markdown fuzz-out/long/report.md "${args[@]}"
