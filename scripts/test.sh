#!/usr/bin/env bash
# Installs the dependencies, builds texlume with warnings as errors, checks the
# formatting and runs the whole test suite (unit tests, COLMAP cross-checks,
# end-to-end CLI tests), then the unit suites again under AddressSanitizer + UBSan
# (scripts/sanitize_tests.sh) and the fuzz smoke run: every
# libFuzzer target for 1 s after replaying every kept finding (scripts/fuzz.sh), both in
# build-sanitize/ (docs/robustness.md).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh
TEXLUME_CMAKE_ARGS="-DTEXLUME_WERROR=ON -DTEXLUME_UNITY_BUILD=ON" ./scripts/build.sh
cmake --build build --target check-format
ctest --test-dir build -j"$(nproc)" --output-on-failure
# Both in build-sanitize/, at -O0: a shorter build, and neither needs speed.
export TEXLUME_SANITIZE_OPT=-O0
./scripts/sanitize_tests.sh
./scripts/fuzz.sh --seconds 1 --jobs "$(nproc)"
