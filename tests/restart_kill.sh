#!/usr/bin/env bash
# Acceptance 2 of issue 4: a run is killed with SIGKILL at K random moments (many of them inside
# a checkpoint write) and resumed each time by jobs/chain.sh; its final stats.nc, particles.nc
# and final checkpoint equal those of an uninterrupted run.
# The scene must run well over 12 s of job time (20 kills of up to 0.6 s each); see
# tests/CMakeLists.txt (KILL_SCENE).
# usage: restart_kill.sh CHANSPH SCENE RUNS KILLS SEED [--set k=v ...]
set -u
# the runs compared here share one identity (issue 13: DIR/run_id, stored in every file)
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3 kills=$4 seed=$5
shift 5
here=$(cd "$(dirname "$0")/.." && pwd)
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
ref=$runs/kill_${kills}_ref dir=$runs/kill_$kills
rm -rf "$ref" "$dir"
t0=$(date +%s.%N)
"$chansph" run "$scene" --out "$ref" "$@" > /dev/null || { echo "FAIL: reference run"; exit 1; }
t_ref=$(echo "$(date +%s.%N) - $t0" | bc)
echo "uninterrupted run: $t_ref s"

RANDOM=$seed
CHANSPH=$chansph CHAIN_MAX_FAILS=1000 CHAIN_PAUSE=0.2 "$here/jobs/chain.sh" "$dir" "$scene" -- "$@" \
  > "$runs/kill_$kills.chain.log" 2>&1 &
chain=$!
in_write=0 done_kills=0
for ((k = 1; k <= kills; k++)); do
  child=""
  while [ -z "$child" ] && kill -0 $chain 2> /dev/null; do # the chansph job of the chain
    child=$(pgrep -P $chain -x chansph)
    [ -z "$child" ] && sleep 0.01
  done
  [ -n "$child" ] || break
  delay=$(printf '0.%03d' $((50 + RANDOM % 550))) # 0.05 .. 0.6 s after the job started
  sleep "$delay"
  kill -KILL "$child" 2> /dev/null || continue
  done_kills=$((done_kills + 1))
  sleep 0.05
  # a temporary file (by inode) that the previous kill did not leave: killed inside its write
  tmp=$(cd "$dir/checkpoints" 2> /dev/null && ls -i -- *.tmp 2> /dev/null | tr '\n' ' ')
  newest=$(ls "$dir/checkpoints" 2> /dev/null | grep -E '^ckpt_[0-9]+\.h5$' | tail -n 1)
  where=""
  if [ -n "$tmp" ] && [ "$tmp" != "${last_tmp:-}" ]; then
    in_write=$((in_write + 1)) where=", inside the write of ${tmp#* }"
  fi
  last_tmp=$tmp
  echo "kill $k at $delay s into the job: newest ${newest:-none}$where"
  while [ -n "$(pgrep -P $chain -x chansph)" ]; do sleep 0.01; done
done
wait $chain
rc=$?
echo "chain.sh exit $rc after $done_kills SIGKILLs ($in_write inside a checkpoint write); $(grep -c '^chain: job' "$runs/kill_$kills.chain.log") jobs"
status=0
[ $rc -eq 0 ] || { echo "FAIL: chain.sh exit $rc"; status=1; }
[ $done_kills -eq "$kills" ] || { echo "FAIL: only $done_kills kills before the run ended"; status=1; }
for f in stats.nc particles.nc; do
  if diff <("$(dirname "$0")/nc_content.sh" "$ref/$f") <("$(dirname "$0")/nc_content.sh" "$dir/$f") \
    > /dev/null; then
    echo "$f: data identical to the uninterrupted run"
  else
    echo "$f: DIFFERENT"; status=1
  fi
done
last=$(ls "$ref/checkpoints" | tail -n 1)
h5diff "$ref/checkpoints/$last" "$dir/checkpoints/$last" > /dev/null &&
  echo "$last: h5diff finds no difference" || { echo "$last: DIFFERENT"; status=1; }
[ $status -eq 0 ] && echo PASS
exit $status
