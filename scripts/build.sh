#!/usr/bin/env bash
# Configures and builds texlume in build/ (Release). Extra arguments go to the
# build step, e.g. `scripts/build.sh --target texlume`.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release ${TEXLUME_CMAKE_ARGS:-}
cmake --build build -j"$(nproc)" "$@"
