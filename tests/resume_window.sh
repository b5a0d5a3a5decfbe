#!/usr/bin/env bash
# Issue 26, point 5: the length of the averaging windows is fixed once averaging has begun. With
# the default stats.window = 0 (a tenth of t_end - t_average_start), `resume --set time.t_end=...`
# keeps the length the windows already have (stored in the checkpoint), so that every window of
# stats.nc has one length; `--set stats.window=...` is refused then (exit 1, the key named,
# nothing changed); before averaging begins it is accepted.
# usage: resume_window.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/resume_window
rm -rf "$d"
# windows of (0.4 - 0) / 10 = 0.04 s; stopped at step 40 (t = 0.208 s)
"$chansph" run "$scene" --out "$d" --set time.t_end=0.4 --set output.t_average_start=0 \
  --max-steps 40 > /dev/null
[ $? -eq 75 ] || fail "first run: not stopped by --max-steps"
before=$(cd "$d" && md5sum stats.nc particles.nc scene.used.ini run_id && ls checkpoints)
out=$("$chansph" resume "$d" --set stats.window=0.1 2>&1)
rc=$?
echo "$out" | tail -n 1
[ $rc -eq 1 ] || fail "stats.window changed after averaging began: exit $rc, expected 1"
echo "$out" | grep -q "key 'stats.window' cannot change on resume once averaging has begun" ||
  fail "no message naming stats.window"
[ "$before" = "$(cd "$d" && md5sum stats.nc particles.nc scene.used.ini run_id && ls checkpoints)" ] ||
  fail "the refused resume changed the run directory"
out=$("$chansph" resume "$d" --set time.t_end=0.8 2>&1) || fail "resume with a later t_end"
echo "$out" | grep "^resume: "
len=$(ncdump -h "$d/stats.nc" | sed -n 's/.*:window_length = \([0-9.e+-]*\) ;/\1/p')
[ "$len" = "0.04" ] || fail "window_length of stats.nc is $len, expected 0.04"
# every window [start, end] of the nominal length 0.04 s
ncdump -v window_bounds -g eulerian "$d/stats.nc" 2> /dev/null |
  sed -n '/window_bounds =/,/;/p' | tr -d ' ;' | sed 's/window_bounds=//' | tr ',' '\n' |
  grep -v '^$' | paste - - -d' ' > "$d.bounds"
n=$(wc -l < "$d.bounds")
[ "$n" -ge 15 ] || fail "only $n windows in stats.nc"
awk '{ if ($2 - $1 < 0.04 - 1e-9 || $2 - $1 > 0.04 + 1e-9) { print "window", NR, $1, $2; bad = 1 } }
  END { exit bad }' "$d.bounds" || fail "windows of another length than 0.04 s"
# averaging not begun (start 0.3 s, stopped at t = 0.052 s): stats.window may change
rm -rf "$d"
"$chansph" run "$scene" --out "$d" --set time.t_end=0.4 --set output.t_average_start=0.3 \
  --max-steps 10 > /dev/null
"$chansph" resume "$d" --set stats.window=0.02 > /dev/null 2>&1 ||
  fail "stats.window before averaging began: refused"
len=$(ncdump -h "$d/stats.nc" | sed -n 's/.*:window_length = \([0-9.e+-]*\) ;/\1/p')
[ "$len" = "0.02" ] || fail "window_length is $len after a change before averaging, expected 0.02"
[ $status -eq 0 ] && echo PASS
exit $status
