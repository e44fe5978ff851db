#!/usr/bin/env bash
# Checks (or with --fix, applies) clang-format on every tracked C++ source.
# Usage: scripts/check_format.sh [clang-format-binary] [--fix]
set -euo pipefail
cd "$(dirname "$0")/.."
CLANG_FORMAT=${1:-clang-format}
mapfile -t files < <(git ls-files '*.h' '*.cpp')
if [ "${2:-}" = "--fix" ]; then
  "$CLANG_FORMAT" -i "${files[@]}"
else
  "$CLANG_FORMAT" --dry-run --Werror "${files[@]}"
  echo "check-format: ${#files[@]} files formatted correctly"
fi
