# shellcheck shell=bash
# Shared by the campaign scripts (jobs/ab24.sh, jobs/les24.sh, jobs/ab39.sh); source it.

# campaign_run DIR SCENE LABEL [chansph arguments...]: run DIR as a batch job through
# jobs/chain.sh (it resumes from DIR's newest checkpoint), unless DIR's run has finished; the
# chain's output goes to DIR.log, and a run that stops on an error is named.
campaign_run() {
  local dir=$1 scene=$2 label=$3
  shift 3
  grep -q "^finished" "$dir/log.txt" 2> /dev/null && return 0
  jobs/chain.sh "$dir" "$scene" -- "$@" > "$dir.log" 2>&1 ||
    echo "$label: the run stopped: $(grep -m1 -E '^error|through' "$dir.log")"
}

# campaign_finished RUN...: print the runs that have finished, one per line.
campaign_finished() {
  local r
  for r in "$@"; do grep -q "^finished" "$r/log.txt" 2> /dev/null && echo "$r"; done
  return 0
}

# campaign_candidates SETS OUTDIR SUFFIX SCENE NAME... -- [chansph arguments...]: run each
# candidate NAME (a key of the associative array named SETS, whose value is its --set words)
# as DIR = OUTDIR/NAME_SUFFIX with the common arguments after --, through campaign_run; the
# directories go to the array campaign_runs. An unknown name is refused before anything runs.
campaign_candidates() {
  local -n sets_=$1
  local out=$2 suffix=$3 scene=$4 name names=()
  shift 4
  while [ $# -gt 0 ] && [ "$1" != -- ]; do names+=("$1") && shift; done
  [ $# -gt 0 ] && shift
  for name in "${names[@]}"; do
    [ -n "${sets_[$name]+x}" ] ||
      { echo "error: unknown candidate '$name' (${!sets_[*]})" >&2 && return 1; }
  done
  mkdir -p "$out"
  campaign_runs=()
  for name in "${names[@]}"; do
    campaign_runs+=("$out/${name}_$suffix")
    # shellcheck disable=SC2086
    campaign_run "$out/${name}_$suffix" "$scene" "$name ($suffix)" "$@" ${sets_[$name]}
  done
}
