#!/usr/bin/env bash
# Graph-cut quilting following the photos (issue 32, docs/quilting.md,
# "Following the photos"): on a stone sphere (12 photos of 320 x 240 from a
# ring, a 128 x 128 RTI capture and a 12-component BTF), builds
#   - the graph-cut model with the photos (paper 003's image term) and without,
#     for the PTM fitted to the capture and for the BTF,
#   - the per-triangle engine's model (paper 003, with its photo-consistency pass),
# renders the held-out views x lights of each and the flat baseline, and prints
# PSNR / SSIM against the ground truth (full resolution and reduced 4 x 4),
# the patches the photos placed and the quilting time.
# Usage: bench/quilt_photos_bench.sh [BUILD_DIR (build)] [WORK_DIR (a temporary folder)] [SEED (1)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
texlume=$(realpath "${1:-$root/build}/apps/texlume")
work=${2:-$(mktemp -d)}
seed=${3:-1}
mkdir -p "$work"
scene="$work/scene"
if [ ! -f "$scene/scene.json" ]; then
  echo "quilt_photos_bench: scene (seed $seed) in $scene" >&2
  "$texlume" scene --out "$scene" --seed "$seed" --images 12 --width 320 --height 240 \
    --capture-size 128 --held-out-views 2 --held-out-lights 4 > /dev/null
fi
object="$scene/object"
photos=(--model "$object/sparse" --images "$object/images" --lights "$object/lights.json")
capture="$scene/material/capture"
"$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$work/sample.ptm" > /dev/null
ptm=(--mesh "$object/mesh.ply" --sample "$work/sample.ptm" --sample-texel-size 0.002 --no-report)
btf=(--mesh "$object/mesh.ply" --btf "$scene/material/btf" --components 12
     --sample-texel-size 0.004 --no-report)
synth() {  # name arguments...
  local name=$1
  shift
  rm -rf "${work:?}/$name"
  echo "quilt_photos_bench: $name" >&2
  "$texlume" synth "$@" --out "$work/$name" > /dev/null
}
synth graphcut_photos --engine graphcut "${photos[@]}" "${ptm[@]}"
synth graphcut --engine graphcut "${ptm[@]}"
synth graphcut_btf_photos --engine graphcut "${photos[@]}" "${btf[@]}"
synth graphcut_btf --engine graphcut "${btf[@]}"
synth triangle "${photos[@]}" "${ptm[@]}"
held="$object/held_out"
render() {  # name model [extra arguments]
  local name=$1 model=$2
  shift 2
  rm -rf "$work/render_$name"
  "$texlume" render --model "$work/$model" --cameras "$held/sparse" --lights "$held/lights.json" \
    --truth "$held/images" --truth-masks "$held/masks" --reduced-factor 4 \
    --out "$work/render_$name" "$@" > /dev/null
}
for m in graphcut_photos graphcut graphcut_btf_photos graphcut_btf triangle; do render $m $m; done
render flat triangle --baseline flat
python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
print("Held-out views x lights inside the object masks: full resolution, and reduced 4 x 4.")
print("| model | PSNR (dB) | SSIM | reduced PSNR | reduced SSIM | patches (by photos) | quilting s |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for name in ["graphcut_photos", "graphcut", "graphcut_btf_photos", "graphcut_btf", "triangle", "flat"]:
    m = json.load(open(f"{work}/render_{name}/render.json"))["metrics"]
    patches = seconds = ""
    if name.startswith("graphcut"):
        manifest = json.load(open(f"{work}/{name}/manifest.json"))
        s = manifest["summary"]
        patches = f"{s['patches']} ({s['patches_placed_by_photos']})"
        seconds = f"{manifest['timings_s']['quilting']:.1f}"
    print(f"| {name} | {m['mean_psnr_db']:.2f} | {m['mean_ssim']:.3f} | "
          f"{m['mean_psnr_reduced_db']:.2f} | {m['mean_ssim_reduced']:.3f} | {patches} | {seconds} |")
PY
