#!/usr/bin/env bash
# The whole job at monument scale (issue 33): a column of about FACES triangles
# (texlume scene --kind cylinder --mesh-faces FACES) photographed by IMAGES close
# photos on RINGS rings (--camera-rings, --camera-distance 2, --focal 1200) of
# WIDTH x HEIGHT pixels, a CAPTURE x CAPTURE stone sample at TEXEL world units per
# texel; then fit, synth (the main job, defaults) and render at the held-out views
# against the truth. Each job runs in its own process, measured by its parent:
# wall and CPU seconds and peak resident memory. The synth job's own stages are its
# progress stages (wall seconds, from its log). The last lines give the synthesis CPU per
# triangle and the held-out PSNR / SSIM.
# Usage: bench/monument_bench.sh [BUILD_DIR (build)] [WORK_DIR (temporary)] [FACES (100000)]
# Environment: IMAGES (200), RINGS (5), WIDTH (320), HEIGHT (240), TEXEL (0.001), CAPTURE (256);
# SYNTH_ARGS: more options for texlume synth (e.g. --memory-limit 22G).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$root/build}")
texlume="$build/apps/texlume"
work=${2:-$(mktemp -d)}
faces=${3:-100000}
images=${IMAGES:-200} rings=${RINGS:-5} width=${WIDTH:-320} height=${HEIGHT:-240}
texel=${TEXEL:-0.001} capture_size=${CAPTURE:-256}
mkdir -p "$work"
# One folder per scene: every setting the scene is made from is in its name.
dir="$work/column_${faces}_${images}_${rings}_${width}x${height}_t${texel}_c${capture_size}"

# measure NAME COMMAND...: runs COMMAND (its output to NAME.log), records its wall and
# CPU seconds and peak resident KiB in NAME.json.
measure() {
  echo "monument_bench: $1" >&2
  python3 "$root/bench/lib/measure.py" "$dir/$1" "${@:2}"
}

mkdir -p "$dir"
if [ ! -f "$dir/scene/scene.json" ]; then
  measure scene "$texlume" scene --out "$dir/scene" --kind cylinder --mesh-faces "$faces" \
    --images "$images" --camera-rings "$rings" --camera-distance 2 --focal 1200 \
    --width "$width" --height "$height" --texel-size "$texel" --capture-size "$capture_size" \
    --no-btf --held-out-views 2
fi
scene="$dir/scene" capture="$dir/scene/material/capture" held="$dir/scene/object/held_out"
object="$dir/scene/object"
rm -rf "$dir/sample.ptm" "$dir/model" "$dir/render"
measure fit "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$dir/sample.ptm"
measure synth "$texlume" synth --model "$object/sparse" --images "$object/images" \
  --lights "$object/lights.json" --mesh "$object/mesh.ply" --sample "$dir/sample.ptm" \
  --sample-texel-size "$texel" --no-report --out "$dir/model" ${SYNTH_ARGS:-}
measure render "$texlume" render --model "$dir/model" --cameras "$held/sparse" \
  --lights "$held/lights.json" --truth "$held/images" --truth-masks "$held/masks" \
  --out "$dir/render"

python3 - "$dir" <<'PY'
import json, os, re, sys
d = sys.argv[1]
job = lambda name: json.load(open(os.path.join(d, name + ".json")))
m = json.load(open(os.path.join(d, "model", "manifest.json")))
s = json.load(open(os.path.join(d, "scene", "scene.json")))
r = json.load(open(os.path.join(d, "render", "render.json")))["metrics"]
faces, photos = m["summary"]["faces"], len(s["photos"])
print(f"Column of {faces} faces, {photos} photos of {s['camera']['width']} x "
      f"{s['camera']['height']} on {s['camera']['rings']} rings\n")
print("| stage | wall s | CPU s | peak resident MiB |\n|---|---|---|---|")
for name in ("scene", "fit", "synth", "render"):
    if not os.path.exists(os.path.join(d, name + ".json")):
        continue  # the scene was made by an earlier run
    j = job(name)
    print(f"| {name} | {j['wall_s']:.1f} | {j['cpu_s']:.1f} | {j['peak_kib'] / 1024:.0f} |")
    if name == "synth":
        # Its stages as its progress reported them ("stage: n/n (100%), S s elapsed").
        for line in open(os.path.join(d, "synth.log")):
            hit = re.match(r"(.+): (\d+)/(\d+) \(100%\), ([\d.]+) s elapsed", line.strip())
            if hit:
                print(f"| synth: {hit.group(1)} | {float(hit.group(4)):.1f} | | |")
print(f"\nsynth: {1000 * job('synth')['cpu_s'] / faces:.2f} CPU ms per triangle, peak "
      f"{m['resources']['peak_resident_bytes'] / 2**20:.0f} MiB (manifest)")
print(f"held-out PSNR / SSIM: {r['mean_psnr_db']:.2f} / {r['mean_ssim']:.3f}")
PY
