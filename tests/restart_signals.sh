#!/usr/bin/env bash
# Acceptance 3 of issue 4: SIGTERM, SIGUSR1, SIGINT and a STOP file make a run finish its step,
# write a checkpoint and exit with 75 ("checkpointed, resubmit me"); --walltime exits in time.
# usage: restart_signals.sh CHANSPH SCENE RUNS [DELAY TRIGGERS]
#   DELAY: seconds each run waits before it starts (a loaded machine; default 0); TRIGGERS:
#   the triggers to try (default "TERM USR1 INT STOP", then resume and --walltime)
set -u
chansph=$1 scene=$2 runs=$3 delay=${4:-0} triggers=${5:-}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} # timing checks: no spinning threads on a busy machine
status=0
fail() { echo "FAIL: $*"; status=1; }
long=(--set time.t_end=1000 --set output.t_average_start=0 --set checkpoint.every_minutes=0)

# a run that would last for hours; the trigger arrives once it is under way
for trig in ${triggers:-TERM USR1 INT STOP}; do
  d=$runs/signal_$trig
  rm -rf "$d"
  (sleep "$delay" && exec "$chansph" run "$scene" --out "$d" "${long[@]}") \
    > "$runs/signal_$trig.out" 2>&1 &
  pid=$!
  # under way: the first progress line is in DIR/log.txt (the directory exists, the loop runs);
  # a fixed delay lost the race under load (issue 13, point 9)
  for _ in $(seq 3000); do
    grep -q "^step" "$d/log.txt" 2> /dev/null && break
    kill -0 $pid 2> /dev/null || break
    sleep 0.1
  done
  grep -q "^step" "$d/log.txt" 2> /dev/null || fail "$trig: the run did not get under way"
  t0=$(date +%s.%N)
  if [ $trig = STOP ]; then touch "$d/STOP"; else kill -$trig $pid; fi
  wait $pid
  rc=$?
  t1=$(date +%s.%N)
  line=$(grep "^stopped at step" "$d/log.txt")
  step=$(echo "$line" | sed 's/stopped at step \([0-9]*\),.*/\1/')
  last=$(cd "$d/checkpoints" 2> /dev/null && ls ckpt_*.h5 | tail -n 1)
  printf '%s: exit %d after %.3f s: %s; checkpoint %s\n' $trig $rc "$(echo "$t1 - $t0" | bc)" \
    "$line" "$last"
  [ $rc -eq 75 ] || fail "$trig: exit status $rc, expected 75"
  [ "$last" = "$(printf 'ckpt_%010d.h5' "$step")" ] || fail "$trig: no checkpoint of step $step"
  [ "$(echo "$t1 - $t0 < 2" | bc)" -eq 1 ] || fail "$trig: took more than 2 s"
  [ $trig = STOP ] && [ -e "$d/STOP" ] && fail "STOP file not removed"
  [ -s "$d/stats.nc" ] || fail "$trig: no stats.nc"
done
if [ -n "$triggers" ]; then
  [ $status -eq 0 ] && echo PASS
  exit $status
fi
# the run resumes from there, and stops again by --max-steps
d=$runs/signal_TERM
"$chansph" resume "$d" --max-steps 3 > /dev/null
rc=$?
[ $rc -eq 75 ] || fail "resume --max-steps 3: exit $rc"
echo "resume --max-steps 3: exit $rc, $(grep '^stopped' "$d/log.txt" | tail -n 1)"

# --walltime 4 s: checkpoint and exit 75 before the limit
d=$runs/signal_walltime
rm -rf "$d"
t0=$(date +%s.%N)
"$chansph" run "$scene" --out "$d" "${long[@]}" --walltime 00:00:04 > /dev/null 2>&1
rc=$?
t1=$(date +%s.%N)
el=$(echo "$t1 - $t0" | bc)
echo "walltime 00:00:04: exit $rc after $el s; $(grep '^stopped' "$d/log.txt")"
[ $rc -eq 75 ] || fail "walltime: exit $rc"
[ "$(echo "$el < 4" | bc)" -eq 1 ] || fail "walltime: ran $el s, limit 4 s"
[ -n "$(ls "$d/checkpoints"/ckpt_*.h5 2> /dev/null)" ] || fail "walltime: no checkpoint"
[ $status -eq 0 ] && echo PASS
exit $status
