#!/usr/bin/env bash
# Installs the dependencies, builds texlume and runs its demo into texlume_demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh
./scripts/build.sh --target texlume
./build/apps/texlume demo --out out
echo
echo "Demo outputs are in $(pwd)/out: open out/report.html (run.json records settings and timings)."
