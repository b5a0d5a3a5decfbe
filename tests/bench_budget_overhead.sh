#!/usr/bin/env bash
# The cost of the statistics with the budgets (issue 23): the dr+ = 4.5 turbulent unit from its
# shipped state, STEPS steps (default 150) each of
#   none   no Eulerian statistics (stats.eulerian = 0)
#   every10  the default: profiles and budgets every 10 steps
#   every20  every 20 steps
# interleaved REPS times (default 3), on an otherwise idle machine; prints the median wall time
# of the step loop (the log's "finished ... in T s wall") and the overhead against none.
# usage: tests/bench_budget_overhead.sh [CHANSPH] [STEPS] [REPS]
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
chansph=${1:-$root/build/chansph} steps=${2:-150} reps=${3:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
declare -A times
for r in $(seq "$reps"); do
  for c in none every10 every20; do
    case $c in
      none) set=(--set stats.eulerian=0) ;;
      every10) set=(--set output.stats_every=10) ;;
      every20) set=(--set output.stats_every=20) ;;
    esac
    "$chansph" run "$root/jobs/scenes/mfu180_dr45_budget.ini" --out "$work/$c" --overwrite \
      --set time.max_steps="$steps" --set output.write_every=0 "${set[@]}" > "$work/$c.log" 2>&1 ||
      { tail -3 "$work/$c.log"; echo "FAIL: run $c"; exit 1; }
    t=$(sed -n 's/^finished: .* in \([0-9.]*\) s wall.*/\1/p' "$work/$c.log")
    times[$c]="${times[$c]:-} $t"
    echo "rep $r $c: $t s"
  done
done
median() { printf '%s\n' $1 | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
base=$(median "${times[none]}")
for c in none every10 every20; do
  m=$(median "${times[$c]}")
  echo "$c: median $m s for $steps steps, overhead $(echo "100 * ($m - $base) / $base" | bc -l | xargs printf '%.1f')%"
done
