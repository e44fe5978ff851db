#!/usr/bin/env bash
# COLMAP's own SfM (CPU) on generated object photo sets of every shape, each with a
# material: how many photos it registers and how well its cameras align to the
# ground truth. Takes a few minutes. Usage: bench/colmap_sfm_check.sh [WORKDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-/tmp/texlume_sfm_check}
export QT_QPA_PLATFORM=offscreen
for combo in "sphere stone" "cylinder brick" "plane grooves" "torus grooves" "torus stone"; do
  set -- $combo
  dir="$work/$1_$2"
  rm -rf "$dir" && mkdir -p "$dir/sparse"
  build/apps/texlume scene --kind "$1" --material "$2" --out "$dir/scene" --no-btf \
    --capture-size 32 --capture-lights 6 --held-out-lights 0 --held-out-views 0 > "$dir/scene.log" 2>&1
  colmap feature_extractor --database_path "$dir/db.db" --image_path "$dir/scene/object/images" \
    --SiftExtraction.use_gpu 0 --ImageReader.single_camera 1 --ImageReader.camera_model PINHOLE \
    > "$dir/colmap.log" 2>&1
  colmap exhaustive_matcher --database_path "$dir/db.db" --SiftMatching.use_gpu 0 >> "$dir/colmap.log" 2>&1
  colmap mapper --database_path "$dir/db.db" --image_path "$dir/scene/object/images" \
    --output_path "$dir/sparse" >> "$dir/colmap.log" 2>&1 || true
  best=""
  for model in "$dir"/sparse/*/; do
    [ -d "$model" ] || continue
    line=$(build/bench/sfm_alignment "$dir/scene/object/sparse" "$model" 2>&1 || true)
    best="$best $line;"
  done
  echo "$1 $2:${best:- no model}"
done
