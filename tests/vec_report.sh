#!/usr/bin/env bash
# Which loops of the force pass GCC vectorises, per force loop and instruction-set clone: compiles
# solver/forces.c with the Release flags of build/ and the vectoriser's dump, and counts the
# pair loops (pair_sums) vectorised in each function with their vector width. Every force loop
# should list its 4 pair loops (2 pressure forms x fluid and vertex parts) at 16 bytes (default
# clone), 32 (avx2) and 64 (x86-64-v4), plus their epilogues. A compile-time report only: a
# loop reported vectorised may still run its scalar version (issue 22: with both data paths in
# one function the gathered loops were reported vectorised and ran 3-4 times slower), so the
# bench (tests/bench_compare.sh) is the check that counts.
# usage: tests/vec_report.sh [BUILD_DIR (default build)]
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
flags=$(sed -n 's/^C_FLAGS = //p' "$build/CMakeFiles/chansph_core.dir/flags.make")
defs=$(sed -n 's/^C_DEFINES = //p' "$build/CMakeFiles/chansph_core.dir/flags.make")
incs=$(sed -n 's/^C_INCLUDES = //p' "$build/CMakeFiles/chansph_core.dir/flags.make")
work=$(mktemp -d /tmp/vec_report.XXXXXX)
trap 'rm -rf "$work"' EXIT
cd "$work"
eval gcc $flags $defs $incs -c "$here/solver/forces.c" -o forces.o -fdump-tree-vect-details
line=$(grep -n '#pragma omp simd' "$here/solver/forces.c" | head -1 | cut -d: -f1)
loop=$line # GCC reports the loop at its pragma
awk -v tag="forces.c:$loop:" '/^;; Function/ {fn = $3}
  index($0, tag) && /optimized: loop vectorized using/ {n[fn " " $(NF-2)]++}
  END {for (k in n) print k, "byte vectors:", n[k]}' ./*.vect | sort
