#!/usr/bin/env bash
# Photos on demand (issue 33): time and peak memory of `texlume synth` as the
# number of large photos grows past what its photo cache holds. For each photo
# count it writes a clean stone sphere (`texlume scene --images N`, 640 x 480),
# makes its photos SCALE times larger (bench/upscale_photos: bicubic, JPEG quality
# 90, cameras scaled; 6.25 gives 4000 x 3000 = 12 MP), fits the sample from the
# scene's capture, and runs the main job with `--photo-cache CACHE` (2G by
# default) and, when every photo fits in ALL_LIMIT bytes (8 GiB by default), with
# the default cache, which then holds them all. Each row: the photos and what
# holding them all would take, the cache's budget, decodes and decoding time,
# synthesis and whole-job time, the job's peak resident memory (its manifest's
# resources.peak_resident_bytes), and the held-out PSNR / SSIM at the scene's
# held-out views and lights (texlume render against the truth).
# Usage: bench/photo_cache_bench.sh [BUILD_DIR (build)] [WORK_DIR (temporary)] [COUNTS (32 128 512)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$root/build}")
texlume="$build/apps/texlume"
work=${2:-$(mktemp -d)}
counts=${3:-32 128 512}
scale=${SCALE:-6.25}
cache=${CACHE:-2G}
all_limit=${ALL_LIMIT:-8589934592}
mkdir -p "$work"
echo "| photos | all photos MiB | cache MiB | decodes | decoding s | synthesis s | job s | peak resident MiB | held-out PSNR / SSIM |"
echo "|---|---|---|---|---|---|---|---|---|"
for n in $counts; do
  scene="$work/scene_$n" big="$work/big_$n"
  if [ ! -f "$scene/scene.json" ]; then
    echo "photo_cache_bench: scene of $n photos" >&2
    "$texlume" scene --out "$scene" --kind sphere --images "$n" --clean --samples 1 --no-btf \
      --held-out-views 2 --held-out-lights 3 --capture-size 128 --capture-lights 24 > /dev/null
  fi
  if [ ! -f "$big/object/lights.json" ]; then
    "$build/bench/upscale_photos" "$scene/object" "$big/object" "$scale" > /dev/null
  fi
  capture="$scene/material/capture"
  [ -f "$scene/sample.ptm" ] ||
    "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$scene/sample.ptm" > /dev/null
  run() {  # NAME [synth options]
    local name=$1
    shift
    local model="$big/model_$name"
    rm -rf "$model" "$big/render_$name"
    local start=$SECONDS
    "$texlume" synth --model "$big/object/sparse" --images "$big/object/images" \
      --lights "$big/object/lights.json" --mesh "$big/object/mesh.ply" --no-report \
      --sample "$scene/sample.ptm" --sample-texel-size 0.002 --out "$model" "$@" > /dev/null
    local seconds=$((SECONDS - start))
    local held="$scene/object/held_out"
    "$texlume" render --model "$model" --cameras "$held/sparse" --lights "$held/lights.json" \
      --truth "$held/images" --truth-masks "$held/masks" --out "$big/render_$name" > /dev/null
    python3 - "$model/manifest.json" "$big/render_$name/render.json" "$n" "$seconds" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
r = json.load(open(sys.argv[2]))
c = m["summary"]["photo_cache"]
mib = lambda b: b / 2**20
print(f"| {sys.argv[3]} | {mib(c['all_photos_bytes']):.0f} | {mib(c['budget_bytes']):.0f}"
      f"{' (all)' if c['holds_all'] else ''} | {c['decodes']} | {c['timings_s']['decoding']:.1f}"
      f" | {m['timings_s']['synthesis']:.1f} | {sys.argv[4]}"
      f" | {mib(m['resources']['peak_resident_bytes']):.0f}"
      f" | {r['metrics']['mean_psnr_db']:.2f} / {r['metrics']['mean_ssim']:.3f} |")
PY
  }
  run "cache" --photo-cache "$cache"
  all_bytes=$(python3 -c "import json; print(json.load(open('$big/model_cache/manifest.json'))['summary']['photo_cache']['all_photos_bytes'])")
  if [ "$all_bytes" -le "$all_limit" ]; then run "all"; fi
done
