#!/bin/sh
# Learns the starting probabilities of kdmesh's adaptive models from meshes
# of CGAL's demo data that are not in the benchmark tables (no triceratops,
# fandisk or bunny), and rewrites native/src/model_priors.inc. The priors are
# part of the stream format: bump kFormatVersion when they change.
#
#   sh scripts/train-priors.sh [--only NAMES]
#
# Learning starts from the priors compiled in; --only retrains the named
# arrays of model_priors.inc (comma-separated) and keeps the others.
set -eu
cd "$(dirname "$0")/.."
sh scripts/build.sh >/dev/null
cgal=/usr/share/doc/libcgal-dev/data.tar.gz
dir=build/training
mkdir -p "$dir"
meshes=""
for name in elephant camel cow bull dino elk couplingdown armadillo ChineseDragon-10kv blade mushroom man hand; do
  [ -f "$dir/$name.off" ] || tar -xzf "$cgal" -O "data/meshes/$name.off" > "$dir/$name.off"
  meshes="$meshes $dir/$name.off"
done
# shellcheck disable=SC2086
./build/kdmesh_train_priors "$@" native/src/model_priors.inc $meshes
echo "wrote native/src/model_priors.inc; rebuild to use it"
