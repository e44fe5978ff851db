#!/usr/bin/env bash
# Builds every unit suite and the libraries they link with clang, AddressSanitizer and UBSan
# in build-sanitize/, and runs them, each test but those listed in tests/sanitizer_skip.txt
# (docs/robustness.md, "Sanitizers"). Extra arguments go to ctest, e.g. `-R ptm`.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/sanitizer_build.sh
configure_sanitizer_build
cmake --build "$sanitizer_build" --target sanitized_tests -j"$(nproc)"
ctest --test-dir "$sanitizer_build" -L sanitize -j"$(nproc)" --output-on-failure "$@"
