#!/usr/bin/env bash
# Run a chansph run to its end on a workstation, resuming it whenever it stops early: the same
# logic as the SLURM and PBS chains (docs/batch-jobs.md).
#
# usage: jobs/chain.sh DIR [SCENE.ini] [-- extra chansph arguments, e.g. --max-steps 1000]
#   DIR has checkpoints  -> chansph resume DIR
#   otherwise            -> chansph run SCENE.ini (or DIR/scene.used.ini) --out DIR --overwrite
# Exit codes of chansph: 0 done (the chain ends, 0); 75 checkpointed, resume at once; 1 input
# error, 2 internal error, 3 numerical failure, 74 cannot write: the chain stops with that code
# (a person must look). Anything else (killed by a signal, node failure) is retried from the
# newest checkpoint, at most CHAIN_MAX_FAILS times in a row without progress (default 3).
# Environment: CHANSPH (default: build/chansph of this repository), CHAIN_MAX_FAILS,
# CHAIN_MAX_JOBS (default 10000), CHAIN_PAUSE (seconds between retries after a failure, 1).
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
chansph=${CHANSPH:-$here/build/chansph}
max_fails=${CHAIN_MAX_FAILS:-3}
max_jobs=${CHAIN_MAX_JOBS:-10000}
pause=${CHAIN_PAUSE:-1}
[ $# -ge 1 ] || { sed -n '2,15p' "$0"; exit 1; }
dir=$1
shift
scene=""
if [ $# -ge 1 ] && [ "$1" != "--" ]; then scene=$1; shift; fi
[ $# -ge 1 ] && [ "$1" = "--" ] && shift
extra=("$@")

newest() { ls "$dir/checkpoints" 2> /dev/null | grep -E '^ckpt_[0-9]+\.h5$' | tail -n 1; }

fails=0
for ((job = 1; job <= max_jobs; job++)); do
  before=$(newest)
  if [ -n "$before" ]; then
    cmd=(resume "$dir")
  elif [ -n "$scene" ]; then
    cmd=(run "$scene" --out "$dir" --overwrite)
  elif [ -f "$dir/scene.used.ini" ]; then
    cmd=(run "$dir/scene.used.ini" --out "$dir" --overwrite)
  else
    echo "chain: $dir has no checkpoint and no scene; give SCENE.ini" >&2
    exit 1
  fi
  echo "chain: job $job: $chansph ${cmd[*]} ${extra[*]}"
  "$chansph" "${cmd[@]}" "${extra[@]}"
  rc=$?
  case $rc in
    0)
      echo "chain: done after $job job(s)"
      exit 0
      ;;
    75)
      fails=0
      if grep "^stopped at step" "$dir/log.txt" 2> /dev/null | tail -n 1 | grep -q "(STOP file)"; then
        echo "chain: stopped by $dir/STOP; continue with: $0 $dir"
        exit 75
      fi
      ;;
    1 | 2 | 3 | 74)
      echo "chain: chansph exited with $rc (see docs/batch-jobs.md); stopping the chain" >&2
      exit $rc
      ;;
    *)
      [ "$(newest)" != "$before" ] && fails=0
      fails=$((fails + 1))
      echo "chain: chansph ended with $rc (killed?); failure $fails of $max_fails" >&2
      [ $fails -ge "$max_fails" ] && { echo "chain: too many failures, stopping" >&2; exit $rc; }
      sleep "$pause"
      ;;
  esac
done
echo "chain: $max_jobs jobs and not done; stopping" >&2
exit 75
