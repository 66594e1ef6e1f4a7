#!/usr/bin/env bash
# Installs the Debian packages quadval needs (scripts/setup.sh), then configures and builds
# everything into ./build (library, `quadval`, tests, benchmarks).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > build.log 2>&1 || { cat build.log; exit 1; }
cmake --build build -j "$(nproc)" >> build.log 2>&1 || { tail -60 build.log; exit 1; }
echo "build: ok (log in build.log); the tool is build/quadval"
