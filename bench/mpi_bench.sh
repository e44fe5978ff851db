#!/usr/bin/env bash
# The main job across MPI ranks (issue 33): parallel efficiency here and a model of
# 8-64 ranks. A column of about FACES triangles photographed by IMAGES photos on RINGS
# rings of WIDTH x HEIGHT (as bench/monument_bench.sh), a CAPTURE^2 stone sample at TEXEL
# world units per texel; then the same synth command three ways, each rendered at the
# held-out views against the truth:
#   one_1t     one process, one thread (OMP_NUM_THREADS=1): the baseline of the efficiency;
#   ranks_Nt1  mpirun -np RANKS, one thread per rank;
#   one_Nt     one process, RANKS threads (the same cores used by OpenMP alone).
# The one-process runs measure their edge mismatch on the ranks' regions (--compare-regions
# RANKS; within their times, as the ranks' run measures its own), printed beside the ranks'.
# Efficiency = wall(one_1t) / (RANKS x wall(ranks)), for the synthesis stage (the
# manifests' timings) and the whole command. The model of N ranks takes the measured
# region work, imbalance, border faces, bytes sent and serial stages of the RANKS run (its
# row for RANKS ranks is checked against the measured wall time; docs/synth.md, "Across
# machines").
# Usage: bench/mpi_bench.sh [BUILD_DIR (build)] [WORK_DIR (temporary)] [FACES (20000)]
# Environment: RANKS (2), IMAGES (100), RINGS (3), WIDTH (320), HEIGHT (240), TEXEL (0.001),
# CAPTURE (256), BANDWIDTH (bytes/s between machines for the model, 1.25e9: 10 GbE).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$root/build}")
texlume="$build/apps/texlume"
work=${2:-$(mktemp -d)}
faces=${3:-20000}
ranks=${RANKS:-2} images=${IMAGES:-100} rings=${RINGS:-3} width=${WIDTH:-320}
height=${HEIGHT:-240} texel=${TEXEL:-0.001} capture_size=${CAPTURE:-256}
bandwidth=${BANDWIDTH:-1.25e9}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # CI machines run as root
dir="$work/column_${faces}_${images}_${rings}_${width}x${height}_t${texel}_c${capture_size}"
mkdir -p "$dir"

# measure NAME COMMAND...: runs COMMAND (output to NAME.log); wall and CPU seconds and
# the peak resident KiB of its largest process in NAME.json.
measure() {
  echo "mpi_bench: $1" >&2
  python3 "$root/bench/lib/measure.py" "$dir/$1" "${@:2}"
}

if [ ! -f "$dir/scene/scene.json" ]; then
  measure scene "$texlume" scene --out "$dir/scene" --kind cylinder --mesh-faces "$faces" \
    --images "$images" --camera-rings "$rings" --camera-distance 2 --focal 1200 \
    --width "$width" --height "$height" --texel-size "$texel" --capture-size "$capture_size" \
    --no-btf --held-out-views 2
fi
object="$dir/scene/object" held="$dir/scene/object/held_out"
capture="$dir/scene/material/capture"
[ -f "$dir/sample.ptm" ] ||
  measure fit "$texlume" fit --images "$capture" --lights "$capture/lights.lp" --out "$dir/sample.ptm"
synth=("$texlume" synth --model "$object/sparse" --images "$object/images"
  --lights "$object/lights.json" --mesh "$object/mesh.ply" --sample "$dir/sample.ptm"
  --sample-texel-size "$texel" --no-report)
