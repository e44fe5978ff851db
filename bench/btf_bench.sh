#!/usr/bin/env bash
# BTF against PTM models (issue 8): on the default stone sphere made glossy
# (--specular, so the material changes with the view), builds
#   - the BTF model from the scene's BTF capture (texlume synth --btf),
#   - the PTM model from the RTI capture of the same material, with and without
#     the PTM pipeline's photo-consistency pass,
#   - the BTF model of graph-cut quilting (texlume synth --engine graphcut --btf,
#     issue 32: the same capture over the mesh without photos),
# renders the held-out views (views and lights no photo has) of each, the BTF
# model's PTM preview and the two baselines, and prints PSNR / SSIM against the
# ground truth, the SVD error table and the time per triangle.
# Usage: bench/btf_bench.sh [BUILD_DIR (build)] [WORK_DIR (a temporary folder)] [SPECULAR (0.4)]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
texlume=$(realpath "${1:-$root/build}/apps/texlume")
work=${2:-$(mktemp -d)}
specular=${3:-0.4}
mkdir -p "$work"
scene="$work/scene"
if [ ! -f "$scene/scene.json" ]; then
  echo "btf_bench: scene (specular $specular, BTF 256 x 256, 13 views x 40 lights) in $scene" >&2
  "$texlume" scene --out "$scene" --specular "$specular" --btf-size 256 --btf-views 13 \
    --btf-lights 40 > /dev/null
fi
object="$scene/object"
inputs=(--model "$object/sparse" --images "$object/images" --lights "$object/lights.json"
        --mesh "$object/mesh.ply" --no-report)
capture="$scene/material/capture"
"$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$work/sample.ptm" > /dev/null
rm -rf "$work/btf" "$work/ptm" "$work/ptm_plain" "$work/btf_graphcut"
"$texlume" synth "${inputs[@]}" --btf "$scene/material/btf" --out "$work/btf" > /dev/null
"$texlume" synth --engine graphcut --mesh "$object/mesh.ply" --btf "$work/btf/btf" \
  --out "$work/btf_graphcut" > /dev/null
"$texlume" synth "${inputs[@]}" --sample "$work/sample.ptm" --sample-texel-size 0.002 \
  --out "$work/ptm" > /dev/null
"$texlume" synth "${inputs[@]}" --sample "$work/sample.ptm" --sample-texel-size 0.002 \
  --correction-iterations 0 --out "$work/ptm_plain" > /dev/null
held="$object/held_out"
render() {  # name model [extra arguments]
  local name=$1 model=$2
  shift 2
  rm -rf "$work/render_$name"
  "$texlume" render --model "$model" --cameras "$held/sparse" --lights "$held/lights.json" \
    --truth "$held/images" --truth-masks "$held/masks" --out "$work/render_$name" "$@" > /dev/null
}
render btf "$work/btf"
render btf_ptm_preview "$work/btf" --baseline ptm
render btf_graphcut "$work/btf_graphcut"
render ptm "$work/ptm"
render ptm_no_correction "$work/ptm_plain"
render flat "$work/btf" --baseline flat
render baked "$work/btf" --baseline baked
python3 - "$work" <<'EOF'
import json, sys
work = sys.argv[1]
print("Held-out views x lights, inside the object masks (12 images):")
print("| model | PSNR (dB) | SSIM | render time (s) |")
print("| --- | --- | --- | --- |")
for name in ["btf", "btf_ptm_preview", "btf_graphcut", "ptm", "ptm_no_correction", "flat", "baked"]:
    r = json.load(open(f"{work}/render_{name}/render.json"))
    m = r["metrics"]
    print(f"| {name} | {m['mean_psnr_db']:.2f} | {m['mean_ssim']:.3f} | {r['timings_s']['total']:.1f} |")
b = json.load(open(f"{work}/btf/manifest.json"))
p = json.load(open(f"{work}/ptm_plain/manifest.json"))
print()
print("| synthesis | per triangle (s) | seams (s) | seam cost per cut pair | straight edge |")
print("| --- | --- | --- | --- | --- |")
t = b["timings_s"]
s = b["summary"]
print(f"| BTF | {t['synthesis_per_triangle']:.4f} | {t['seams']:.2f} | "
      f"{s['seam_cost_per_link']:.3f} | {s['straight_edge_cost_per_link']:.3f} |")
g = json.load(open(f"{work}/btf_graphcut/manifest.json"))
print(f"| BTF, graph-cut quilting (no photos) | "
      f"{g['timings_s']['quilting'] / g['summary']['faces']:.4f} | | | |")
print(f"| PTM (no correction) | {p['timings_s']['synthesis_per_triangle']:.4f} | | | |")
svd = json.load(open(f"{work}/btf/btf/btf_svd.json"))
print()
print("| components | RMS error (linear) | relative |")
print("| --- | --- | --- |")
for e in svd["errors"]:
    print(f"| {e['components']} | {e['rms']:.5f} | {e['relative']:.4f} |")
EOF
