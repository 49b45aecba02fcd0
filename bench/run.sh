#!/bin/sh
# Benchmark suite: kdmesh against Google Draco on the same models, same
# machine, same run. Prints Markdown tables (docs/BENCHMARKS.md is made of
# them).
#
#   sh bench/run.sh [--quick]     (npm run bench [-- --quick])
#
# --quick runs one model at one quantization with 3 timed runs (CI smoke).
set -eu
cd "$(dirname "$0")/.."

runs=7
quick=0
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1; runs=3 ;;
    *) echo "bench/run.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

sh scripts/setup.sh
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DKDMESH_BUILD_BENCH=ON \
  -DKDMESH_BUILD_TESTS=OFF >/dev/null
cmake --build build-bench -j"$(nproc)" >/dev/null

sh scripts/models.sh
dragon=build/models/dragon_vrip.ply
models="$dragon"
if [ -f ../shared/models/bunny.obj ]; then models="../shared/models/bunny.obj $models"; fi
bits="--bits 12 --bits 16"
if [ "$quick" = 1 ]; then
  models=${models%% *}
  bits="--bits 12"
fi

echo "## Point clouds: kdmesh vs Draco, in process (warm medians of $runs runs)"
echo
# shellcheck disable=SC2086
./build-bench/kdmesh_bench_points --runs "$runs" $bits $models
echo

echo "## Meshes: kdmesh vs Draco edgebreaker, in process (warm medians of $runs runs)"
echo
meshes="build/models/triceratops.off"
if [ "$quick" = 0 ]; then
  meshes="$meshes $(ls ../shared/models/bunny.obj 2>/dev/null || true) $dragon"
  ./build-bench/kdmesh_bench_mesh --runs "$runs" --bits 10 --bits 16 build/models/fandisk.off
  echo
