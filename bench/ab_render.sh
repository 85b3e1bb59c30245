#!/usr/bin/env bash
# A/B render time of two mcrt executables on one scene, interleaved (A, B,
# A, B, ...) so that the machine's drift (up to 20 % over a day) affects
# both alike; prints each round's seconds (render time from --stats) and
# the ratio B/A per round, then the median ratio. Also reports whether the
# two images of the first round are bit-identical (mcrt diff: mse 0).
#
# Usage: bench/ab_render.sh A_MCRT B_MCRT ROUNDS SCENE [render flags...]
#   e.g. bench/ab_render.sh /tmp/mcrt-old build/mcrt 5 scenes/cornell_book3.json --threads 2
# Environment: A_FLAGS, B_FLAGS: extra flags for one side only.
set -euo pipefail
cd "$(dirname "$0")/.."
a=$1 b=$2 rounds=$3 scene=$4
shift 4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
seconds() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["render_seconds"])' "$1"; }
ratios=()
echo "| round | A seconds | B seconds | B / A |"
echo "|---|---|---|---|"
for ((i = 1; i <= rounds; i++)); do
  # shellcheck disable=SC2086
  "$a" render "$scene" -o "$tmp/a$i.exr" --quiet --stats "$tmp/a.json" "$@" ${A_FLAGS:-}
  # shellcheck disable=SC2086
  "$b" render "$scene" -o "$tmp/b$i.exr" --quiet --stats "$tmp/b.json" "$@" ${B_FLAGS:-}
  sa=$(seconds "$tmp/a.json") sb=$(seconds "$tmp/b.json")
  r=$(python3 -c "print(f'{$sb / $sa:.4f}')")
  ratios+=("$r")
  echo "| $i | $sa | $sb | $r |"
done
python3 -c "import statistics,sys; print(f'median B / A: {statistics.median(map(float, sys.argv[1:])):.4f}')" "${ratios[@]}"
mse=$("$b" diff "$tmp/b1.exr" "$tmp/a1.exr" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["mse"])')
if [ "$mse" = "0.0" ]; then echo "images of round 1: bit-identical"; else echo "images of round 1: differ (mse $mse)"; fi
