#!/usr/bin/env bash
# Issue 13, point 1: no checkpoint and no output is written from a state that was not checked,
# whatever health.every. A NaN injected after step 23 of a run that checkpoints every 5 steps:
#  a) health.every = 100: exit 3 at step 25 (the first write after the NaN) with the health
#     report; the kept checkpoints (10, 15, 20) hold finite values and the run resumes from
#     the newest to its end;
#  b) health.every = 1000000, no checkpoints, stats.nc rewrites and snapshots: exit 3 at the
#     first sample after the NaN; every file written (stats.nc, snapshots) finite, no
#     particles.nc.
# usage: write_check.sh CHANSPH SCENE RUNS PYTHON
set -u
chansph=$1 scene=$2 runs=$3 py=$4
check="$py $(dirname "$0")/finite_check.py --allow output/next_write"
status=0
fail() { echo "FAIL: $*"; status=1; }
common=(--set time.t_end=0.3 --set output.t_average_start=0.05 --set checkpoint.keep=3
  --inject-nan 23:5)

d=$runs/write_check_a
rm -rf "$d"
out=$("$chansph" run "$scene" --out "$d" "${common[@]}" --set health.every=100 \
  --set checkpoint.every_steps=5 2>&1)
rc=$?
echo "$out" | tail -n 3
[ $rc -eq 3 ] || fail "a: exit status $rc, expected 3"
echo "$out" | grep -Eq "non-finite value at step 25 \(t = [^)]*\): particle id [0-9]+ at \(" ||
  fail "a: no health report at step 25"
ls "$d/checkpoints"
[ "$(cd "$d/checkpoints" && echo ckpt_*.h5)" = \
  "ckpt_0000000010.h5 ckpt_0000000015.h5 ckpt_0000000020.h5" ] ||
  fail "a: the checkpoints of steps 10, 15, 20 are not the ones kept"
$check "$d"/checkpoints/ckpt_*.h5 || fail "a: a checkpoint holds a non-finite value"
out=$("$chansph" resume "$d" 2>&1)
rc=$?
echo "$out" | grep -E "^resume: from|^finished"
[ $rc -eq 0 ] || fail "a: resume exit status $rc, expected 0"
echo "$out" | grep -q "resume: from .*ckpt_0000000020.h5" || fail "a: not resumed from step 20"

d=$runs/write_check_b
rm -rf "$d"
out=$("$chansph" run "$scene" --out "$d" "${common[@]}" --set health.every=1000000 \
  --set output.write_every=0.02 --set snapshots.every=0.02 --set output.series_every=7 \
  --set output.stats_every=7 2>&1)
rc=$?
echo "$out" | tail -n 3
[ $rc -eq 3 ] || fail "b: exit status $rc, expected 3"
# the first write after step 23: the snapshot of step 24 (t = 0.1248)
echo "$out" | grep -Eq "non-finite value at step 24 " || fail "b: no health report at step 24"
[ -e "$d/particles.nc" ] && fail "b: particles.nc written"
ls "$d"/snapshots/snap_*.h5 > /dev/null 2>&1 || fail "b: no snapshot before the NaN"
$check "$d"/stats.nc "$d"/snapshots/snap_*.h5 ||
  fail "b: a file holds a non-finite value"
[ $status -eq 0 ] && echo PASS
exit $status
