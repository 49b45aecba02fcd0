#!/bin/sh
# Builds everything: the native library, CLI (build/kdmesh) and tests, and
# the WebAssembly decoder (web/dist/), installing missing packages first.
set -eu
cd "$(dirname "$0")/.."
sh scripts/setup.sh
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build build -j"$(nproc)"
sh scripts/build-wasm.sh
