#!/usr/bin/env bash
# The SLURM and PBS chain scripts with stand-ins for sbatch/srun/squeue/scontrol and
# qsub/mpirun/qstat (each submission runs the next job at once): a run cut into jobs of 60 steps
# by CHANSPH_ARGS ends with the stats.nc and particles.nc data of an uninterrupted run, every
# resubmission repeats the options of the job (as scontrol show job / qstat -f report them; the
# stand-ins print a user's submission), and every job that resubmitted exits 0. (The stand-ins
# nest the jobs, so only the innermost one ends the run.) tests/slurm_chain.sh runs the SLURM
# chain on a real SLURM.
# usage: batch_chain.sh CHANSPH SCENE RUNS
set -u
# the runs compared here share one identity (issue 13: DIR/run_id, stored in every file)
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3
here=$(cd "$(dirname "$0")/.." && pwd)
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
fake=$runs/batch_fake_bin
rm -rf "$fake" && mkdir -p "$fake"
cat > "$fake/srun" << 'X'
#!/usr/bin/env bash
while [[ $1 == --* ]]; do shift; done
exec "$@"
X
cat > "$fake/mpirun" << 'X'
#!/usr/bin/env bash
echo "mpirun $*" >> "${MPIRUN_LOG:-/dev/null}"
while [[ $1 == -* ]]; do [[ $1 == -np || $1 == --bind-to || $1 == --hostfile ]] && shift; shift; done
exec "$@"
X
printf '#!/usr/bin/env bash\necho "1-00:00:00"\n' > "$fake/squeue"
# scontrol show job -o of a job submitted with sbatch --time=2:00:00 --cpus-per-task=3
# --ntasks=2 -p short --mem=2G --comment="two words" --output=/x/chain-%j.out
cat > "$fake/scontrol" << 'X'
#!/usr/bin/env bash
echo "JobId=$SLURM_JOB_ID JobName=chansph UserId=u(1) GroupId=g(1) MCS_label=N/A Priority=1 Nice=0 Account=(null) QOS=normal JobState=RUNNING Reason=None Dependency=(null) Requeue=1 Restarts=0 BatchFlag=1 Reboot=0 ExitCode=0:0 RunTime=00:00:01 TimeLimit=02:00:00 TimeMin=N/A Partition=short AllocNode:Sid=n:1 ReqNodeList=(null) ExcNodeList=(null) NodeList=n1 BatchHost=n1 NumNodes=1 NumCPUs=6 NumTasks=2 CPUs/Task=3 ReqB:S:C:T=0:0:*:* TRES=cpu=6,mem=2G,node=1 Socks/Node=* NtasksPerN:B:S:C=0:0:*:* CoreSpec=* MinCPUsNode=3 MinMemoryNode=2G MinTmpDiskNode=0 Features=(null) DelayBoot=00:00:00 OverSubscribe=OK Contiguous=0 Licenses=(null) Network=(null) Command=/x/chansph.sbatch WorkDir=/x Comment=two words StdErr=/x/chain-$SLURM_JOB_ID.out StdIn=/dev/null StdOut=/x/chain-$SLURM_JOB_ID.out Power="
X
cat > "$fake/sbatch" << 'X'
#!/usr/bin/env bash
for a in "$@"; do case $a in --export=*) IFS=, read -r -a kv <<< "${a#--export=}";
  for x in "${kv[@]}"; do [[ $x == *=* ]] && export "${x?}"; done ;; esac; done
{ printf 'sbatch:' && printf ' [%s]' "${@:1:$#-2}" && echo; } >> "$RUN_DIR.jobs"
SLURM_JOB_ID=$((SLURM_JOB_ID + 1)) bash "${@: -1}"
X
# qstat -f of a job submitted with qsub -l select=2:ncpus=8:mpiprocs=2:ompthreads=4
# -l walltime=01:30:00 -q short -A proj -m abe -M u@x (a long value wraps with a tab)
cat > "$fake/qstat" << 'X'
#!/usr/bin/env bash
printf 'Job Id: %s\n' "$PBS_JOBID"
printf '    %s\n' "Job_Name = chansph" "Job_Owner = u@host" "job_state = R" "queue = short" \
  "Account_Name = proj" "Resource_List.mpiprocs = 4" "Resource_List.ncpus = 16" \
  "Resource_List.nodect = 2" "Resource_List.place = scatter" \
  "Resource_List.select = 2:ncpus=8:mpiprocs=2:ompthr"
