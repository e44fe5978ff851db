#!/usr/bin/env bash
# Time per triangle of the main job's placement search (issue 33): `texlume synth`
# with `--search exhaustive` (paper 003: every placement of the sample scored by
# FFT for every face) and `--search coarse-to-fine` (the default) on the same
# scenes, in the same run. Scenes (SCENES, both by default): s512 and sphere
# (bench/lib/synth_scenes.sh).
# Each row: the job's CPU seconds (user + system) and per triangle of the mesh it
# synthesised, its synthesis seconds (its manifest) and whole-job wall seconds, and the
# held-out PSNR / SSIM at full resolution and reduced 4 x 4 (texlume render
# against the truth, inside the masks). The last column is the exhaustive
# search's CPU over this row's.
# Usage: bench/triangle_time_bench.sh [BUILD_DIR (build)] [WORK_DIR (temporary)] [SCENES (s512 sphere)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/bench/lib/synth_scenes.sh"
build=$(realpath "${1:-$root/build}")
texlume="$build/apps/texlume"
work=${2:-$(mktemp -d)}
scenes=${3:-s512 sphere}
mkdir -p "$work"
echo "| scene | search | CPU s | CPU ms per triangle | synthesis s | job s | held-out PSNR / SSIM | reduced 4x4 | CPU ratio |"
echo "|---|---|---|---|---|---|---|---|---|"
for name in $scenes; do
  dir="$work/$name"
  synth_scene_settings "$name"
  if [ ! -f "$dir/scene.json" ]; then
    echo "triangle_time_bench: scene $name" >&2
    "$texlume" scene --out "$dir" --no-btf "${scene_args[@]}" > /dev/null
  fi
  capture="$dir/material/capture" held="$dir/object/held_out"
  [ -f "$dir/sample.ptm" ] ||
    "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$dir/sample.ptm" > /dev/null
  baseline_cpu=""
  for search in exhaustive coarse-to-fine; do
    model="$dir/model_$search"
    rm -rf "$model" "$dir/render_$search"
    times=$(timed_synth "$texlume" "$dir" "$texel" "$model" --search "$search")
    cpu=$(echo "$times" | awk '{print $1 + $2}') wall=$(echo "$times" | awk '{print $3}')
    "$texlume" render --model "$model" --cameras "$held/sparse" --lights "$held/lights.json" \
      --truth "$held/images" --truth-masks "$held/masks" --reduced-factor 4 \
      --out "$dir/render_$search" > /dev/null
    baseline_cpu=${baseline_cpu:-$cpu}
    python3 - "$model/manifest.json" "$dir/render_$search/render.json" "$name" "$search" \
      "$cpu" "$baseline_cpu" "$wall" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
r = json.load(open(sys.argv[2]))["metrics"]
name, search, cpu, base, wall = sys.argv[3], sys.argv[4], *map(float, sys.argv[5:8])
faces = m["summary"]["faces"]
t = m["timings_s"]
print(f"| {name} ({faces} faces) | {search} | {cpu:.1f} | {1000 * cpu / faces:.1f}"
      f" | {t['synthesis']:.1f} | {wall:.1f}"
      f" | {r['mean_psnr_db']:.2f} / {r['mean_ssim']:.3f}"
      f" | {r['mean_psnr_reduced_db']:.2f} / {r['mean_ssim_reduced']:.3f} | {base / cpu:.2f} |")
PY
  done
done
