#!/bin/sh
# Builds the native library, CLI (build/kdmesh) and tests, installing missing
# system packages first.
set -eu
cd "$(dirname "$0")/.."
sh scripts/setup.sh
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build build -j"$(nproc)"
