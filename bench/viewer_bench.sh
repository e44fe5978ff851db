#!/usr/bin/env bash
# Viewer start-up and frame times (issue 7: "a 20k-triangle model is
# interactive within 2 seconds of opening"). Builds the default stone sphere
# with its standard 1280-triangle mesh (the baseline) and with a 20480-triangle
# icosphere (--mesh-resolution 5), synthesises both the same way (best view
# only, to keep the bench short; the viewer's work does not depend on it), then
# times `texlume view` on both in headless Chromium (web/bench/viewer_bench.mjs).
# Usage: bench/viewer_bench.sh [BUILD_DIR (build)] [WORK_DIR (a temporary folder)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
texlume=$(realpath "${1:-$root/build}/apps/texlume")
work=${2:-$(mktemp -d)}
mkdir -p "$work"
for level in 0 5; do
  scene="$work/scene_$level"
  model="$work/model_$level"
  if [ ! -f "$model/manifest.json" ]; then
    echo "viewer_bench: building the model with --mesh-resolution $level in $model" >&2
    "$texlume" scene --out "$scene" --mesh-resolution "$level" --no-btf --held-out-views 0 > /dev/null
    capture="$scene/material/capture"
    "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$work/sample_$level.ptm" \
      --exr "$work/sample_$level.exr" > /dev/null
    object="$scene/object"
    "$texlume" synth --model "$object/sparse" --images "$object/images" \
      --lights "$object/lights.json" --mesh "$object/mesh.ply" --sample "$work/sample_$level.exr" \
      --sample-texel-size 0.002 --best-view-only --no-report --out "$model" > /dev/null
  fi
done
cd "$root/web"
TEXLUME="$texlume" node bench/viewer_bench.mjs "$work/model_0" "$work/model_5"
