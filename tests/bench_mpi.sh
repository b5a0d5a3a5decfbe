#!/usr/bin/env bash
# Strong scaling on this machine (issue 6, acceptance 4): the 3-D bench scene of `chansph bench`
# (100 000 fluid particles) on 1 rank x 1 thread, 1 rank x 2 threads and 2 ranks x 1 thread.
# Each configuration runs REPEATS times (default 3); the median ms/step is reported with the
# parallel efficiency and the time in halo exchange and migration. A benchmark, not a test: it
# prints numbers and asserts nothing.
# usage: tests/bench_mpi.sh [CHANSPH] [STEPS] [REPEATS] [-- extra chansph bench arguments]
set -euo pipefail
chansph=${1:-build/chansph}
steps=${2:-30}
repeats=${3:-3}
shift $(($# < 3 ? $# : 3))
[ "${1:-}" = "--" ] && shift
extra=("$@")
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out=$(mktemp -d)
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
declare -A ms halo
calc() { awk "BEGIN {print $1}"; }
for cfg in "1 1" "1 2" "2 1"; do
  set -- $cfg
  for r in $(seq "$repeats"); do
    OMP_NUM_THREADS=$2 mpirun --oversubscribe --bind-to none -np "$1" "$chansph" bench \
      --steps "$steps" "${extra[@]}" > "$out/b_$1_$2_$r.txt" 2>&1
  done
  ms[$1x$2]=$(for r in $(seq "$repeats"); do
    sed -n 's/.*timed steps in .* s (\([0-9.]*\) ms\/step).*/\1/p' "$out/b_$1_$2_$r.txt"
  done | median)
  halo[$1x$2]=$(for r in $(seq "$repeats"); do
    sed -n 's/^halo exchange and migration per step: \([0-9.]*\) ms max.*/\1/p' "$out/b_$1_$2_$r.txt"
  done | median)
done
head -1 "$out/b_2_1_1.txt"
grep -h "^particles per rank\|^halo exchange" "$out/b_2_1_1.txt"
printf "%-22s %12s %14s %16s\n" "configuration" "ms/step" "speed-up" "halo ms/step"
for k in 1x1 1x2 2x1; do
  printf "%-22s %12.2f %14.3f %16s\n" "$k (ranks x threads)" "${ms[$k]}" \
    "$(calc "${ms[1x1]} / ${ms[$k]}")" "${halo[$k]:--}"
done
eff=$(calc "100 * ${ms[1x2]} / ${ms[2x1]}")
printf "2 ranks x 1 thread at %.1f%% of 1 rank x 2 threads (target >= 90%%); parallel efficiency " "$eff"
printf "on 2 cores: 1x2 %.1f%%, 2x1 %.1f%%\n" "$(calc "50 * ${ms[1x1]} / ${ms[1x2]}")" \
  "$(calc "50 * ${ms[1x1]} / ${ms[2x1]}")"
rm -rf "$out"
