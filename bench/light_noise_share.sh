#!/usr/bin/env bash
# How much of an image's error is the lights' own sampling noise, per
# sample generator: R = (MSE_area - MSE_psa) / MSE_psa, the image's MSE
# with area sampling over its MSE with projected-solid-angle sampling (no
# variance of its own for an unoccluded light on a diffuse receiver), minus
# 1, at each spp, with independent and with Sobol samples (nee; the mean
# MSE of SEEDS renders against a 4096-spp reference). The ratio of the two
# samplers' R says how much more a quasi-random sequence removes of the
# light's noise than of the rest (edges, visibility, indirect light), which
# the `auto` rule, modelled on independent samples, does not know.
#
# Usage: bench/light_noise_share.sh SCENE.json... (environment: SPP="8 32
#   128", DEPTHS="1 50", SEEDS=6, SIZE=100, MCRT=build/mcrt)
set -euo pipefail
cd "$(dirname "$0")/.."
mcrt=${MCRT:-build/mcrt} size=${SIZE:-100} seeds=${SEEDS:-6}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mse() { "$mcrt" diff "$1" "$2" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["mse"])'; }
echo "| scene | max depth | spp | R independent | R sobol | sobol / independent |"
echo "|---|---:|---:|---:|---:|---:|"
for scene in "$@"; do
  for depth in ${DEPTHS:-1 50}; do
    ref=$tmp/ref.exr
    "$mcrt" render "$scene" -o "$ref" --quiet --spp 4096 --width "$size" --height "$size" --max-depth "$depth" \
      --integrator mis --sampler sobol --light-sampling solid-angle --seed 7919
    for spp in ${SPP:-8 32 128}; do
      declare -A r=()
      for sampler in independent sobol; do
        declare -A m=()
        for strategy in area projected-solid-angle; do
          total=0
          for ((seed = 1; seed <= seeds; seed++)); do
            "$mcrt" render "$scene" -o "$tmp/x.exr" --quiet --spp "$spp" --width "$size" --height "$size" \
              --max-depth "$depth" --integrator nee --sampler "$sampler" --light-sampling "$strategy" --seed "$seed"
            total=$(python3 -c "print($total + $(mse "$tmp/x.exr" "$ref") / $seeds)")
          done
          m[$strategy]=$total
        done
        r[$sampler]=$(python3 -c "print(${m[area]} / ${m[projected-solid-angle]} - 1)")
      done
      python3 -c "i, s = ${r[independent]}, ${r[sobol]}; print(f'| $(basename "$scene" .json) | $depth | $spp | {i:.3f} | {s:.3f} | {s / i:.2f} |')"
    done
  done
done
