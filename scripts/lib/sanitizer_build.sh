# Sourced by scripts/fuzz.sh and scripts/sanitize_tests.sh: configures build-sanitize/,
# the build they share (clang; every library compiled with AddressSanitizer and UBSan, the
# ones the fuzz targets run also with libFuzzer's coverage; -DTEXLUME_FUZZ=ON), so that each
# builds only what it runs.
# TEXLUME_SANITIZE_OPT sets its optimisation (default -O1). A unity build, as the test
# command's Release build (in CI 198 s against 322 s compiling each source alone);
# TEXLUME_SANITIZE_UNITY=OFF compiles each source alone, as the default build does.
sanitizer_build=build-sanitize
configure_sanitizer_build() {
  CC=clang CXX=clang++ cmake -S . -B "$sanitizer_build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_FLAGS_RELEASE="${TEXLUME_SANITIZE_OPT:--O1} -gline-tables-only -DNDEBUG" \
    -DTEXLUME_FUZZ=ON -DTEXLUME_UNITY_BUILD="${TEXLUME_SANITIZE_UNITY:-ON}" \
    -DTEXLUME_BUILD_TESTS=ON -DTEXLUME_BUILD_BENCHMARKS=OFF > /dev/null
}
# Findings stop the run; leaks are findings too, but for the third-party ones listed. The
# exact unwinder records allocations through libraries built without frame pointers, so
# that the listed leaks are recognised by their library.
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0:fast_unwind_on_malloc=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/scripts/lib/lsan_suppressions.txt"
