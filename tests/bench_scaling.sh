#!/usr/bin/env bash
# Per-phase scaling of two builds over ranks x threads, runs interleaved (issue 44).
#
# usage: tests/bench_scaling.sh OLD_CHANSPH NEW_CHANSPH [--reps N] [--steps N]
#                               [--layouts "1x1 1x2 2x1"] [--log FILE] [SCENE.ini]
# For each repetition and layout RANKSxTHREADS, runs `chansph bench [SCENE] --steps N` with the
# old build, then the new one (mpirun -np RANKS --bind-to none, OMP_NUM_THREADS=THREADS), and
# appends the output to the log (default: a new file under /tmp) after a line
# "=== build=old|new ranks=R threads=T rep=K". Then prints tests/bench_table.py's medians
# (ms/step, particle-steps/s, efficiency against 1 x 1, sort and halo per step). Default: the
# built-in bench case, 3 repetitions of 20 steps, layouts 1x1 1x2 2x1. Run it on an idle machine.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
old=${1:?usage: bench_scaling.sh OLD_CHANSPH NEW_CHANSPH [options] [SCENE]}
new=${2:?usage: bench_scaling.sh OLD_CHANSPH NEW_CHANSPH [options] [SCENE]}
shift 2
reps=3 steps=20 layouts="1x1 1x2 2x1" log="" scene=()
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --layouts) layouts=$2; shift 2 ;;
    --log) log=$2; shift 2 ;;
    *) scene=("$1"); shift ;;
  esac
done
[ -n "$log" ] || log=$(mktemp /tmp/bench_scaling.XXXXXX.log)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
for rep in $(seq 1 "$reps"); do
  for l in $layouts; do
    r=${l%x*} t=${l#*x}
    for b in old new; do
      bin=$old
      [ $b = new ] && bin=$new
      echo "=== build=$b ranks=$r threads=$t rep=$rep" >> "$log"
      OMP_NUM_THREADS=$t mpirun -np "$r" --oversubscribe --bind-to none -x OMP_NUM_THREADS \
        "$bin" bench "${scene[@]}" --steps "$steps" >> "$log" 2>&1
    done
  done
done
echo "log: $log"
"$here/tests/bench_table.py" "$log"
