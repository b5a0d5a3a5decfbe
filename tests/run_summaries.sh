#!/usr/bin/env bash
# Issue 13, point 13: honest run summaries. The ETA counts time.max_steps; a run stopped by
# max_steps reports average_end (stats.nc) and extract's time range up to the reached time;
# warnings for snapshots.every longer than the run and for Lagrangian lags without samples and
# T_L = NaN; run|resume|bench|extract --help print the usage and exit 0; resume does not build
# and announce an initial profile before restoring. (compare and CHANSPH_PYTHON:
# compare_extract_inputs.)
# usage: run_summaries.sh CHANSPH SCENES RUNS
set -u
chansph=$1 scenes=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
p2=$scenes/poiseuille2d.ini

d=$runs/summary_eta
rm -rf "$d"
out=$("$chansph" run "$p2" --out "$d" --set time.t_end=1e6 --set time.max_steps=60 \
  --set output.log_every=20 2>&1) || fail "eta run"
echo "$out" | grep "^step"
[ "$(echo "$out" | grep -c "^step.*ETA 00:00:")" -eq 4 ] ||
  fail "the ETA of a run ended by time.max_steps (60 steps of a 2-D channel) is not seconds"

d=$runs/summary_max_steps
rm -rf "$d"
out=$("$chansph" run "$p2" --out "$d" --set time.t_end=0.2 --set output.t_average_start=0 \
  --set time.max_steps=20 --set snapshots.every=5 2>&1) || fail "max_steps run"
echo "$out" | grep -q "warning: snapshots.every = 5 s is longer than the rest of the run (t = 0 .. t_end = 0.2 s): no snapshot will be written" ||
  fail "no warning for snapshots.every longer than the run"
ncdump -h "$d/stats.nc" | grep -E ":(t_reached|average_end) ="
ncdump -h "$d/stats.nc" | grep -q ":average_end = 0.104 ;" || fail "average_end is not the reached 0.104 s"
"$chansph" extract "$d/stats.nc" | head -n 1 | grep -q " .. 0.104 s," ||
  fail "extract's time range does not end at the reached 0.104 s"

d=$runs/summary_lagrangian
rm -rf "$d"
out=$("$chansph" run "$scenes/poiseuille3d.ini" --out "$d" --set time.t_end=0.3 \
  --set output.t_average_start=0.05 --set stats.u_tau_ref=0.6 --set lagrangian.y_plus=1 \
  --set lagrangian.horizon=0.1 --set lagrangian.n_lags=50 2>&1) || fail "lagrangian run"
echo "$out" | grep warning
echo "$out" | grep -q "warning: lagrangian level y+ = 1: 49 of 51 lags have no samples" ||
  fail "no warning for Lagrangian lags without samples"
echo "$out" | grep -q "warning: lagrangian level y+ = 1: T_L of .* is NaN" || fail "no warning for T_L = NaN"
grep -q "warning: lagrangian level" "$d/log.txt" || fail "the warnings are not in log.txt"

for cmd in run resume bench extract; do
  out=$("$chansph" $cmd --help 2>&1)
  rc=$?
  [ $rc -eq 0 ] || fail "chansph $cmd --help: exit $rc"
  echo "$out" | grep -q "usage" || fail "chansph $cmd --help: no usage"
done

d=$runs/summary_resume
rm -rf "$d"
"$chansph" run "$p2" --out "$d" --set init.profile=reichardt --max-steps 2 > /dev/null 2>&1
out=$("$chansph" resume "$d" --max-steps 1 2>&1)
[ $? -eq 75 ] || fail "resume --max-steps 1"
echo "$out" | grep "init:" && fail "resume announces an initial profile before restoring"
[ $status -eq 0 ] && echo PASS
exit $status
