#!/usr/bin/env bash
# Issue 42 point 8: arguments that select nothing are input errors, not an empty answer with
# exit 0: chansph-stats error_vs_time --cumulative after the last window, skewflat_compare --at
# outside the channel. Each: exit 1, "error: ..." naming the argument or file and the span.
# usage: tool_args_check.sh STATS_RUN
set -u
run=$1
root=$(cd "$(dirname "$0")/.." && pwd)
tool=$root/stats/python/chansph-stats dns=$root/stats/dns/mkm1999/chan180.means
status=0
expect() { # expect REGEX command...
  local re=$1 msg rc
  shift
  msg=$("$@" 2>&1 > /dev/null)
  rc=$?
  echo "exit $rc: $msg"
  [ $rc -eq 1 ] && echo "$msg" | grep -q -- "$re" || { echo "FAIL: $*"; status=1; }
}
out=$(mktemp -d)
expect "error: $run/stats.nc: no complete window starts at or after --cumulative 1e+09 (its windows span t = " \
  "$tool" error_vs_time --dns "$dns" "A=$run" --cumulative 1e9 --out "$out"
expect "argument --cumulative: -1: must be at least 0" \
  "$tool" error_vs_time --dns "$dns" "A=$run" --cumulative -1 --out "$out"
expect "error: --at -1: y+ -1 outside the channel of the run" "$tool" skewflat_compare "$run/stats.nc" --at -1
expect "error: --at 5,1e6: y+ 1e+06 outside the channel" "$tool" skewflat_compare "$run/stats.nc" --at 5,1e6
"$tool" error_vs_time --dns "$dns" "A=$run" --cumulative 0.3 --out "$out" | grep -q "0.30- 1.00" ||
  { echo "FAIL: --cumulative 0.3 gives no row"; status=1; }
# a shipped segment, stats.nc without its log: particle-steps from stats.nc (steps x n_fluid,
# spread evenly over 0 .. t_reached), read at the end of the last group
mkdir -p "$out/nolog" && cp "$run/stats.nc" "$out/nolog/"
"$tool" error_vs_time --dns "$dns" "A=$out/nolog" --cumulative 0.3 --out "$out" | grep -q "no log.txt" &&
  /usr/bin/python3 - "$run/stats.nc" "$out/error_vs_time.csv" << 'PY' ||
import sys, netCDF4
d = netCDF4.Dataset(sys.argv[1])
last = open(sys.argv[2]).read().splitlines()[-1].split(",")
want = float(d.steps) * float(d.n_fluid) * float(last[3]) / float(d.t_reached)
sys.exit(0 if abs(float(last[4]) - want) <= 1e-6 * want else f"{last[4]} particle-steps, not {want}")
PY
  { echo "FAIL: error_vs_time on stats.nc without log.txt"; status=1; }
rm -rf "$out"
[ $status -eq 0 ] && echo "PASS: tool arguments that select nothing are refused"
exit $status
