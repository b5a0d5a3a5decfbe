#!/usr/bin/env bash
# The SLURM and PBS chain scripts with stand-ins for sbatch/srun/squeue and qsub/mpirun (each
# submission runs the next job at once): a run cut into jobs of 60 steps by CHANSPH_ARGS ends
# with the stats.nc and particles.nc data of an uninterrupted run. (The stand-ins nest the jobs,
# so only the innermost one ends the run.)
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
while [[ $1 == -* ]]; do [[ $1 == -np || $1 == --bind-to ]] && shift; shift; done
exec "$@"
X
printf '#!/usr/bin/env bash\necho "1-00:00:00"\n' > "$fake/squeue"
cat > "$fake/sbatch" << 'X'
#!/usr/bin/env bash
for a in "$@"; do case $a in --export=*) IFS=, read -r -a kv <<< "${a#--export=}";
  for x in "${kv[@]}"; do [[ $x == *=* ]] && export "${x?}"; done ;; esac; done
echo "sbatch: next job" >> "$RUN_DIR.jobs"
bash "${@: -1}"
X
cat > "$fake/qsub" << 'X'
#!/usr/bin/env bash
[ "$1" = -v ] && { IFS=, read -r -a kv <<< "$2"; for x in "${kv[@]}"; do export "${x?}"; done; }
echo "qsub: next job" >> "$RUN_DIR.jobs"
bash "${@: -1}"
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
  rm -rf "$d" "$d.jobs"
  script=$here/jobs/$kind/chansph.$([ $kind = slurm ] && echo sbatch || echo pbs)
  (cd "$here" && PATH=$fake:$PATH RUN_DIR=$d SCENE=$runs/batch_scene.ini CHANSPH=$chansph \
    CHAIN_SCRIPT=$script CHANSPH_ARGS="--max-steps 60" bash "$script" > "$d.log" 2>&1)
  jobs=$(($(cat "$d.jobs" 2> /dev/null | wc -l) + 1))
  done_line=$(grep 'chain: .* done after' "$d.log")
  echo "$kind: $jobs jobs; ${done_line:-no 'done' line}"
  [ -n "$done_line" ] && [ $jobs -ge 2 ] || { echo "FAIL: $kind chain"; status=1; }
  for f in stats.nc particles.nc; do
    diff <("$(dirname "$0")/nc_content.sh" "$ref/$f") <("$(dirname "$0")/nc_content.sh" "$d/$f") \
      > /dev/null || { echo "FAIL: $kind $f differs"; status=1; }
  done
done
[ $status -eq 0 ] && echo PASS
exit $status
