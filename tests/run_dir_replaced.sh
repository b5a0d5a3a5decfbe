#!/usr/bin/env bash
# Issue 26, point 3: one writer per run directory, also when the directory is deleted and
# recreated under a running process.
# replaced: `run --out D` works in the background; D is deleted and a new `run --out D` runs
#   there. The first process stops at its next write (here a STOP file: exit 74, a message)
#   without writing into the new D; the new run's checkpoints are all its own and `resume D`
#   works (54d8750: the first run wrote its checkpoint there and its rotation deleted the new
#   run's, and resume found none valid).
# rotation: a checkpoint of another run in D/checkpoints (older than the run's own) is not
#   deleted by the run's rotation.
# usage: run_dir_replaced.sh CHANSPH SCENE RUNS CASE
set -u
chansph=$1 scene=$2 runs=$3 case=$4
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
unset CHANSPH_RUN_ID
status=0
fail() { echo "FAIL: $*"; status=1; }
d=$runs/dir_replaced_$case
rm -rf "$d" "$d.other"
# the run identity stored in a checkpoint
ckpt_id() { h5dump -a /run_id "$1" | sed -n 's/.*(0): "\(.*\)".*/\1/p'; }
if [ "$case" = replaced ]; then
  # the first run writes nothing until it is stopped (no periodic checkpoint, stats.nc at the
  # end): its next write comes after the second run has made and used the new D
  "$chansph" run "$scene" --out "$d" --set time.t_end=1000 --set output.t_average_start=0 \
    --set checkpoint.every_minutes=0 --set checkpoint.every_steps=0 --set checkpoint.keep=1 \
    --set output.log_every=100 > "$d.first.out" 2>&1 &
  pid=$!
  for _ in $(seq 3000); do # under way: a progress line
    grep -q "^step" "$d/log.txt" 2> /dev/null && break
    kill -0 $pid 2> /dev/null || break
    sleep 0.1
  done
  grep -q "^step" "$d/log.txt" || fail "the first run did not start"
  rm -rf "$d"
  "$chansph" run "$scene" --out "$d" --set time.t_end=0.2 --set output.t_average_start=0 \
    --set checkpoint.every_steps=5 --set checkpoint.keep=2 > /dev/null 2>&1 ||
    fail "the second run failed"
  id=$(cat "$d/run_id")
  touch "$d/STOP" # the first run's path to its STOP file now names the new D's
  for _ in $(seq 600); do kill -0 $pid 2> /dev/null || break; sleep 0.1; done
  kill $pid 2> /dev/null && fail "the first run still runs (killed)"
  wait $pid
  rc=$?
  tail -n 3 "$d.first.out"
  [ $rc -eq 74 ] || fail "the first run ended with $rc, expected 74"
  grep -q "is no longer the run directory this process locked" "$d.first.out" ||
    fail "the first run gave no message about its directory"
  for ck in "$d"/checkpoints/ckpt_*.h5; do
    [ "$(ckpt_id "$ck")" = "$id" ] || fail "$ck is not the second run's ($id)"
  done
  [ "$(ls "$d"/checkpoints/ckpt_*.h5 | wc -l)" -ge 2 ] || fail "the second run's checkpoints are gone"
  [ -e "$d/STOP" ] || fail "the first run removed the STOP file of a directory it no longer holds"
  rm -f "$d/STOP"
  out=$("$chansph" resume "$d" --set time.t_end=0.25 2>&1)
  rc=$?
  [ $rc -eq 0 ] || fail "resume of the second run: exit $rc"
  echo "$out" | grep "^resume: "
  echo "$out" | grep -q "^resume: skipped" && fail "resume skipped a checkpoint"
else
  "$chansph" run "$scene" --out "$d.other" --set time.max_steps=5 --set output.t_average_start=0 \
    > /dev/null 2>&1 || fail "the other run"
  "$chansph" run "$scene" --out "$d" --set time.t_end=0.1 --set output.t_average_start=0 \
    --set checkpoint.every_steps=5 --set checkpoint.keep=2 > /dev/null 2>&1 || fail "the run"
  cp "$d.other/checkpoints/ckpt_0000000005.h5" "$d/checkpoints/"
  "$chansph" resume "$d" --set time.t_end=0.2 > /dev/null 2>&1 || fail "resume"
  ls "$d/checkpoints"
  [ -e "$d/checkpoints/ckpt_0000000005.h5" ] ||
    fail "the rotation deleted the checkpoint of another run"
  [ "$(ls "$d"/checkpoints/ckpt_*.h5 | wc -l)" -eq 3 ] ||
    fail "expected the run's 2 newest checkpoints and the other run's"
fi
[ $status -eq 0 ] && echo PASS
exit $status
