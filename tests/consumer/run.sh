#!/usr/bin/env bash
# Installs mcrt from a build tree into a scratch prefix, builds the README's
# C++ example against it with find_package(mcrt), runs it and checks that it
# wrote its image. Usage: run.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1
build=$2
work=$build/consumer-test
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
# The first ```cpp block of the README is the example.
awk '/^```cpp/{f=1; next} /^```/{if (f) exit} f' "$src/README.md" >"$work/main.cpp"
[ -s "$work/main.cpp" ] || { echo "no C++ example in README.md"; exit 1; }
cmake -S "$src/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" -DMAIN="$work/main.cpp" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" >/dev/null
(cd "$work" && ./build/consumer)
head -c 2 "$work/floor.ppm" | grep -q P3 || { echo "the example wrote no PPM image"; exit 1; }
echo "README example: built against the installed package, ran, wrote floor.ppm"
