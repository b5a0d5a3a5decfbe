#!/usr/bin/env bash
# Issue 13, point 5: output.t_average_start may change on resume only before averaging has
# begun, and not to a time before the checkpoint; otherwise resume exits 1 naming the key and
# changes nothing in the run directory.
# usage: resume_average_start.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/average_start
rm -rf "$d"
"$chansph" run "$scene" --out "$d" --set time.t_end=0.3 --set output.t_average_start=0.1 \
  > /dev/null || fail "first run"
before=$(cd "$d" && md5sum stats.nc particles.nc scene.used.ini run_id && ls checkpoints)
out=$("$chansph" resume "$d" --set time.t_end=0.4 --set output.t_average_start=0.2 2>&1)
rc=$?
echo "$out"
[ $rc -eq 1 ] || fail "averaging begun: exit $rc, expected 1"
echo "$out" | grep -q "key 'output.t_average_start' cannot change on resume once averaging has begun" ||
  fail "averaging begun: no message naming the key"
[ "$before" = "$(cd "$d" && md5sum stats.nc particles.nc scene.used.ini run_id && ls checkpoints)" ] ||
  fail "the refused resume changed the run directory"
# averaging not begun yet (stopped at t = 0.052 s, start 0.2 s): a later start is accepted,
# one before the checkpoint is not
rm -rf "$d"
"$chansph" run "$scene" --out "$d" --set time.t_end=0.3 --set output.t_average_start=0.2 \
  --max-steps 10 > /dev/null
[ $? -eq 75 ] || fail "second run: not stopped by --max-steps"
out=$("$chansph" resume "$d" --set output.t_average_start=0.01 2>&1)
rc=$?
echo "$out"
[ $rc -eq 1 ] || fail "start before the checkpoint: exit $rc, expected 1"
echo "$out" | grep -q "key 'output.t_average_start' is before the time of the checkpoint" ||
  fail "start before the checkpoint: no message"
out=$("$chansph" resume "$d" --set output.t_average_start=0.25 2>&1)
rc=$?
echo "$out" | grep "changed"
[ $rc -eq 0 ] || fail "later start before averaging began: exit $rc, expected 0"
echo "$out" | grep -q "resume: output.t_average_start changed from 0.2 to 0.25" ||
  fail "the accepted change is not logged"
[ $status -eq 0 ] && echo PASS
exit $status
