#!/usr/bin/env bash
# First contact: from `git clone` of this commit to the default image on
# disk, the steps of scripts/render.sh timed one by one (clone, set-up's
# package check, configure, build of the executable, the default render),
# for build configurations compared A, B, C, A, B, C, ... so that the
# machine's drift touches each alike. Prints a markdown table of the median
# of each step and whether each configuration's image equals the first's
# bit for bit (mcrt diff: rmse 0).
#
# Usage: bench/first_contact.sh [ROUNDS] [CONFIG...]
#   ROUNDS   default 3
#   CONFIG   cmake options, one string per configuration; "make:" before
#            them builds with Make instead of Ninja. Default: "" (the
#            defaults) "-DMCRT_LTO=OFF" "-DMCRT_LTO=OFF
#            -DMCRT_PRECOMPILED_HEADER=OFF" "make:-DMCRT_LTO=OFF
#            -DMCRT_PRECOMPILED_HEADER=OFF"
# Needs the Debian packages of scripts/setup.sh already installed (their
# installation is not part of the measure).
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
rounds=${1:-3}
shift $(( $# > 0 ? 1 : 0 ))
configs=("$@")
[ ${#configs[@]} -gt 0 ] || configs=("" "-DMCRT_LTO=OFF" "-DMCRT_LTO=OFF -DMCRT_PRECOMPILED_HEADER=OFF"
                                   "make:-DMCRT_LTO=OFF -DMCRT_PRECOMPILED_HEADER=OFF")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }

for ((r = 0; r < rounds; r++)); do
  for ((c = 0; c < ${#configs[@]}; c++)); do
    cfg=${configs[$c]}
    gen=()
    if [[ $cfg == make:* ]]; then gen=(-G "Unix Makefiles"); cfg=${cfg#make:}; fi
    dir=$work/clone
    rm -rf "$dir"
    t0=$(now)
    git clone -q "$repo" "$dir"
    t1=$(now)
    (cd "$dir" && bash scripts/setup.sh)
    t2=$(now)
    # shellcheck disable=SC2086  # cfg is a list of options
    (cd "$dir" && if [ ${#gen[@]} -gt 0 ]; then cmake -S . -B build "${gen[@]}" $cfg >/dev/null; fi &&
      bash scripts/configure.sh $cfg)
    t3=$(now)
    (cd "$dir" && cmake --build build -j"$(nproc)" --target mcrt_cli >"$work/build_$c.log" 2>&1)
    t4=$(now)
    (cd "$dir" && build/mcrt render scenes/cornell_rect.json -o cornell_rect.exr --quiet)
    t5=$(now)
    warnings=$(grep -c "warning:" "$work/build_$c.log" || true)
    same=yes
    if [ "$r" -eq 0 ] && [ "$c" -eq 0 ]; then cp "$dir/cornell_rect.exr" "$work/first.exr"; fi
    if ! "$dir/build/mcrt" diff "$dir/cornell_rect.exr" "$work/first.exr" | grep -qx "rmse 0"; then same=no; fi
    echo "$c $t0 $t1 $t2 $t3 $t4 $t5 $warnings $same" >>"$work/times"
  done
done

python3 - "$work/times" "$(git rev-parse --short HEAD)" "${configs[@]}" <<'PY'
import statistics, sys, platform, os, subprocess
rows = [l.split() for l in open(sys.argv[1])]
commit, configs = sys.argv[2], sys.argv[3:]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
print(f"commit {commit}; {os.cpu_count()} cores, {cpu}; {len(rows) // len(configs)} rounds, medians in seconds\n")
print("| configuration | clone | set-up check | configure | build `mcrt` | render | clone to image | warnings | image = first |")
print("|---|---|---|---|---|---|---|---|---|")
for c, cfg in enumerate(configs):
    mine = [list(map(float, r[1:7])) for r in rows if int(r[0]) == c]
    steps = [statistics.median(t[i + 1] - t[i] for t in mine) for i in range(5)]
    total = statistics.median(t[5] - t[0] for t in mine)
    warn = max(int(r[7]) for r in rows if int(r[0]) == c)
    same = all(r[8] == "yes" for r in rows if int(r[0]) == c)
    name = cfg.replace("make:", "Make, ") if cfg else "defaults (Ninja, LTO, PCH)"
    if not cfg.startswith("make:") and cfg:
        name = "Ninja, " + cfg
    print(f"| {name} | " + " | ".join(f"{s:.1f}" for s in steps) + f" | {total:.1f} | {warn} | {'yes' if same else 'no'} |")
PY
