#!/usr/bin/env bash
# Issue 26, point 6: a run that ended at its convergence target (stats.target_stderr) stays
# finished when resumed, as one that reached t_end does: exit 0, no step taken, no new
# checkpoint, stats.nc and particles.nc of the same step. With a changed target it goes on.
# usage: resume_converged.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/resume_converged
rm -rf "$d"
"$chansph" run "$scene" --out "$d" --set init.profile=laminar --set output.t_average_start=0 \
  --set stats.window=0.1 --set stats.target_profiles=u_mean --set stats.target_stderr=1e-3 \
  --set stats.target_corr_ratio=0 > "$d.out" 2>&1 || fail "first run: exit $?"
grep "^converged" "$d.out" || fail "the first run did not converge"
steps() { ncdump -h "$1" | sed -n 's/.*:\(steps\|step\) = \([0-9]*\).*/\2/p'; }
before="$(ls "$d/checkpoints") $(steps "$d/stats.nc") $(steps "$d/particles.nc")"
out=$("$chansph" resume "$d" 2>&1)
rc=$?
echo "$out" | grep "^resume"
[ $rc -eq 0 ] || fail "resume: exit $rc, expected 0"
echo "$out" | grep -q "^resume: the run ended at step [0-9]* when its statistics met stats.target_stderr = 0.001: it stays finished" ||
  fail "no message that the run stays finished"
after="$(ls "$d/checkpoints") $(steps "$d/stats.nc") $(steps "$d/particles.nc")"
[ "$before" = "$after" ] || fail "the resume went on: before: $before; after: $after"
# a stricter target: the run goes on
out=$("$chansph" resume "$d" --set stats.target_stderr=1e-4 --max-steps 20 2>&1)
rc=$?
[ $rc -eq 75 ] || fail "resume with a new target: exit $rc, expected 75 (--max-steps)"
echo "$out" | grep -q "^resume: the convergence target changed: the run goes on" ||
  fail "no message that the run goes on"
[ $status -eq 0 ] && echo PASS
exit $status