run() {  # NAME THREADS [mpirun ARGS...]
  local name=$1 threads=$2
  shift 2
  # One process measures its edges on the regions the ranks place apart.
  local compare=()
  [ $# -gt 0 ] || compare=(--compare-regions "$ranks")
  rm -rf "$dir/$name" "$dir/render_$name"
  OMP_NUM_THREADS=$threads measure "$name" "$@" "${synth[@]}" "${compare[@]}" --out "$dir/$name"
  measure "render_$name" "$texlume" render --model "$dir/$name" --cameras "$held/sparse" \
    --lights "$held/lights.json" --truth "$held/images" --truth-masks "$held/masks" \
    --reduced-factor 4 --out "$dir/render_$name/out"
}
run one_1t 1
run "ranks_${ranks}t1" 1 mpirun --oversubscribe -np "$ranks"
run "one_${ranks}t" "$ranks"

python3 - "$dir" "$ranks" "$bandwidth" <<'PY'
import json, math, os, sys
d, n, bandwidth = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
job = lambda name: json.load(open(os.path.join(d, name + ".json")))
manifest = lambda name: json.load(open(os.path.join(d, name, "manifest.json")))
render = lambda name: json.load(open(os.path.join(d, "render_" + name, "out", "render.json")))["metrics"]
names = ["one_1t", f"ranks_{n}t1", f"one_{n}t"]
m1 = manifest(names[0])
faces = m1["summary"]["faces"]
print(f"Column of {faces} faces; synth three ways\n")
print("| run | wall s | CPU s | synthesis s | peak MiB | PSNR / SSIM | reduced 4x4 |")
print("|---|---|---|---|---|---|---|")
for name in names:
    j, m, r = job(name), manifest(name), render(name)
    print(f"| {name} | {j['wall_s']:.1f} | {j['cpu_s']:.1f} | {m['timings_s']['synthesis']:.1f} | "
          f"{j['peak_kib'] / 1024:.0f} | {r['mean_psnr_db']:.3f} / {r['mean_ssim']:.4f} | "
          f"{r['mean_psnr_reduced_db']:.3f} / {r['mean_ssim_reduced']:.4f} |")
mn = manifest(names[1])
dist = mn["distributed"]
wall1, walln = job(names[0])["wall_s"], job(names[1])["wall_s"]
syn1, synn = m1["timings_s"]["synthesis"], mn["timings_s"]["synthesis"]
print(f"\nefficiency at {n} ranks: synthesis {syn1 / (n * synn):.2f}, whole command "
      f"{wall1 / (n * walln):.2f} (speed-up {syn1 / synn:.2f} / {wall1 / walln:.2f})")
# The same edges in each run: the ranks' own, and one process's on the same regions
# (--compare-regions).
print(f"\nedge mismatch (mean +- standard error) on the regions of {n} ranks\n")
print("| edges | " + " | ".join(names) + " |")
print("|---|" + "---|" * len(names))
mismatch = [manifest(names[0])["region_comparison"][0]["edge_mismatch"],
            mn["distributed"]["edge_mismatch"],
            manifest(names[2])["region_comparison"][0]["edge_mismatch"]]
for edges in ("region_borders", "next_to_borders", "next_to_band", "elsewhere"):
    cells = [f"{m[edges]['mean']:.5f} +- {m[edges]['standard_error']:.5f}" for m in mismatch]
    print(f"| {edges.replace('_', ' ')} ({mismatch[1][edges]['edges']}) | " + " | ".join(cells) + " |")
print()
for r in dist["per_rank"]:
    print(f"rank {r['rank']}: {r['faces']} faces, placed {r['faces_placed']} in "
          f"{r['seconds_region']:.1f} s, detail transfer {r['seconds_finish']:.1f} s (prepare "
          f"{r['seconds_prepare']:.1f} s), sent {r['bytes_sent']} B")
print(f"rank 0: gather {dist['seconds_gather']:.2f} s, {dist['region_band_faces']} faces of the band along "
      f"the borders placed and finished in {dist['seconds_region_borders']:.1f} s")

# The model (docs/synth.md "Across machines") of this job on N ranks of one thread, from the
# measured parts of the RANKS run:
#   T(N) = every rank's (load + visibility + set-up and photometry)
#        + region work / N x imbalance          (placement and detail transfer, per face)
#        + gather: the other ranks' bytes / bandwidth (rank 0 receives them one after another)
#        + borders: t_border x beta sqrt(N F)    (border faces of N compact regions on a surface)
#        + rank 0's serial stages (atlases, baselines, writing).
t = mn["timings_s"]
work = [r["seconds_region"] + r["seconds_finish"] for r in dist["per_rank"]]
placed = sum(r["faces_placed"] for r in dist["per_rank"])
region_work = sum(work)
imbalance = max(work) / (region_work / n)
t_border = dist["seconds_region_borders"] / max(1, dist["region_band_faces"])
beta = dist["region_band_faces"] / math.sqrt(n * faces)
sent = [r for r in dist["per_rank"] if r["rank"] != 0]
volume = sum(r["bytes_sent"] for r in sent) / max(1, sum(r["faces_placed"] for r in sent)) * placed
prepare = dist["per_rank"][0]["seconds_prepare"]
every_rank = t["load"] + t["visibility"] + prepare
# Rank 0's wall time less what the model counts apart (its gather wait is the imbalance).
serial = (job(names[1])["wall_s"] - every_rank - work[0] - dist["seconds_gather"] -
          dist["seconds_region_borders"])
print(f"\nmodel inputs: region work {region_work:.1f} s ({1000 * region_work / placed:.2f} ms per "
      f"face), imbalance {imbalance:.2f}, {1000 * t_border:.2f} ms per border face, beta {beta:.2f}, "
      f"volume {volume / 2**20:.0f} MiB, every rank {every_rank:.1f} s, rank 0 serial {serial:.1f} s, "
      f"{bandwidth:.3g} B/s")
print("\n| ranks | region work s | gather s | borders s | every rank s | serial s | T s | "
      "speed-up | efficiency |")
print("|---|---|---|---|---|---|---|---|---|")
one = every_rank + region_work + serial
for ranks in (1, n, 8, 16, 32, 64):
    compute = region_work / ranks * (imbalance if ranks > 1 else 1.0)
    gather = volume * (ranks - 1) / ranks / bandwidth if ranks > 1 else 0.0
    borders = t_border * beta * math.sqrt(ranks * faces) if ranks > 1 else 0.0
    total = compute + gather + borders + every_rank + serial
    label = f"{ranks} (measured {walln:.0f})" if ranks == n else str(ranks)
    print(f"| {label} | {compute:.1f} | {gather:.2f} | {borders:.1f} | {every_rank:.1f} | "
          f"{serial:.1f} | {total:.1f} | {one / total:.2f} | {one / (ranks * total):.2f} |")
PY
