#!/bin/sh
# Regenerates the decoder fuzzer's seed streams, tests/fuzz/seeds/decoder/,
# by encoding the reader seeds (tests/fuzz/seeds/) with build/kdmesh, one
# stream per coding path: connectivity of every dimension on a grid and in
# float32 mode, connectivity coded for fast decoding (with edge expansions
# coded by their fan's cuts), exact attributes, quantized and geometric octahedral
# attributes with labels, octahedral normals of a point cloud, a label table, infinite and NaN coordinates, and float64
# coordinates with their residual attributes. Run it after a
# format change; the test FuzzSeeds.DecoderSeedsDecodeAndCoverEveryTable
# fails until the streams are current.
#
#   sh scripts/fuzz-seeds.sh [path/to/kdmesh]
set -eu
cd "$(dirname "$0")/.."
cli=${1:-build/kdmesh}
in=tests/fuzz/seeds
out=tests/fuzz/seeds/decoder
mkdir -p "$out"
"$cli" encode "$in/mixed.obj" -o "$out/mixed.kdm" --exact -q
"$cli" encode "$in/tetrahedra.mesh" -o "$out/tetrahedra.kdm" --bits 6 -q
"$cli" encode "$in/mixed.obj" -o "$out/fast-decode.kdm" --bits 10 --fast-decode -q
"$cli" encode "$in/surface.ply" -o "$out/fast-decode-surface.kdm" --bits 10 --fast-decode -q
"$cli" encode "$in/colours.ply" -o "$out/attributes.kdm" --exact -q
"$cli" encode "$in/regions.mesh" -o "$out/labels.kdm" --exact -q
"$cli" encode "$in/surface.ply" -o "$out/quantized.kdm" --bits 10 --attr-bits 12 --normal-bits 8 -q
"$cli" encode "$in/oriented.ply" -o "$out/normals.kdm" --bits 8 --normal-bits 6 -q
"$cli" encode "$in/nonfinite.xyz" -o "$out/nonfinite.kdm" --exact -q
"$cli" encode "$in/doubles.ply" -o "$out/float64.kdm" --exact -q
