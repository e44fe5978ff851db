#!/usr/bin/env bash
# Builds texlume's libFuzzer targets (clang, every library with AddressSanitizer and UBSan)
# in build-fuzz/, writes their seed corpora, replays every input in fuzz/regressions/<target>/
# and then fuzzes each target (docs/robustness.md, "Fuzzing").
#   scripts/fuzz.sh [--seconds N | --runs N] [target ...]
# --seconds N  fuzz each target for N seconds (default 60)
# --runs N     fuzz each target for N executions instead
# New findings are written to fuzz/regressions/<target>/; the script then exits 1.
# TEXLUME_FUZZ_OPT=-O0 builds faster and fuzzes slower (the test command's smoke run).
# Prints a table: target, executions, findings.
set -euo pipefail
cd "$(dirname "$0")/.."
limit="-max_total_time=60"
targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) limit="-max_total_time=$2"; shift 2 ;;
    --runs) limit="-runs=$2"; shift 2 ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
all=(cameras_bin images_bin points3d_bin cameras_txt images_txt points3d_txt lp object_lights
     ptm ptm_exr ply obj off stl btf_json manifest_json)
[[ ${#targets[@]} -eq 0 ]] && targets=("${all[@]}")

build=build-fuzz
# Seeds come from the normal build's fuzz_make_seeds (scripts/build.sh makes it).
seeds_program=build/fuzz/fuzz_make_seeds
[[ -x "$seeds_program" ]] || ./scripts/build.sh --target fuzz_make_seeds
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="${TEXLUME_FUZZ_OPT:--O1} -gline-tables-only -DNDEBUG" \
  -DTEXLUME_FUZZ=ON -DTEXLUME_BUILD_TESTS=OFF -DTEXLUME_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build "$build" --target fuzz_all -j"$(nproc)"
rm -rf "$build/seeds"
"$seeds_program" "$build/seeds" > /dev/null

export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
printf '| target | executions | findings |\n| --- | --- | --- |\n' | tee "$build/fuzz_summary.md"
for t in "${targets[@]}"; do
  exe="$build/fuzz/fuzz_$t"
  regressions="fuzz/regressions/$t"
  corpus="$build/corpus/$t"
  mkdir -p "$regressions" "$corpus"
  cp -n "$build/seeds/$t"/* "$corpus/" 2>/dev/null || true
  # Every earlier finding must now be refused cleanly.
  mapfile -t kept < <(find "$regressions" -type f ! -name '*.md' | sort)
  if [[ ${#kept[@]} -gt 0 ]] && ! "$exe" -rss_limit_mb=4096 "${kept[@]}" > "$build/replay_$t.log" 2>&1; then
    echo "fuzz: $t: a kept regression input fails again (see $build/replay_$t.log)" >&2
    status=1
  fi
  before=$(find "$regressions" -type f | wc -l)
  log="$build/fuzz_$t.log"
  "$exe" "$limit" -rss_limit_mb=4096 -timeout=10 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$regressions/" "$corpus" > "$log" 2>&1 || true
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  findings=$(( $(find "$regressions" -type f | wc -l) - before ))
  printf '| %s | %s | %s |\n' "$t" "$runs" "$findings" | tee -a "$build/fuzz_summary.md"
  if [[ $findings -gt 0 ]]; then
    echo "fuzz: $t: $findings new finding(s) in $regressions (see $log)" >&2
    status=1
  fi
done
exit $status
