#!/bin/sh
# Builds the libFuzzer targets with clang, ASan and UBSan (build-fuzz/),
# seeds their corpora from the test models, and runs each for SECONDS
# (default 25, so CI stays under a minute). Crashes land in build-fuzz/ as
# crash-* files, which should become regression tests.
#
#   sh scripts/fuzz.sh [SECONDS]
set -eu
cd "$(dirname "$0")/.."
seconds=${1:-25}
if [ ! -f build-fuzz/CMakeCache.txt ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKDMESH_FUZZ=ON \
    -DKDMESH_SANITIZE=address,undefined -DKDMESH_BUILD_TESTS=OFF -DKDMESH_BUILD_CLI=OFF >/dev/null
fi
cmake --build build-fuzz -j"$(nproc)" --target fuzz_decoder fuzz_readers

corpus=build-fuzz/corpus
mkdir -p "$corpus/decoder" "$corpus/readers"
if [ -z "$(ls "$corpus/decoder")" ]; then
  # Streams of every kind, small enough to mutate quickly: a real model's,
  # and the committed seed streams (scripts/fuzz-seeds.sh makes them).
  ./build/kdmesh encode build/models/triceratops.off -o "$corpus/decoder/mesh.kdm" --bits 8 --chunk-bytes 256 -q
  ./build/kdmesh encode build/models/triceratops.off -o "$corpus/decoder/points.kdm" --bits 10 --points-only -q
  cp tests/fuzz/seeds/decoder/*.kdm "$corpus/decoder/"
  # Reader seeds: the first byte picks the format (see fuzz_readers.cpp).
  for seed in tests/fuzz/seeds/*.*; do
    case "$seed" in
      *.ply) first='\000' ;; *.obj) first='\001' ;; *.off) first='\002' ;; *.xyz) first='\003' ;;
      *.stl) first='\004' ;; *.mesh) first='\005' ;; *.node) first='\006' ;; *.vtk) first='\007' ;;
    esac
    { printf "$first"; cat "$seed"; } > "$corpus/readers/$(basename "$seed")"
  done
fi

# Budgets per input: an input that takes more than 2 s (the slowest take
# well under 1 s under the sanitizers) or allocates more than 256 MB at once
# is a finding, like a crash: work and memory must stay in proportion to the
# bytes given.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for target in decoder readers; do
  echo "fuzz_$target: $seconds s" >&2
  ./build-fuzz/tests/fuzz/fuzz_$target -max_total_time="$seconds" -rss_limit_mb=1024 -malloc_limit_mb=256 -timeout=2 \
    -artifact_prefix=build-fuzz/ -print_final_stats=1 "$corpus/$target" 2>build-fuzz/fuzz_$target.log ||
    { tail -n 40 build-fuzz/fuzz_$target.log >&2; exit 1; }
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb|stat::slowest_unit_time_sec" build-fuzz/fuzz_$target.log >&2 || true
done
