#!/usr/bin/env bash
# Issue 13, point 14: a convergence target (stats.target_stderr) ends the run by itself once the
# relative standard errors of the chosen profiles are below it, with enough windows of enough
# correlation times: final checkpoint, stats.nc, exit 0. Every convergence line of the log is
# followed by the target line with the projected simulated and wall time.
# usage: converge_stop.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/converge
rm -rf "$d"
common=(--set init.profile=laminar --set output.t_average_start=0 --set stats.window=0.1
  --set output.write_every=0.2 --set stats.target_profiles=u_mean)
out=$("$chansph" run "$scene" --out "$d" "${common[@]}" --set stats.target_stderr=1e-3 \
  --set stats.target_corr_ratio=0 2>&1)
rc=$?
echo "$out" | grep -E "^(target|converged|finished)"
[ $rc -eq 0 ] || fail "exit status $rc, expected 0"
line=$(echo "$out" | grep "^converged: the statistics meet stats.target_stderr = 0.001 at step")
[ -n "$line" ] || fail "no converged line"
step=$(echo "$line" | sed 's/.* at step \([0-9]*\),.*/\1/')
echo "$out" | grep -q "^finished: $step steps, t = 0\.[0-9]* s" || fail "the run did not end at step $step (t_end = 12 s)"
[ -e "$d/checkpoints/$(printf 'ckpt_%010d.h5' "$step")" ] || fail "no final checkpoint at step $step"
ncdump -h "$d/stats.nc" | grep -Eq ":n_windows = [4-9]" || fail "stats.nc has fewer than 4 windows"
# every convergence line with 2 or more windows is followed by a target line with a projection
n_stats=$(echo "$out" | grep -c "^stats: [2-9][0-9]* complete windows")
n_target=$(echo "$out" | grep -Ec "^target: relative stderr 0.001 of u_mean: .*(projected: [0-9]+ windows, t = .* s \(.* s more simulated, about [0-9:]+ wall\)|target met)")
[ "$n_target" -ge 2 ] && [ "$n_target" -ge $((n_stats - 1)) ] ||
  fail "convergence lines without projection ($n_stats convergence lines, $n_target target lines)"
# windows shorter than target_corr_ratio correlation times do not count: the run goes to t_end
out=$("$chansph" run "$scene" --out "$d" --overwrite "${common[@]}" --set time.t_end=0.6 \
  --set stats.target_stderr=1e-3 2>&1)
rc=$?
[ $rc -eq 0 ] || fail "second run: exit $rc"
echo "$out" | grep -q "^converged" && fail "converged with windows shorter than 5 correlation times"
echo "$out" | grep -q "windows too short to count: window/correlation time .* < 5" ||
  fail "no message that the windows are too short"
[ $status -eq 0 ] && echo PASS
exit $status
