#!/usr/bin/env bash
# Browser tests of `texlume view` and the glTF validator on a small synthetic
# model (web/test/viewer.test.mjs). Usage: viewer_test.sh TEXLUME_PROGRAM
set -euo pipefail
texlume=$(realpath "$1")
web=$(cd "$(dirname "$0")/../../web" && pwd)
if [ ! -d "$web/node_modules/playwright-core" ]; then
  echo "viewer_test: $web/node_modules is missing; run ./scripts/install_deps.sh" >&2
  exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$texlume" scene --out "$tmp/scene" --kind sphere --material stone --images 12 --width 320 \
  --height 240 --capture-size 128 --capture-lights 24 --held-out-lights 0 --held-out-views 1 \
  --texel-size 0.004 --relief 0.012 --no-btf > "$tmp/scene.log"
capture="$tmp/scene/material/capture"
# The sample with its horizon map: the model casts the relief's shadows, in the
# viewer as in texlume render (and the synthesis relights the sample with them).
"$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$tmp/sample.ptm" \
  --exr "$tmp/sample.exr" --horizon "$tmp/horizon.exr" > "$tmp/fit.log"
object="$tmp/scene/object"
"$texlume" synth --model "$object/sparse" --images "$object/images" --lights "$object/lights.json" \
  --mesh "$object/mesh.ply" --sample "$tmp/sample.exr" --sample-horizon "$tmp/horizon.exr" \
  --shadowed-synthesis --sample-texel-size 0.004 --atlas-size 1024 --out "$tmp/model" \
  > "$tmp/synth.log" 2>&1
cd "$web"
TEXLUME="$texlume" TEXLUME_MODEL="$tmp/model" TEXLUME_PHOTOS="$object" node --test test/
