#!/usr/bin/env bash
# Fidelity on captures the pipeline was not tuned to (issue 29). For each shape
# (sphere and cylinder by default) it writes the realistic scene `texlume scene`
# makes by default (sensor noise, JPEG, vignetting, white balance, exposure,
# specular lobe with sheen, one bounce of interreflection, light directions 2
# degrees off), and "another instance": the same scene with another seed of the
# material, which is the best unconstrained synthesis can reach. It builds the
# PTM model from the scene's RTI capture, renders the held-out views at twice
# the photos' resolution, and prints for texlume, flat, baked and the other
# instance: PSNR and SSIM at full and at the photos' resolution, the luma bias,
# the chroma spread against the truth, the gradient-histogram distance and the
# radially averaged power spectrum difference (bench/view_fidelity).
# With CLEAN=1 the scenes are today's clean ones (texlume scene --clean).
# Usage: bench/fidelity_bench.sh [BUILD_DIR (build)] [WORK_DIR (temporary)] [SHAPES (sphere cylinder)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$root/build}")
texlume="$build/apps/texlume"
view_fidelity="$build/bench/view_fidelity"
work=${2:-$(mktemp -d)}
shapes=${3:-sphere cylinder}
clean=()
if [ "${CLEAN:-0}" = 1 ]; then clean=(--clean); fi
mkdir -p "$work"
for shape in $shapes; do
  dir="$work/$shape"
  mkdir -p "$dir"
  for instance in scene other; do
    seed=()
    if [ "$instance" = other ]; then seed=(--material-seed 1001); fi
    if [ ! -f "$dir/$instance/scene.json" ]; then
      echo "fidelity_bench: $shape $instance ${clean[*]}" >&2
      "$texlume" scene --out "$dir/$instance" --kind "$shape" --held-out-scale 2 --no-btf \
        "${clean[@]}" "${seed[@]}" > /dev/null
    fi
  done
  object="$dir/scene/object"
  capture="$dir/scene/material/capture"
  held="$object/held_out"
  "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$dir/sample.ptm" \
    > /dev/null
  rm -rf "$dir/model"
  start=$SECONDS
  "$texlume" synth --model "$object/sparse" --images "$object/images" \
    --lights "$object/lights.json" --mesh "$object/mesh.ply" --no-report \
    --sample "$dir/sample.ptm" --sample-texel-size 0.002 --out "$dir/model" > /dev/null
  synth_s=$((SECONDS - start))
  for mode in texlume flat baked; do
    baseline=()
    if [ "$mode" != texlume ]; then baseline=(--baseline "$mode"); fi
    rm -rf "$dir/render_$mode"
    "$texlume" render --model "$dir/model" --cameras "$held/sparse" --lights "$held/lights.json" \
      --out "$dir/render_$mode" "${baseline[@]}" > /dev/null
  done
  echo
  echo "### $shape${clean:+ (clean)}: held-out views x lights at 2x the photos' resolution (synth ${synth_s} s)"
  "$view_fidelity" "$held/images" "$held/masks" 2 texlume="$dir/render_texlume" \
    flat="$dir/render_flat" baked="$dir/render_baked" \
    another_instance="$dir/other/object/held_out/images"
done
