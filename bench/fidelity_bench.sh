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
# With CLEAN=1 the scenes are today's clean ones (texlume scene --clean); with
# COLMAP=1 it also builds the model from COLMAP's own cameras (a calibrated
# camera: the scene's intrinsics held fixed), moved into the mesh's frame.
# SCENE_ARGS adds options to both scenes (e.g. "--held-out-elevation 5,15" for
# grazing held-out lights). With ABLATIONS=1 it also builds the model without each
# of the main job's passes, one at a time (rows no_detail_transfer, shrink_0 and
# shrink_1: the photo-consistency prior centred on the quilted patch or on the
# sample's mean instead of the estimate, and no_correction). With BTF=1 the scenes
# also hold a BTF capture of the material (BTF_ARGS, by default 256 x 256 texels,
# 13 views x 40 lights) and a row "btf" renders the model `texlume synth --btf`
# builds from it: a model that keeps the capture's own images, shadows included.
# With HORIZON=1 the sample is also fitted with its horizon map (texlume fit
# --horizon) and a row "texlume_horizon" renders the model that casts the relief's
# own shadows (texlume synth --sample-horizon: the atlases' relief matched to the
# sample's shadows), and a row "texlume_horizon_gain1" the same model with the
# sample's own height scale (--atlas-relief-gain 1).
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
btf_capture=(--no-btf)
if [ "${BTF:-0}" = 1 ]; then
  read -r -a btf_capture <<< "${BTF_ARGS:---btf-size 256 --btf-views 13 --btf-lights 40}"
fi
mkdir -p "$work"
for shape in $shapes; do
  dir="$work/$shape"
  mkdir -p "$dir"
  for instance in scene other; do
    seed=()
    if [ "$instance" = other ]; then seed=(--material-seed 1001); fi
    if [ "${BTF:-0}" = 1 ] && [ ! -d "$dir/$instance/material/btf" ]; then
      rm -rf "${dir:?}/$instance"  # written without a BTF capture
    fi
    if [ ! -f "$dir/$instance/scene.json" ]; then
      echo "fidelity_bench: $shape $instance ${clean[*]} ${btf_capture[*]}" >&2
      "$texlume" scene --out "$dir/$instance" --kind "$shape" --held-out-scale 2 \
        "${btf_capture[@]}" "${clean[@]}" "${seed[@]}" ${SCENE_ARGS:-} > /dev/null
    fi
  done
  object="$dir/scene/object"
  capture="$dir/scene/material/capture"
  held="$object/held_out"
  "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$dir/sample.ptm" \
    > /dev/null
  render() {  # NAME MODEL_FOLDER [--baseline MODE]
    local name=$1 model=$2
    shift 2
    rm -rf "$dir/render_$name"
    "$texlume" render --model "$model" --cameras "$held/sparse" --lights "$held/lights.json" \
      --out "$dir/render_$name" "$@" > /dev/null
  }
  synth() {  # NAME COLMAP_MODEL [synth options: by default the PTM sample]
    local name=$1 cameras=$2
    shift 2
    local sample=(--sample "$dir/sample.ptm" --sample-texel-size 0.002)
    if [ "$#" -gt 0 ] && [ "$1" = --btf ]; then sample=(); fi
    if [ "$#" -gt 0 ] && [ "$1" = --horizon ]; then
      sample=(--sample "$dir/sample_lit.ptm" --sample-texel-size 0.002
        --sample-horizon "$dir/horizon.exr")
      shift
    fi
    rm -rf "$dir/model_$name"
    local start=$SECONDS
    "$texlume" synth --model "$cameras" --images "$object/images" \
      --lights "$object/lights.json" --mesh "$object/mesh.ply" --no-report \
      "${sample[@]}" --out "$dir/model_$name" "$@" > /dev/null
    echo "synth $name: $((SECONDS - start)) s" >&2
    render "$name" "$dir/model_$name"
  }
  synth texlume "$object/sparse"
  render flat "$dir/model_texlume" --baseline flat
  render baked "$dir/model_texlume" --baseline baked
  rows=(texlume="$dir/render_texlume")
  if [ "${COLMAP:-0}" = 1 ]; then
    # COLMAP's own cameras for a calibrated camera (intrinsics fixed to the scene's),
    # moved into the mesh's frame by the similarity of the camera centres.
    if [ ! -d "$dir/colmap_model" ]; then
      mkdir -p "$dir/colmap/sparse"
      params=$(awk '!/^#/ {print $5","$6","$7","$8; exit}' "$object/sparse_txt/cameras.txt")
      export QT_QPA_PLATFORM=offscreen
      colmap feature_extractor --database_path "$dir/colmap/db.db" --image_path "$object/images" \
        --SiftExtraction.use_gpu 0 --ImageReader.single_camera 1 \
        --ImageReader.camera_model PINHOLE --ImageReader.camera_params "$params" > "$dir/colmap/log" 2>&1
      colmap exhaustive_matcher --database_path "$dir/colmap/db.db" --SiftMatching.use_gpu 0 \
        >> "$dir/colmap/log" 2>&1
      if colmap mapper --database_path "$dir/colmap/db.db" --image_path "$object/images" \
        --output_path "$dir/colmap/sparse" --Mapper.ba_refine_focal_length 0 \
        --Mapper.ba_refine_principal_point 0 >> "$dir/colmap/log" 2>&1; then
        "$build/bench/sfm_alignment" "$object/sparse" "$dir/colmap/sparse/0" "$dir/colmap_model" >&2
      else
        echo "fidelity_bench: COLMAP made no model of the $shape photos ($dir/colmap/log):" \
          "no texlume_colmap row" >&2
      fi
    fi
    if [ -d "$dir/colmap_model" ]; then
      synth colmap "$dir/colmap_model"
      rows+=(texlume_colmap="$dir/render_colmap")
    fi
  fi
  if [ "${HORIZON:-0}" = 1 ]; then
    "$texlume" fit --images "$capture" --lights "$capture/lights.lp" \
      --out "$dir/sample_lit.ptm" --horizon "$dir/horizon.exr" > /dev/null
    synth horizon "$object/sparse" --horizon
    synth horizon_gain1 "$object/sparse" --horizon --atlas-relief-gain 1
    rows+=(texlume_horizon="$dir/render_horizon" texlume_horizon_gain1="$dir/render_horizon_gain1")
  fi
  if [ "${BTF:-0}" = 1 ]; then
    synth btf "$object/sparse" --btf "$dir/scene/material/btf"
    rows+=(btf="$dir/render_btf")
  fi
  if [ "${ABLATIONS:-0}" = 1 ]; then
    synth no_detail_transfer "$object/sparse" --no-detail-transfer
    synth shrink_0 "$object/sparse" --correction-prior-shrink 0
    synth shrink_1 "$object/sparse" --correction-prior-shrink 1
    synth no_correction "$object/sparse" --correction-iterations 0
    for name in no_detail_transfer shrink_0 shrink_1 no_correction; do
      rows+=("$name=$dir/render_$name")
    done
  fi
  echo
  echo "### $shape${clean:+ (clean)}: held-out views x lights at 2x the photos' resolution"
  "$view_fidelity" "$held/images" "$held/masks" 2 "${rows[@]}" flat="$dir/render_flat" \
    baked="$dir/render_baked" another_instance="$dir/other/object/held_out/images"
done
