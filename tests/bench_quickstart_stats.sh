#!/usr/bin/env bash
# The statistics' share of the quick-start's step, two builds each with its own quick-start
# scene (issue 43: <= 3% as shipped), interleaved REPS times (default 3) on an otherwise idle
# machine: OMP_NUM_THREADS=2 chansph run SCENE --set time.max_steps=STEPS (default 200)
# --set output.write_every=0, from the scene's own shipped state (a relative init.from is taken
# against jobs/scenes/, so that a scene copied out of the repository still finds it). The share is the run's own timers: the
# statistics phases (stats: sampling; budget: the split of the pair forces and its halo
# refresh) over the rest of the wall time; prints each run and the medians.
# usage: tests/bench_quickstart_stats.sh OLD_CHANSPH OLD_SCENE NEW_CHANSPH NEW_SCENE [STEPS] [REPS]
# e.g. git show b5ee795:jobs/scenes/quickstart.ini > /tmp/qs_old.ini and the old build.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 4 ] || { sed -n 2,10p "$0" >&2; exit 1; }
bins=("$1" "$3") scenes=("$2" "$4") steps=${5:-200} reps=${6:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
shares=("" "")
for r in $(seq "$reps"); do
  for k in 0 1; do
    log=$work/$k.log
    from=$(sed -n 's/^from *= *\([^ ;]*\).*/\1/p' "${scenes[$k]}" | head -1)
    case $from in /*) ;; *) from=$root/jobs/scenes/$from ;; esac
    OMP_NUM_THREADS=2 "${bins[$k]}" run "${scenes[$k]}" --out "$work/$k" --overwrite \
      --set init.from="$from" --set time.max_steps="$steps" \
      --set output.write_every=0 > "$log" 2>&1 ||
      { tail -3 "$log"; echo "FAIL: run ${bins[$k]}"; exit 1; }
    t=$(sed -n 's/^finished: .* in \([0-9.]*\) s wall.*/\1/p' "$log")
    s=$(awk '$1 == "stats" || $1 == "budget" {s += $2} END {printf "%.3f", s}' "$log")
    share=$(echo "$s $t" | awk '{printf "%.5f", $1 / ($2 - $1)}')
    shares[$k]="${shares[$k]} $share"
    echo "rep $r ${bins[$k]} (${scenes[$k]}): $t s, statistics $s s: $(echo "$share" | awk '{printf "%.2f", 100 * $1}')% of the rest"
  done
done
median() { printf '%s\n' $1 | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
for k in 0 1; do
  echo "${bins[$k]} (${scenes[$k]}): statistics $(median "${shares[$k]}" | awk '{printf "%.2f", 100 * $1}')% of the rest of the step (median of $reps)"
done
