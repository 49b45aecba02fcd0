#!/bin/sh
# Everything CI checks: build once, then run every test suite.
set -eu
cd "$(dirname "$0")/.."
sh scripts/build.sh
sh scripts/models.sh
ctest --test-dir build --output-on-failure -j"$(nproc)"
