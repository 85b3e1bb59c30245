#!/usr/bin/env bash
# The tests that read untrusted input (the pbrt-v4 parser, the PLY reader,
# the scene builder and their fuzz tests), built with AddressSanitizer and UndefinedBehaviorSanitizer
# in build-asan/ and run; any report stops the run with a non-zero status.
# Slow (a separate build), so not part of scripts/test.sh. Extra arguments go
# to each test binary (e.g. --gtest_filter='*Fuzz*').
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMCRT_NATIVE=OFF -DMCRT_BUILD_BENCH=OFF \
  -DMCRT_BUILD_EXAMPLES=OFF -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" >/dev/null
cmake --build build-asan -j"$(nproc)" --target test_pbrt_parser test_ply test_pbrt_scenes
for t in test_pbrt_parser test_ply; do
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 "build-asan/tests/$t" "$@"
done
# The builder's fuzz test and its refusals (the renders of that file are
# left to the ordinary build: they are slow under the sanitizers).
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 build-asan/tests/test_pbrt_scenes \
  --gtest_filter='PbrtBuilder.*:Contract/*' "$@"
