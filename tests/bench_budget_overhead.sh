#!/usr/bin/env bash
# The cost of the statistics with the budgets (issue 23): the dr+ = 4.5 turbulent unit from its
# shipped state, STEPS steps (default 300) each of
#   none     no Eulerian statistics (stats.eulerian = 0)
#   b1       profiles every 10 steps, the budgets with each sample (stats.budget_every = 1)
#   b5       the default: profiles every 10 steps, the budgets every 5th sample (50 steps)
#   b10      the budgets every 10th sample (100 steps)
# interleaved REPS times (default 3), on an otherwise idle machine; prints the median wall time
# of the step loop (the log's "finished ... in T s wall") and the overhead against none, and,
# since wall times on a shared machine drift by more than the overhead, the run's own timers:
# the statistics phases (stats, budget) as a share of the rest of the step, and the sort's share
# (the engine's per-particle arrays travel through it).
# usage: tests/bench_budget_overhead.sh [CHANSPH] [STEPS] [REPS]
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
chansph=${1:-$root/build/chansph} steps=${2:-300} reps=${3:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
declare -A times shares sorts
for r in $(seq "$reps"); do
  for c in none b1 b5 b10; do
    case $c in
      none) set=(--set stats.eulerian=0) ;;
      b1) set=(--set output.stats_every=10 --set stats.budget_every=1) ;;
      b5) set=(--set output.stats_every=10 --set stats.budget_every=5) ;;
      b10) set=(--set output.stats_every=10 --set stats.budget_every=10) ;;
    esac
    "$chansph" run "$root/jobs/scenes/mfu180_dr45_budget.ini" --out "$work/$c" --overwrite \
      --set time.max_steps="$steps" --set output.write_every=0 "${set[@]}" > "$work/$c.log" 2>&1 ||
      { tail -3 "$work/$c.log"; echo "FAIL: run $c"; exit 1; }
    t=$(sed -n 's/^finished: .* in \([0-9.]*\) s wall.*/\1/p' "$work/$c.log")
    times[$c]="${times[$c]:-} $t"
    # the run's own timers: the statistics' phases (sampling, the budget's split and its halo
    # refresh) and the sort (which carries the engine's per-particle arrays) in seconds
    ph=$(awk '$1 == "stats" || $1 == "budget" {s += $2} $1 == "sort" {o = $2}
              END {printf "%.3f %.3f", s, o}' "$work/$c.log")
    shares[$c]="${shares[$c]:-} $(echo "$ph $t" | awk '{printf "%.5f", $1 / ($3 - $1)}')"
    sorts[$c]="${sorts[$c]:-} $(echo "$ph $t" | awk '{printf "%.5f", $2 / $3}')"
    echo "rep $r $c: $t s (statistics phases $(echo "$ph" | cut -d' ' -f1) s, sort $(echo "$ph" | cut -d' ' -f2) s)"
  done
done
median() { printf '%s\n' $1 | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
base=$(median "${times[none]}")
for c in none b1 b5 b10; do
  m=$(median "${times[$c]}")
  lo=$(printf '%s\n' ${times[$c]} | sort -g | head -1)
  echo "$c: median $m s (fastest $lo s) for $steps steps, overhead $(echo "100 * ($m - $base) / $base" | bc -l | xargs printf '%.1f')%;" \
    "statistics phases $(median "${shares[$c]}" | awk '{printf "%.2f", 100 * $1}')% of the rest of the step," \
    "sort $(median "${sorts[$c]}" | awk '{printf "%.2f", 100 * $1}')% of the run"
done
