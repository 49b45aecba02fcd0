#!/bin/sh
# The main job: build, encode the default model (the Stanford dragon) and
# print what the stream holds.
set -eu
cd "$(dirname "$0")/.."
sh scripts/build.sh
sh scripts/models.sh
model=build/models/dragon_vrip.ply
mkdir -p out
./build/kdmesh encode "$model" -o out/dragon.kdm --bits 12
./build/kdmesh info out/dragon.kdm
