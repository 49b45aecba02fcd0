#!/bin/sh
# Everything CI checks: build once, then run every test suite (GoogleTest
# through ctest, then the Node tests of the WebAssembly decoder, the type
# declarations, the viewer and loader in headless chromium, the packed
# npm package bundled by vite, esbuild, webpack and Rollup, and the dev
# server under hostile requests).
set -eu
cd "$(dirname "$0")/.."
sh scripts/build.sh
sh scripts/models.sh
ctest --test-dir build --output-on-failure -j"$(nproc)"
node --test tests/js/ tests/types/ tests/browser/ tests/consumer/ tests/server/
# The benchmark suite's smoke run: CI checks only that it runs.
sh bench/run.sh --quick > build/bench-quick.md
test -s build/bench-quick.md
# Robustness: the suite under ASan + UBSan, and a short fuzzing run.
sh scripts/sanitize.sh
sh scripts/fuzz.sh 25
