#!/bin/sh
# The GoogleTest suite built and run with ASan and UBSan (build-asan/).
set -eu
cd "$(dirname "$0")/.."
if [ ! -f build-asan/CMakeCache.txt ]; then
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKDMESH_SANITIZE=address,undefined >/dev/null
fi
cmake --build build-asan -j"$(nproc)"
ln -sfn ../build/models build-asan/models
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure -j"$(nproc)"
