#!/usr/bin/env bash
# Issue 26, point 13: the progress lines. The ETA counts the command line's --max-steps (a run
# with t_end = 1e6 s stopped after 30 steps shows seconds, not days); the line of step 0 shows
# no ETA yet (`ETA --:--:--`, never 00:00:00); a first line follows the first step although
# output.log_every exceeds the run's steps; each line carries the elapsed wall time and the
# share done.
# usage: progress_eta.sh CHANSPH SCENES RUNS
set -u
chansph=$1 scenes=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/progress_eta
rm -rf "$d"
out=$("$chansph" run "$scenes/poiseuille2d.ini" --out "$d" --set time.t_end=1e6 \
  --set output.log_every=100000 --max-steps 30 2>&1)
[ $? -eq 75 ] || fail "the run did not stop by --max-steps (exit 75)"
echo "$out" | grep "^step"
echo "$out" | grep -E "^step +0 " | grep -q "ETA --:--:--" ||
  fail "step 0 does not say that the ETA is not known yet"
echo "$out" | grep -E "^step +1 " | grep -Eq "elapsed 00:00:[0-9]{2} +[0-9.]+% +ETA 00:0[0-9]:" ||
  fail "no line after the first step with elapsed time, share done and an ETA of seconds"
exit $status
