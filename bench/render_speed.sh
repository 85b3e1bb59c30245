#!/usr/bin/env bash
# Render throughput of the mcrt executable: camera samples per second of
# `mcrt render` (render time from --stats: rendering only, no start-up or
# file output), best of N runs per scene, as a markdown table.
#
# Usage: bench/render_speed.sh [MCRT] [RUNS] [SCENE...]
#   defaults: build/mcrt, 3 runs, scenes/cornell_book3.json
# Environment: THREADS (default: all hardware threads), STRATEGY (area or
# solid-angle; default: as each scene file says), ELLIPSE_MAP (parallel or
# polar: the map of ellipses sampled by solid angle; default parallel),
# INTEGRATOR (mixture, nee or mis), SAMPLER (independent, stratified, sobol).
set -euo pipefail
cd "$(dirname "$0")/.."
mcrt=${1:-build/mcrt}
runs=${2:-3}
shift $(( $# > 2 ? 2 : $# )) || true
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(scenes/cornell_book3.json)
threads=${THREADS:-$(nproc)}
extra=()
[ -n "${STRATEGY:-}" ] && extra=(--light-sampling "$STRATEGY")
[ -n "${ELLIPSE_MAP:-}" ] && extra+=(--ellipse-map "$ELLIPSE_MAP")
[ -n "${INTEGRATOR:-}" ] && extra+=(--integrator "$INTEGRATOR")
[ -n "${SAMPLER:-}" ] && extra+=(--sampler "$SAMPLER")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "| scene | resolution | spp | threads | light sampling | integrator | sampler | seconds (best of $runs) | samples/s |"
echo "|---|---|---|---|---|---|---|---|---|"
for scene in "${scenes[@]}"; do
  best=""
  for ((i = 0; i < runs; i++)); do
    "$mcrt" render "$scene" -o "$tmp/out.exr" --threads "$threads" --quiet --stats "$tmp/stats.json" "${extra[@]}"
    s=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["render_seconds"])' "$tmp/stats.json")
    if [ -z "$best" ] || python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) < float(sys.argv[2]) else 1)' "$s" "$best"; then
      best=$s
      cp "$tmp/stats.json" "$tmp/best.json"
    fi
  done
  python3 - "$tmp/best.json" "$(basename "$scene")" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(f"| {sys.argv[2]} | {j['width']}x{j['height']} | {j['spp']} | {j['threads']} | {j['light_sampling']} | "
      f"{j.get('integrator', 'mixture')} | {j.get('sampler', 'independent')} | "
      f"{j['render_seconds']:.2f} | {j['samples_per_second'] / 1e6:.2f} M |")
PY
done