printf '\teads=4\n'
printf '    %s\n' "Resource_List.walltime = 01:30:00" "Mail_Points = abe" "Mail_Users = u@x" \
  "project = _pbs_project_default"
echo
X
cat > "$fake/qsub" << 'X'
#!/usr/bin/env bash
args=("$@")
for ((i = 0; i < $# - 1; i++)); do
  [ "${args[i]}" = -v ] && { IFS=, read -r -a kv <<< "${args[i + 1]}";
    for x in "${kv[@]}"; do export "${x?}"; done; }
done
{ printf 'qsub:' && printf ' [%s]' "${@:1:$#-3}" && echo " WALLTIME=$WALLTIME"
  echo "${@: -2:1}" | tr , '\n' | grep -q '^CHANSPH_ARGS=--max-steps 60$' ||
    echo "qsub -v does not pass CHANSPH_ARGS"; } >> "$RUN_DIR.jobs"
PBS_JOBID=$((${PBS_JOBID%%.*} + 1)).server bash "${@: -1}"
X
chmod +x "$fake"/*
opts=(--set time.t_end=0.6 --set output.t_average_start=0.2)
ref=$runs/batch_ref
rm -rf "$ref"
"$chansph" run "$scene" --out "$ref" "${opts[@]}" > /dev/null || { echo "FAIL: reference"; exit 1; }
cp "$ref/scene.used.ini" "$runs/batch_scene.ini"
status=0
for kind in slurm pbs; do
  d=$runs/batch_$kind
  rm -rf "$d" "$d.jobs" "$d.mpirun"
  script=$here/jobs/$kind/chansph.$([ $kind = slurm ] && echo sbatch || echo pbs)
  # PBS: the node file of select=2:ncpus=8:mpiprocs=2 (2 nodes, 2 MPI processes each)
  printf 'n1\nn1\nn2\nn2\n' > "$runs/batch_nodefile"
  (cd "$here" && PATH=$fake:$PATH RUN_DIR=$d SCENE=$runs/batch_scene.ini CHANSPH=$chansph \
    CHAIN_SCRIPT=$script CHANSPH_ARGS="--max-steps 60" SLURM_JOB_ID=100 PBS_JOBID=100.server \
    PBS_NODEFILE=$runs/batch_nodefile MPIRUN_LOG=$d.mpirun bash "$script" > "$d.log" 2>&1)
  rc=$?
  jobs=$(($(cat "$d.jobs" 2> /dev/null | wc -l) + 1))
  done_line=$(grep 'chain: .* done after' "$d.log")
  echo "$kind: $jobs jobs, first job exit status $rc; ${done_line:-no 'done' line}"
  [ -n "$done_line" ] && [ $jobs -ge 2 ] && [ $rc -eq 0 ] || { echo "FAIL: $kind chain"; status=1; }
  if [ $kind = slurm ]; then
    want="sbatch: [--job-name=chansph] [--partition=short] [--qos=normal] [--time=02:00:00]"
    want+=" [--nodes=1] [--ntasks=2] [--cpus-per-task=3] [--mem=2G] [--comment=two words]"
    want+=" [--chdir=/x] [--output=/x/chain-%j.out]"
  else
    want="qsub: [-N] [chansph] [-q] [short] [-A] [proj] [-m] [abe] [-M] [u@x]"
    want+=" [-l] [select=2:ncpus=8:mpiprocs=2:ompthreads=4] [-l] [place=scatter]"
    want+=" [-l] [walltime=01:30:00] WALLTIME=01:30:00"
  fi
  while read -r line; do
    [ "$line" = "$want" ] || {
      printf 'FAIL: %s resubmitted with\n  %s\nnot\n  %s\n' $kind "$line" "$want"
      status=1
    }
  done < "$d.jobs"
  head -n 1 "$d.jobs"
  if [ $kind = pbs ]; then # the ranks and nodes of the allocation reach mpirun
    grep -q -- "^mpirun -np 4 --hostfile $runs/batch_nodefile --bind-to none " "$d.mpirun" ||
      { echo "FAIL: pbs: mpirun not started with the node file's 4 ranks:"; head -n 2 "$d.mpirun"; status=1; }
    head -n 1 "$d.mpirun" | cut -c1-80
  fi
  for f in stats.nc particles.nc; do
    diff <("$(dirname "$0")/nc_content.sh" "$ref/$f") <("$(dirname "$0")/nc_content.sh" "$d/$f") \
      > /dev/null || { echo "FAIL: $kind $f differs"; status=1; }
  done
done
[ $status -eq 0 ] && echo PASS
exit $status
