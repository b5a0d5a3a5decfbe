#!/usr/bin/env bash
# jobs/slurm/chansph.sbatch on a real single-node SLURM (issue 13, point 10): the test starts its
# own munged, slurmctld and slurmd on localhost (configuration, state and logs under
# RUNS/slurm_chain, ports 16817/16818, its own munge socket and key), submits a chain (twice:
# chansph launched by srun with MpiDefault=pmix, and by mpirun with CHAIN_LAUNCH=mpirun) with
# options on the sbatch command line that differ from the script's #SBATCH defaults
# (--cpus-per-task=1 against 16, --time=15 against 24:00:00, a job name, an output pattern), cut
# into jobs of 40 steps (3 jobs), and checks that
#   - every job of the chain has the user's options (scontrol show job of each job),
#   - every job ends COMPLETED with exit code 0 (the jobcomp/filetxt record of every job),
#   - the chain ends with the stats.nc and particles.nc of an uninterrupted run;
# and a third chain, of a 3-D scene, on 4 ranks (mpirun) as 2 x 2 x-z blocks (CHANSPH_ARGS="--set run.ranks=2,2"),
# stopped after 2 jobs (CHAIN_MAX_JOBS), then continued by a second submission as 4 x 1 slabs
# (the decomposition changed between jobs): it too ends with the uninterrupted run's files.
# The node is declared with 4 CPUs whatever it has (SlurmdParameters=config_overrides), so that
# the 4 ranks fit a 2-core machine.
# Nothing is installed: without slurm-wlm and munge (Debian packages), or when not run as root
# (slurmd must start jobs as their user), the test is skipped with exit 77. jobs/setup.sh does not
# install SLURM; docs/batch-jobs.md says how to run this test.
# usage: slurm_chain.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
here=$(cd "$(dirname "$0")/.." && pwd)
for c in munged mungekey slurmctld slurmd sbatch squeue scontrol sinfo scancel; do
  command -v "$c" > /dev/null || {
    echo "SKIP: $c not found (apt-get install slurm-wlm munge to run this test)"
    exit 77
  }
done
[ "$(id -u)" -eq 0 ] || { echo "SKIP: slurmd needs root"; exit 77; }
for c in slurmctld slurmd; do # a SLURM of the machine's own: leave it alone
  ps -C $c -o stat= 2> /dev/null | grep -qv '^Z' && {
    echo "SKIP: a $c is running on this machine"
    exit 77
  }
