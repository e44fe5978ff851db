#!/usr/bin/env bash
# Installs every build, test and demo dependency of texlume on Debian 12 (bookworm).
# Idempotent: packages already present are left alone. Run as root (or with sudo available).
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git clang-format
  lld  # links the programs and tests in a fifth of GNU ld's time (Apache-2.0 with LLVM exception)
  # libraries (see DESIGN.md, "Modules")
  libeigen3-dev libopenmesh-dev libopencv-dev libceres-dev libopenimageio-dev
  nlohmann-json3-dev libembree-dev
  libcli11-dev  # the command line (BSD)
  libnanoflann-dev  # detail transfer's nearest windows (BSD, header-only)
  libcpp-httplib-dev  # the viewer's local HTTP server (MIT)
  zlib1g-dev  # CRC-32 checksums of the inputs in reports (zlib licence)
  libmetis-dev  # the face graph's partition into regions, one per rank (Apache-2.0)
  libopenmpi-dev openmpi-bin  # synth across machines: mpirun -np N texlume synth (BSD)
  openimageio-tools  # its CMake package config refers to the OIIO tools
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # the fuzz targets: clang's libFuzzer, AddressSanitizer and UBSan (scripts/fuzz.sh)
  clang libclang-rt-14-dev
  # the real COLMAP program, used by the cross-check tests
  colmap
  # the browser tests of the viewer (driven by playwright-core from npm)
  chromium
)
# Node.js and npm install the viewer's packages (web/package-lock.json); the
# machine's own are used when present.
if ! command -v npm > /dev/null; then PACKAGES+=(nodejs npm); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages already installed"
else
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "install_deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The viewer's web packages (three.js and esbuild to bundle it; playwright-core
# and gltf-validator for the tests), exactly as pinned in web/package-lock.json.
web="$(cd "$(dirname "$0")/../web" && pwd)"
if [ ! -f "$web/node_modules/.package-lock.json" ] ||
   [ "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]; then
  echo "install_deps: npm ci in $web"
  (cd "$web" && npm ci --no-audit --no-fund)
else
  echo "install_deps: web packages already installed"
fi
# The viewer's page loads one bundle: web/viewer/viewer.js with the parts of
# three.js it uses (and web/viewer/colmap_camera.js), minified by esbuild
# (web/dist/viewer.js), rebuilt when a file of web/viewer is newer.
if [ ! -f "$web/dist/viewer.js" ] ||
   [ -n "$(find "$web/viewer" -name '*.js' -newer "$web/dist/viewer.js")" ] ||
   [ "$web/package-lock.json" -nt "$web/dist/viewer.js" ]; then
  echo "install_deps: npm run build in $web"
  (cd "$web" && npm run build --silent)
fi
