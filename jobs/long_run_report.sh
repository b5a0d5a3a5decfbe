#!/usr/bin/env bash
# The report of a long turbulent run (docs/validation/turbulent_channel.md): its
# developed range T0..T1 written as a stats.nc of its own (chansph extract --nc), the profiles
# against MKM Re_tau = 180 (chansph compare: L2 per layer, the deviation relative to each DNS
# peak over 10 < y+ < 150 with the standard errors, plots), the Reynolds-stress budgets against
# the MKM balances, the window peaks, and the error of the running average from T0 against run
# time. Seconds, no simulation.
# usage: jobs/long_run_report.sh RUN_DIR T0[:T1] OUT_DIR [LABEL]
#   e.g. jobs/long_run_report.sh runs/w6 1.0 runs/w6_report w6
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 3 ] || { sed -n 2,10p "$0" >&2; exit 1; }
run=$1 range=$2 out=$3 label=${4:-run}
case $range in *:*) ;; *) range="$range:" ;; esac
t0=${range%%:*}
chansph=${CHANSPH:-$root/build/chansph}
tools=$root/stats/python/chansph-stats
dns=$root/stats/dns/mkm1999/chan180.means
[ -f "$run/stats.nc" ] || { echo "error: $run/stats.nc: no such file" >&2; exit 1; }
mkdir -p "$out"
"$chansph" extract "$run/stats.nc" --window "$range" --nc "$out/stats.nc"
"$chansph" compare "$out/stats.nc" --dns "$dns" --out "$out/compare" > "$out/compare.txt"
"$chansph" compare "$out/stats.nc" --dns "$dns" --out "$out/compare_force" --no-plots \
  --u-tau force > "$out/compare_force.txt"
"$tools" rs_budget "$out/stats.nc" --markdown > "$out/rs_budget.md"
t1=$(/usr/bin/python3 -c "import netCDF4, sys; print(netCDF4.Dataset(sys.argv[1]).average_end)" \
  "$out/stats.nc")
"$tools" window_peaks --dns "$dns" --plot "$out/profiles.png" "$label=$run@$t0:$t1" \
  > "$out/window_peaks.txt"
"$tools" error_vs_time --dns "$dns" --group 0.5 --cumulative "$t0" --out "$out" \
  "$label=$run" > "$out/error_vs_time.txt"
grep -E "^ours|^  |^deviation|^largest" "$out/compare.txt" | sed -n '1,12p'
echo "(u_tau of the force balance:)"
sed -n '/^deviation/,/^largest/p' "$out/compare_force.txt"
tail -3 "$out/error_vs_time.txt"
echo "wrote $out/: stats.nc (the range), compare/, compare.txt, compare_force.txt, rs_budget.md,"
echo "  window_peaks.txt, profiles.png, error_vs_time.csv/.png/.txt"
