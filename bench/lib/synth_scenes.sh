# Sourced by bench/triangle_time_bench.sh and bench/synth_ab_bench.sh: the time
# benches' scenes and the synth command they time.
# - s512: the issue's stone sphere, a 512 x 512 RTI capture at 256 texels per world
#   unit, photos of 640 x 480 at about 200 px per world unit;
# - sphere: bench/fidelity_bench.sh's realistic sphere (256 x 256 capture at 500
#   texels per world unit, held-out views at twice the photos' resolution).

# The texlume scene options of scene $1 (into the array scene_args) and its sample's
# texel size in world units (into texel); exits 2 for an unknown scene.
synth_scene_settings() {
  case "$1" in
    s512) texel=0.00390625 scene_args=(--capture-size 512 --texel-size 0.00390625) ;;
    sphere) texel=0.002 scene_args=(--kind sphere --held-out-scale 2) ;;
    *) echo "$(basename "$0"): unknown scene $1 (s512 or sphere)" >&2; exit 2 ;;
  esac
}

# Times `TEXLUME synth` on scene folder DIR (its object and sample.ptm) at texel
# size TEXEL into model folder OUT, with any further synth options; prints
# "user system wall" seconds. The job's messages go to OUT.log, shown when it fails.
timed_synth() {
  local texlume=$1 dir=$2 texel=$3 out=$4
  shift 4
  local object="$dir/object" TIMEFORMAT="%U %S %R"
  if ! { time "$texlume" synth --model "$object/sparse" --images "$object/images" \
    --lights "$object/lights.json" --mesh "$object/mesh.ply" --no-report \
    --sample "$dir/sample.ptm" --sample-texel-size "$texel" --out "$out" "$@" \
    > "$out.log" 2>&1; } 2> "$out.time"; then
    echo "$(basename "$0"): texlume synth failed; its messages ($out.log):" >&2
    tail -20 "$out.log" >&2
    exit 1
  fi
  tail -1 "$out.time"
}
