#!/usr/bin/env bash
# jobs/pbs/chansph.pbs at the walltime (issue 42 point 7): PBS sends SIGTERM. With a stand-in
# mpirun that behaves as Open MPI's (a SIGTERM kills the ranks and mpirun exits 1; SIGUSR1 is
# forwarded to the ranks and mpirun exits with their status) and a qsub that records the
# resubmission, the job
#   1. sent SIGTERM itself passes SIGUSR1 to mpirun: chansph checkpoints (75), the next job is
#      submitted once, the job exits 0;
#   2. sent SIGTERM with every process of the job (as PBS signals the job's session, mpirun
#      and chansph included): mpirun exits 1, but chansph checkpointed on the signal: the chain
#      goes on the same way (exit 0, one resubmission).
# Before, the script passed SIGTERM on and the chain stopped with exit 1 as on an input error.
# usage: pbs_signal.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
here=$(cd "$(dirname "$0")/.." && pwd)
export CHANSPH_RUN_ID=compare-test OMP_NUM_THREADS=1
fake=$runs/pbs_signal_bin
rm -rf "$fake" && mkdir -p "$fake"
cat > "$fake/mpirun" << 'X'
#!/usr/bin/env bash
while [[ $1 == -* ]]; do [[ $1 == -np || $1 == --bind-to ]] && shift; shift; done
"$@" &
child=$! termed=0
trap 'termed=1; kill -TERM $child 2> /dev/null' TERM
trap 'kill -USR1 $child 2> /dev/null' USR1
while :; do
  wait $child
  rc=$?
  kill -0 $child 2> /dev/null || break
done
[ $termed = 1 ] && exit 1 # Open MPI: a job whose mpirun was sent SIGTERM ends with status 1
exit $rc
X
printf '#!/usr/bin/env bash\nprintf "Job Id: %%s\\n    Resource_List.walltime = 01:00:00\\n" "$PBS_JOBID"\n' > "$fake/qstat"
cat > "$fake/qsub" << 'X'
#!/usr/bin/env bash
echo "qsub $*" >> "$RUN_DIR.jobs"
X
chmod +x "$fake"/*
status=0
for mode in script group; do
  d=$runs/pbs_signal_$mode
  rm -rf "$d" "$d.jobs" "$d.out"
  # a long run (t_end far away): only the signal ends this job
  (cd "$here" && PATH=$fake:$PATH RUN_DIR=$d SCENE=$scene CHANSPH=$chansph \
    CHANSPH_ARGS="--set time.t_end=1000 --set output.t_average_start=0" \
    PBS_JOBID=7.server exec setsid bash jobs/pbs/chansph.pbs > "$d.out" 2>&1) &
  job=$!
  for _ in $(seq 600); do # the run has taken steps
    grep -q "^step *[1-9]" "$d/log.txt" 2> /dev/null && break
    sleep 0.1
  done
  sleep 1
  if [ $mode = script ]; then kill -TERM $job; else kill -TERM -- -$job; fi
  wait $job
  rc=$?
  n=$(cat "$d.jobs" 2> /dev/null | wc -l)
  ck=$(ls "$d/checkpoints" 2> /dev/null | grep -c '^ckpt_.*\.h5$')
  echo "$mode: job exit $rc, $n resubmission(s), $ck checkpoint(s); $(grep '^chain:' "$d.out" | tr '\n' ' ')"
  grep "^stopped at step" "$d/log.txt" | tail -n 1
  if [ $rc -ne 0 ] || [ "$n" -ne 1 ] || [ "$ck" -lt 1 ]; then
    echo "FAIL: PBS job sent SIGTERM ($mode): exit $rc, $n resubmissions, $ck checkpoints"
    tail -n 5 "$d.out"
    status=1
  fi
done
[ $status -eq 0 ] && echo "PASS: the PBS chain goes on after SIGTERM"
exit $status
