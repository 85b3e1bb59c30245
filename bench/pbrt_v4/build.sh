#!/usr/bin/env bash
# Builds pbrt-v4 (CPU), the peer that defines the pbrt-v4 format, into
# build/pbrt-v4/build/pbrt, on demand: bench only, never needed by the
# tests or CI. Safe to run again (does nothing once built).
#
# Usage: bench/pbrt_v4/build.sh [--source DIR]
#   --source DIR  a pbrt-v4 source tree with its submodules under src/ext/
#                 (default: cloned with --recursive from
#                 https://github.com/mmp/pbrt-v4 at the commit below into
#                 build/pbrt-v4/src)
#
# A copy of the repository without its files of 4 MiB or more lacks
# src/pbrt/util/bluenoise.cpp and pmj02tables.cpp: the build then writes
# stand-ins of their declarations, all zeros, and lists them in
# build/pbrt-v4/standins.txt, which bench/pbrt_v4's reports print. They are
# read only by Sampler "pmj02bn" and by dithering of 8-bit output; the
# comparison renders with the file's sampler to EXR and refuses pmj02bn
# when they are stand-ins.
set -euo pipefail
cd "$(dirname "$0")/../.."
pin=5f7a606806a4ac7b939131ded9d7a30ebd02416e
out=build/pbrt-v4
src=$out/src
while [ $# -gt 0 ]; do
  case "$1" in
    --source) src=$(realpath "$2"); shift 2 ;;
    *) echo "build.sh: unknown option $1 (expected --source DIR)" >&2; exit 2 ;;
  esac
done
[ -x "$out/build/pbrt" ] && { echo "$out/build/pbrt"; exit 0; }

packages=(cmake ninja-build g++ zlib1g-dev libopenexr-dev libgl-dev libx11-dev libxrandr-dev libxinerama-dev
          libxcursor-dev libxi-dev libxkbcommon-dev)
bash scripts/install_debian.sh "${packages[@]}"

mkdir -p "$out"
if [ ! -f "$src/CMakeLists.txt" ]; then
  git clone --quiet --recursive https://github.com/mmp/pbrt-v4 "$src"
  git -C "$src" checkout --quiet "$pin"
  git -C "$src" submodule --quiet update --init --recursive
fi

# Stand-ins for the two tables a copy without large files lacks.
: >"$out/standins.txt"
if [ ! -f "$src/src/pbrt/util/bluenoise.cpp" ]; then
  cat >"$src/src/pbrt/util/bluenoise.cpp" <<'CPP'
// Stand-in (bench/pbrt_v4/build.sh): the original table is absent from this copy.
#include <pbrt/util/bluenoise.h>
namespace pbrt {
PBRT_CONST uint16_t BlueNoiseTextures[NumBlueNoiseTextures][BlueNoiseResolution][BlueNoiseResolution] = {};
}  // namespace pbrt
CPP
  echo "src/pbrt/util/bluenoise.cpp" >>"$out/standins.txt"
fi
if [ ! -f "$src/src/pbrt/util/pmj02tables.cpp" ]; then
  cat >"$src/src/pbrt/util/pmj02tables.cpp" <<'CPP'
// Stand-in (bench/pbrt_v4/build.sh): the original table is absent from this copy.
#include <pbrt/util/pmj02tables.h>
namespace pbrt {
PBRT_CONST uint32_t pmj02bnSamples[nPMJ02bnSets][nPMJ02bnSamples][2] = {};
}  // namespace pbrt
CPP
  echo "src/pbrt/util/pmj02tables.cpp" >>"$out/standins.txt"
fi

# BUILD_TESTING=OFF: ptex's include(CTest) would build double-conversion's
# tests; Wayland off: glfw (linked by pbrt's gui.cpp) builds for X11 only.
cmake -S "$src" -B "$out/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DGLFW_BUILD_WAYLAND=OFF \
  >"$out/configure.log" 2>&1 || { tail -20 "$out/configure.log" >&2; exit 1; }
cmake --build "$out/build" -j"$(nproc)" --target pbrt_exe >"$out/build.log" 2>&1 || { tail -30 "$out/build.log" >&2; exit 1; }
echo "$out/build/pbrt"
