#!/bin/sh
# The main job: build, encode the default model (the Stanford dragon) and
# print what the stream holds. Until connectivity coding lands, the dragon's
# vertices are encoded as a point cloud.
set -eu
cd "$(dirname "$0")/.."
sh scripts/build.sh
model=$(sh scripts/models.sh)
mkdir -p out
./build/kdmesh encode "$model" -o out/dragon.kdm --bits 12 --points-only
./build/kdmesh info out/dragon.kdm