fi
# shellcheck disable=SC2086
./build-bench/kdmesh_bench_mesh --runs "$runs" $bits $meshes
echo
if [ "$quick" = 0 ]; then
  echo "Peak memory of the command-line tools (12 bits; fandisk 10; the tetrahedral ball 16):"
  echo
  echo "| model | triangles + tetrahedra | encode s | encode peak KB | bytes/simplex | decode s | decode peak KB | bytes/simplex |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|"
  for spec in "build/models/triceratops.off:12" "build/models/fandisk.off:10" "../shared/models/bunny.obj:12" \
              "$dragon:12" "build/models/ball10k.1.ele:16" "build/models/fandisk-solid.1.ele:16"; do
    file=${spec%:*}; b=${spec##*:}
    [ -f "$file" ] || continue
    enc=$( { /usr/bin/time -f "%e %M" ./build-bench/kdmesh encode "$file" -o build-bench/peak.kdm --bits "$b" -q; } 2>&1 | tail -n 1)
    dec=$( { /usr/bin/time -f "%e %M" ./build-bench/kdmesh decode build-bench/peak.kdm -o build-bench/peak.ply -q; } 2>&1 | tail -n 1)
    simplices=$(./build-bench/kdmesh info build-bench/peak.kdm --json | awk -F'[][,]' '/simplexCounts/ { print $4 + $5 }')
    echo "$(basename "$file") $simplices $enc $dec" |
      awk '{ printf "| %s | %d | %.2f | %d | %.0f | %.2f | %d | %.0f |\n", $1, $2, $3, $4, 1024 * $4 / $2, $5, $6, 1024 * $6 / $2 }'
  done
  echo
fi

echo "## Vertex attributes: kdmesh vs Draco -cl 10, bits per vertex"
echo
# shellcheck disable=SC2086
./build-bench/kdmesh_bench_attributes --bits 12 $meshes
echo

echo "## WebAssembly decoder in Node (warm medians)"
echo
sh scripts/build-wasm.sh >/dev/null
if [ "$quick" = 1 ]; then
  node bench/wasm-bench.mjs --quick build/models/triceratops.off
else
  # shellcheck disable=SC2086
  node bench/wasm-bench.mjs build/models/triceratops.off $(ls ../shared/models/bunny.obj 2>/dev/null || true) "$dragon"
fi
echo

if [ "$quick" = 0 ]; then
  echo "## Viewer: time to first and final render (headless chromium, SwiftShader)"
  echo
  node bench/browser-bench.mjs --throttle 10000 --runs 5
  echo
  echo "## glTF scene: Draco, meshopt and kdmesh through GLTFLoader"
  echo
  node bench/gltf-bench.mjs --throttle 10000 --runs 3
  echo
  echo "Pictures of the dragon's early levels, predicted and cell-centre placement (docs/coarse-levels/):"
  echo
  node bench/coarse-levels.mjs --out build-bench/coarse-levels 8000 16000
  echo
fi

if [ "$quick" = 0 ]; then
  echo "## Rate–distortion (docs/rate-distortion.svg)"
  echo
  rd=build-bench/rd
  mkdir -p "$rd"
  plot=""
  for spec in "bunny:../shared/models/bunny.obj:12" "dragon:$dragon:12" "triceratops:build/models/triceratops.off:12" \
              "tetrahedral-ball:build/models/ball10k.1.ele:16"; do
    name=${spec%%:*}; rest=${spec#*:}; file=${rest%:*}; b=${rest##*:}
    [ -f "$file" ] || continue
    ./build-bench/kdmesh_bench_rd --bits "$b" "$file" > "$rd/$name.csv"
    draco=""
    case "$file" in *.ele) ;; *)
      ./build-bench/kdmesh encode "$file" -o "$rd/$name.kdm" --exact -q
      ./build-bench/kdmesh decode "$rd/$name.kdm" -o "$rd/$name.ply" -q
      draco_encoder -i "$rd/$name.ply" -o "$rd/$name.drc" -qp "$b" -cl 10 >/dev/null
      draco=":$(wc -c < "$rd/$name.drc")" ;;
    esac
    plot="$plot $name-${b}bit=$rd/$name.csv$draco"
    echo "- $name ($b bits): $(sed -n 2p "$rd/$name.csv" | cut -d, -f2) vertex after $(sed -n 2p "$rd/$name.csv" | cut -d, -f1) bytes;" \
      "mean error 1 % of the diagonal after $(awk -F, 'NR > 1 && $3 <= 0.01 { print $1; exit }' "$rd/$name.csv") bytes," \
      "Hausdorff 1 % after $(awk -F, 'NR > 1 && $5 != "" && $5 <= 0.01 { print $1; exit }' "$rd/$name.csv") bytes," \
      "of $(tail -n 1 "$rd/$name.csv" | cut -d, -f1)"
  done
  # shellcheck disable=SC2086
  node bench/plot-rd.mjs docs/rate-distortion.svg $plot
  echo
fi

if [ "$quick" = 0 ]; then
  echo "## Scale: the dragon replicated side by side (16 bits, one run each)"
  echo
  echo "| copies | triangles | bytes | encode s | decode s | encode Mtri/s | decode Mtri/s | peak bytes / triangle |"
  echo "|---:|---:|---:|---:|---:|---:|---:|---:|"
  for copies in 1 2 4 6; do ./build-bench/kdmesh_bench_scale "$copies" "$dragon"; done
  echo
fi

echo "## Point clouds: file sizes from the command-line tools"
echo
echo "| model | bits | kdmesh bytes | kdmesh bpv | draco_encoder -point_cloud -cl 10 bytes | Draco bpv |"
echo "|---|---:|---:|---:|---:|---:|"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for model in $models; do
  for b in $(echo "$bits" | sed 's/--bits//g'); do
    ./build-bench/kdmesh encode "$model" -o "$tmp/m.kdm" --bits "$b" --points-only -q
    draco_encoder -point_cloud -i "$model" -o "$tmp/m.drc" -qp "$b" -cl 10 >/dev/null
    vertices=$(./build-bench/kdmesh info "$tmp/m.kdm" --json | sed -n 's/.*"vertexCount": *\([0-9]*\).*/\1/p' | head -n 1)
    ours=$(wc -c < "$tmp/m.kdm")
    theirs=$(wc -c < "$tmp/m.drc")
    awk -v m="$(basename "$model")" -v b="$b" -v o="$ours" -v t="$theirs" -v n="$vertices" \
      'BEGIN { printf "| %s | %s | %d | %.3f | %d | %.3f |\n", m, b, o, 8 * o / n, t, 8 * t / n }' 
  done
done
