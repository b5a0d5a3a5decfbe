#!/usr/bin/env bash
# Issue 13, point 4: a run directory is locked for the life of the run. While `run` works in
# DIR, `resume DIR` and `run --out DIR --overwrite` exit 1 with a message naming the holder, and
# change nothing; once the run has stopped, resume works.
# usage: run_lock.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/lock
rm -rf "$d"
"$chansph" run "$scene" --out "$d" --set time.t_end=1000 --set output.t_average_start=0 \
  --set checkpoint.every_minutes=0 --set checkpoint.every_steps=20 --set output.log_every=20 \
  > "$runs/lock.out" 2>&1 &
pid=$!
# under way: its first checkpoint is written (at most 300 s on a loaded machine)
for _ in $(seq 3000); do
  compgen -G "$d/checkpoints/ckpt_*.h5" > /dev/null && break
  kill -0 $pid 2> /dev/null || break
  sleep 0.1
done
compgen -G "$d/checkpoints/ckpt_*.h5" > /dev/null || fail "the run did not start"
before=$(ls "$d/checkpoints" | head -n 1)
out=$("$chansph" resume "$d" --max-steps 2 2>&1) # --max-steps: no long run without the lock
rc=$?
echo "resume while running: exit $rc: $out"
[ $rc -eq 1 ] || fail "resume while running: exit $rc, expected 1"
echo "$out" | grep -q "$d is in use by another chansph run or resume (process $pid)" ||
  fail "resume while running: no message naming the lock holder"
out=$("$chansph" run "$scene" --out "$d" --overwrite --max-steps 2 2>&1)
rc=$?
echo "run --overwrite while running: exit $rc"
[ $rc -eq 1 ] || fail "run --overwrite while running: exit $rc, expected 1"
echo "$out" | grep -q "is in use by another chansph run" || fail "run --overwrite: no message"
[ -e "$d/checkpoints/$before" ] || [ -n "$(ls "$d/checkpoints")" ] ||
  fail "the running run's checkpoints were removed"
touch "$d/STOP"
wait $pid
rc=$?
[ $rc -eq 75 ] || fail "the run ended with $rc, expected 75 (STOP)"
grep -q "^resume: from" "$d/log.txt" && fail "log.txt holds lines of a second process"
"$chansph" resume "$d" --max-steps 2 > /dev/null 2>&1
rc=$?
[ $rc -eq 75 ] || fail "resume after the run ended: exit $rc, expected 75"
[ $status -eq 0 ] && echo PASS
exit $status
