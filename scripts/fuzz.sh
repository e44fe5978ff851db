#!/usr/bin/env bash
# Builds texlume's libFuzzer targets (clang, every library with AddressSanitizer and UBSan)
# in build-sanitize/ (scripts/lib/sanitizer_build.sh), writes their seed corpora, replays
# every input in fuzz/regressions/<target>/ and then fuzzes each target
# (docs/robustness.md, "Fuzzing").
#   scripts/fuzz.sh [--seconds N | --runs N] [--max-len N] [--jobs N] [target ...]
# --seconds N  fuzz each target for N seconds (default 60)
# --runs N     fuzz each target for N executions instead
# --max-len N  the longest input tried, in bytes (default 65536)
# --jobs N     fuzz N targets at a time (default 1)
# New findings are written to fuzz/regressions/<target>/; the script then exits 1.
# TEXLUME_SANITIZE_OPT=-O0 builds faster and fuzzes slower.
# Prints a table: target, executions, findings.
set -euo pipefail
cd "$(dirname "$0")/.."
limit="-max_total_time=60"
max_len=65536
parallel=1
targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) limit="-max_total_time=$2"; shift 2 ;;
    --runs) limit="-runs=$2"; shift 2 ;;
    --max-len) max_len="$2"; shift 2 ;;
    --jobs) parallel="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
all=(cameras_bin images_bin points3d_bin cameras_txt images_txt points3d_txt lp object_lights
     ptm ptm_exr ply obj off stl btf_json manifest_json)
[[ ${#targets[@]} -eq 0 ]] && targets=("${all[@]}")

source scripts/lib/sanitizer_build.sh
build="$sanitizer_build"
# Seeds come from the normal build's fuzz_make_seeds (scripts/build.sh makes it).
seeds_program=build/fuzz/fuzz_make_seeds
[[ -x "$seeds_program" ]] || ./scripts/build.sh --target fuzz_make_seeds
configure_sanitizer_build
cmake --build "$build" --target fuzz_all -j"$(nproc)"
rm -rf "$build/seeds"
"$seeds_program" "$build/seeds" > /dev/null

# Replays the kept findings of one target, fuzzes it, and writes its table row to
# $build/row_<target> and 1 (a finding) or 0 to $build/status_<target>.
fuzz_target() {
  local t="$1" failed=0
  local exe="$build/fuzz/fuzz_$t" regressions="fuzz/regressions/$t" corpus="$build/corpus/$t"
  mkdir -p "$regressions" "$corpus"
  cp -n "$build/seeds/$t"/* "$corpus/" 2>/dev/null || true
  # Every earlier finding must now be refused cleanly.
  local kept
  mapfile -t kept < <(find "$regressions" -type f ! -name '*.md' | sort)
  if [[ ${#kept[@]} -gt 0 ]] && ! "$exe" -rss_limit_mb=4096 -malloc_limit_mb=512 "${kept[@]}" > "$build/replay_$t.log" 2>&1; then
    echo "fuzz: $t: a kept regression input fails again (see $build/replay_$t.log)" >&2
    failed=1
  fi
  local before log="$build/fuzz_$t.log"
  before=$(find "$regressions" -type f | wc -l)
  # A single allocation over 512 MiB is a finding: the targets run under a 4 MiB
  # memory limit (fuzz_target.cpp), so only an unchecked size from the input asks for it.
  "$exe" "$limit" -rss_limit_mb=4096 -malloc_limit_mb=512 -timeout=10 -max_len="$max_len" \
    -print_final_stats=1 \
    -artifact_prefix="$regressions/" "$corpus" > "$log" 2>&1 || true
  local runs findings
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  findings=$(( $(find "$regressions" -type f | wc -l) - before ))
  printf '| %s | %s | %s |\n' "$t" "$runs" "$findings" > "$build/row_$t"
  echo "fuzz: $t: $runs executions, $findings new finding(s)"
  if [[ $findings -gt 0 ]]; then
    echo "fuzz: $t: $findings new finding(s) in $regressions (see $log)" >&2
    failed=1
  fi
  echo "$failed" > "$build/status_$t"
}

for t in "${targets[@]}"; do
  rm -f "$build/row_$t" "$build/status_$t"
  while [[ $(jobs -rp | wc -l) -ge $parallel ]]; do wait -n || true; done
  fuzz_target "$t" &
done
wait
status=0
printf '| target | executions | findings |\n| --- | --- | --- |\n' > "$build/fuzz_summary.md"
for t in "${targets[@]}"; do
  cat "$build/row_$t" >> "$build/fuzz_summary.md"
  [[ "$(cat "$build/status_$t")" == 0 ]] || status=1
done
cat "$build/fuzz_summary.md"
exit $status
