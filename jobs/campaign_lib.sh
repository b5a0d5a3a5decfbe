# Shared by the campaign scripts of issue 24 (jobs/ab24.sh, jobs/les24.sh); source it.

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
