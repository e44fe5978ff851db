#!/usr/bin/env bash
# Two builds of texlume timed on the same synth job, alternating in one script
# (this machine's speed drifts by 10-20 % between runs and more between days, so
# a change is measured against its baseline run beside it). The scene folders
# are bench/triangle_time_bench.sh's (WORK/s512, WORK/sphere: run it once first).
# Each row: a build's run, its CPU seconds (user + system), wall seconds and
# synthesis seconds (its manifest); after each pair, whether every atlas file the
# two models wrote (ptm_atlas_0.ptm, albedo_0.png, ...) is the same bytes.
# Usage: bench/synth_ab_bench.sh BASE_BUILD NEW_BUILD WORK [SCENES (s512 sphere)] [RUNS (2)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/bench/lib/synth_scenes.sh"
base=$(realpath "$1") new=$(realpath "$2") work=$(realpath "$3")
scenes=${4:-s512 sphere} runs=${5:-2}
echo "| scene | build | run | CPU s | wall s | synthesis s |"
echo "|---|---|---|---|---|---|"
for name in $scenes; do
  synth_scene_settings "$name"
  dir="$work/$name"
  [ -f "$dir/sample.ptm" ] || { echo "synth_ab_bench: no $dir/sample.ptm (run bench/triangle_time_bench.sh)" >&2; exit 2; }
  for run in $(seq "$runs"); do
    for side in base new; do
      build=$base
      [ "$side" = new ] && build=$new
      model="$dir/ab_$side"
      rm -rf "$model"
      times=$(timed_synth "$build/apps/texlume" "$dir" "$texel" "$model")
      python3 - "$model/manifest.json" "$name" "$side" "$run" $times <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
name, side, run, user, system, wall = sys.argv[2], sys.argv[3], sys.argv[4], *map(float, sys.argv[5:8])
print(f"| {name} | {side} | {run} | {user + system:.1f} | {wall:.1f} | {m['timings_s']['synthesis']:.1f} |")
PY
    done
    # Every atlas either model wrote (PTM atlases and the pictures baked beside them).
    same=1
    for atlas in "$dir"/ab_base/*_[0-9]*.* "$dir"/ab_new/*_[0-9]*.*; do
      other="$dir/ab_base/$(basename "$atlas")"
      [ "$other" = "$atlas" ] && other="$dir/ab_new/$(basename "$atlas")"
      cmp -s "$atlas" "$other" || same=0
    done
    if [ "$same" = 1 ]; then
      echo "atlases: the same bytes" >&2
    else
      echo "atlases: different" >&2
    fi
  done
done