done
export CHANSPH_RUN_ID=compare-test OMP_NUM_THREADS=1
d=$(cd "$runs" && pwd)/slurm_chain
rm -rf "$d" && mkdir -p "$d/state" "$d/spool" "$d/log" || exit 1
pids=()
cleanup() {
  scancel --quiet --full --name=chansph-slurm-test-srun,chansph-slurm-test-mpirun 2> /dev/null
  local p
  for p in "${pids[@]}"; do kill "$p" 2> /dev/null; done
  for p in "${pids[@]}"; do wait "$p" 2> /dev/null; done
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; for f in "$d"/log/*.log; do echo "--- $f"; tail -n 15 "$f"; done; exit 1; }

# munge: a key and a socket of our own
mungekey -c -k "$d/munge.key" -b 1024 || fail "mungekey"
chmod 400 "$d/munge.key"
munged -F -f -S "$d/munge.sock" --key-file="$d/munge.key" --log-file="$d/log/munged.log" \
  --pid-file="$d/munged.pid" --seed-file="$d/munge.seed" > /dev/null 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -S "$d/munge.sock" ] && break; sleep 0.1; done
[ -S "$d/munge.sock" ] || fail "munged did not start"

# slurm.conf: this node with its real CPUs and memory (slurmd -C), no cgroups, no accounting
# database; jobcomp/filetxt records the final state of every job
h=$(hostname -s)
node=$(slurmd -C | grep '^NodeName=' | sed -E 's/CPUs=[0-9]+/CPUs=4/; s/SocketsPerBoard=[0-9]+/SocketsPerBoard=1/; s/CoresPerSocket=[0-9]+/CoresPerSocket=4/; s/ThreadsPerCore=[0-9]+/ThreadsPerCore=1/')
cat > "$d/slurm.conf" << EOF
ClusterName=chansphtest
SlurmctldHost=$h
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$d/munge.sock
CredType=cred/munge
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd.log
MpiDefault=pmix
ProctrackType=proctrack/linuxproc
TaskPlugin=task/affinity
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$d/log/jobcomp.txt
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmdParameters=config_overrides
MinJobAge=3600
KillWait=5
$node State=UNKNOWN
PartitionName=chansphtest Nodes=$h Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$d/slurm.conf
slurmctld -D -i -f "$SLURM_CONF" > "$d/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" > "$d/log/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 60); do [ "$(sinfo -h -o %t 2> /dev/null)" = idle ] && break; sleep 0.5; done
[ "$(sinfo -h -o %t 2> /dev/null)" = idle ] || fail "the node did not become idle"
echo "slurm: $(sinfo -h -o '%P %D %c CPUs %m MB %t') ($node)"

# the reference: one uninterrupted run
opts=(--set time.t_end=0.6 --set output.t_average_start=0.2)
ref=$d/ref
"$chansph" run "$scene" --out "$ref" "${opts[@]}" > /dev/null || fail "reference run"
cp "$ref/scene.used.ini" "$d/scene.ini"

# two chains, with the user's options on the command line: launched by srun (Open MPI through
# SLURM's PMIx, MpiDefault=pmix above) and by mpirun (CHAIN_LAUNCH=mpirun)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
status=0
for launch in srun mpirun; do
  run=$d/run_$launch
  name=chansph-slurm-test-$launch
  first=$(cd "$here" && RUN_DIR=$run SCENE=$d/scene.ini CHANSPH=$chansph CHAIN_LAUNCH=$launch \
    CHAIN_SCRIPT=$here/jobs/slurm/chansph.sbatch CHANSPH_ARGS="--max-steps 40" \
    sbatch --parsable --export=ALL --time=15 --cpus-per-task=1 --ntasks=1 \
    --job-name="$name" --output="$d/log/$launch-%j.out" jobs/slurm/chansph.sbatch) ||
    fail "sbatch"
  echo "$launch: submitted job $first"
  ends="chain: .* done after\|chain: chansph exited\|too many failures\|not resubmitting"
  ends+="\|chain: sbatch failed"
  for _ in $(seq 240); do
    grep -q "$ends" "$d"/log/"$launch"-*.out 2> /dev/null &&
      [ -z "$(squeue -h -n "$name")" ] && break
    sleep 0.5
  done
  [ -z "$(squeue -h -n "$name")" ] || fail "the chain did not end within 2 minutes: $(squeue)"
  sleep 1 # the last job's completion record
  jobs=0
  while read -r line; do
    [[ $line == *"Name=$name "* ]] || continue
    jobs=$((jobs + 1))
    id=$(sed -E 's/^JobId=([0-9]+) .*/\1/' <<< "$line")
    state=$(grep -oE 'JobState=[A-Z_]+' <<< "$line")
    code=$(grep -oE ' ExitCode=[0-9:]+' <<< "$line")
    show=$(scontrol show job -o "$id")
    cpt=$(grep -oE 'CPUs/Task=[0-9]+' <<< "$show")
    tl=$(grep -oE 'TimeLimit=[0-9:-]+' <<< "$show")
    echo "  job $id: $state$code $cpt $tl" \
      "$(grep -m1 -oE 'chain job [0-9]+' "$d/log/$launch-$id.out")"
    [ "$state" = JobState=COMPLETED ] && [ "$code" = " ExitCode=0:0" ] || {
      echo "FAIL: job $id did not end COMPLETED with exit code 0"
      status=1
    }
    [ "$cpt" = CPUs/Task=1 ] && [ "$tl" = TimeLimit=00:15:00 ] || {
      echo "FAIL: job $id lost the options of the submission (--cpus-per-task=1 --time=15)"
      status=1
    }
  done < "$d/log/jobcomp.txt"
  [ $jobs -ge 3 ] || { echo "FAIL: $jobs job(s) in the chain, expected at least 3"; status=1; }
  grep -h "chain: .* done after" "$d"/log/"$launch"-*.out || {
    echo "FAIL: no 'done' line"
    status=1
  }
  for f in stats.nc particles.nc; do
    diff <("$here/tests/nc_content.sh" "$ref/$f") <("$here/tests/nc_content.sh" "$run/$f") \
      > /dev/null || { echo "FAIL: $launch: $f differs from the uninterrupted run"; status=1; }
  done
done
# x-z blocks: 4 ranks as 2 x 2 for two jobs, then the chain continued as 4 x 1 slabs, on a 3-D
# scene (les395_smoke in an 18 x 12 pencil box, 120 steps) against its uninterrupted run
ref=$d/ref_blocks
"$chansph" run "$here/jobs/scenes/les395_smoke.ini" --out "$ref" --set domain.lx=2.4 \
  --set domain.lz=1.6 --set time.max_steps=120 > /dev/null || fail "reference run (blocks)"
cp "$ref/scene.used.ini" "$d/scene3.ini"
run=$d/run_blocks
name=chansph-slurm-test-blocks
submit() { # CHANSPH_ARGS, CHAIN_MAX_JOBS
  (cd "$here" && RUN_DIR=$run SCENE=$d/scene3.ini CHANSPH=$chansph CHAIN_LAUNCH=mpirun \
    CHAIN_SCRIPT=$here/jobs/slurm/chansph.sbatch CHANSPH_ARGS="$1" CHAIN_MAX_JOBS=$2 \
    sbatch --parsable --export=ALL --time=15 --cpus-per-task=1 --ntasks=4 \
    --job-name="$name" --output="$d/log/blocks-%j.out" jobs/slurm/chansph.sbatch)
}
wait_chain() {
  for _ in $(seq 480); do
    [ -z "$(squeue -h -n "$name")" ] && return 0
    sleep 0.5
  done
  fail "the blocks chain did not end within 4 minutes: $(squeue)"
}
first=$(submit "--max-steps 40 --set run.ranks=2,2" 2) || fail "sbatch (blocks)"
echo "blocks: submitted job $first (2 x 2, two jobs)"
wait_chain
n22=$(grep -c "^decomposition: 4 MPI ranks as 2 x 2 blocks" "$run/log.txt")
[ "$n22" -ge 2 ] || { echo "FAIL: blocks: $n22 job(s) on 2 x 2 in the log, expected 2"; status=1; }
[ -f "$run/particles.nc" ] && grep -q "done after" "$d"/log/blocks-*.out &&
  { echo "FAIL: blocks: the chain ended within the 2 jobs; nothing left to change"; status=1; }
second=$(submit "--max-steps 40 --set run.ranks=4,1" 100) || fail "sbatch (blocks, second)"
echo "blocks: submitted job $second (4 x 1 slabs, to the end)"
wait_chain
grep -q "^decomposition: 4 MPI ranks as 4 x 1 blocks" "$run/log.txt" ||
  { echo "FAIL: blocks: no job ran as 4 x 1"; status=1; }
grep -h "chain: .* done after" "$d"/log/blocks-*.out ||
  { echo "FAIL: blocks: no 'done' line"; status=1; }
grep -h "^decomposition: 4 MPI ranks" "$run/log.txt" | cut -c1-60 | uniq -c
for f in stats.nc particles.nc; do # all but the scene text, whose run.ranks is 4,1 here
  diff <("$here/tests/nc_content.sh" "$ref/$f" | grep -v ':scene = ') \
    <("$here/tests/nc_content.sh" "$run/$f" | grep -v ':scene = ') > /dev/null ||
    { echo "FAIL: blocks: $f differs from the uninterrupted run"; status=1; }
done
[ $status -eq 0 ] && echo PASS || fail "see above"
exit $status
