#!/usr/bin/env bash
# Installs the Debian packages quadval needs (scripts/setup.sh), then configures and builds
# into ./build: everything (library, `quadval`, tests, benchmarks), or only the CMake targets
# given as arguments (e.g. `bash scripts/build.sh quadval-cli` for the tool alone).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > build.log 2>&1 || { cat build.log; exit 1; }
targets=()
for t in "$@"; do targets+=(--target "$t"); done
echo "build: compiling (a few minutes on 2 cores; log in build.log)"
cmake --build build -j "$(nproc)" "${targets[@]}" >> build.log 2>&1 || { tail -60 build.log; exit 1; }
echo "build: ok; the tool is build/quadval"
