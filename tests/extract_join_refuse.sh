#!/usr/bin/env bash
# chansph extract joins only one run's continuation, and --nc never replaces what it reads
# (issue 42 points 1, 2 and 8). Each refusal is exit 1 with a message naming the file and the
# reason, and leaves no output:
#   the same file twice or a copy of it; segments out of order; two continuations of one state
#   (overlapping in time); a run from the scene's initial condition; another body force;
#   another dimension; a joined file and a segment it holds; a segment without the record of
#   the state it started from (joined only with --force); --nc OUT that is an input (by inode:
#   also a hard link; with --window too), a run's particles.nc or a run's own stats.nc; 65
#   files (the limit named); a segment without the momentum-budget records (the message says
#   which file lacks them).
# And what is one run joins: A B C, and the joined A B followed by C, with the same windows.
# usage: extract_join_refuse.sh CHANSPH SCENE STATS_RUN WORK
#   STATS_RUN: the shared small run (SCENE to t = 1, averaging from 0.2 in windows of 0.1)
set -u
chansph=$1 scene=$2 run=$3 work=$4
rm -rf "$work"
mkdir -p "$work"
seg() { # seg DIR FROM [KEY=VALUE ...]: a segment of 0.2 s from FROM's final state ("" = rest)
  local dir=$1 from=$2
  shift 2
  local set=(--set time.t_end=0.2 --set output.t_average_start=0 --set stats.window=0.1)
  [ -n "$from" ] && set+=(--set init.from="$from")
  for kv in "$@"; do set+=(--set "$kv"); done
  "$chansph" run "$scene" --out "$dir" --overwrite "${set[@]}" > "$dir.log" 2>&1 ||
    { tail -3 "$dir.log"; echo "FAIL: the segment run $dir"; exit 1; }
}
a=$run/stats.nc
seg "$work/b" "$run/particles.nc"
seg "$work/c" "$work/b/particles.nc"
seg "$work/b2" "$run/particles.nc"
seg "$work/f" "$run/particles.nc" drive.force=1.6
seg "$work/r" ""
b=$work/b/stats.nc c=$work/c/stats.nc out=$work/out.nc
fails=0
refused() { # refused REGEX ARGS...: extract ARGS exits 1 with a message matching REGEX, no $out
  # (with keep=1: $out is an existing file, checked unchanged below, not removed)
  local re=$1
  shift
  [ "${keep:-0}" = 1 ] || rm -f "$out"
  local msg rc
  msg=$("$chansph" extract "$@" 2>&1)
  rc=$?
  if [ $rc -eq 1 ] && echo "$msg" | grep -q -- "$re" && { [ "${keep:-0}" = 1 ] || [ ! -e "$out" ]; }; then
    echo "ok (refused): ${msg%%$'\n'*}"
  else
    echo "FAIL: extract $* gave exit $rc, output $([ -e "$out" ] && echo kept || echo none):"
    echo "$msg" | head -3
    fails=$((fails + 1))
  fi
}
cp "$a" "$work/a_copy.nc"
refused "error: $a: holds the statistics of run .*the same file twice" "$a" "$a" --nc "$out"
refused "error: $work/a_copy.nc: holds the statistics of run" "$a" "$work/a_copy.nc" --nc "$out"
refused "error: $a: started from the scene's initial condition" "$b" "$a" --nc "$out"
refused "error: $c: started from the state of run .*not its continuation" "$a" "$c" "$b" --nc "$out"
refused "error: $work/b2/stats.nc: started from .*overlap in time" "$a" "$b" "$work/b2/stats.nc" --nc "$out"
refused "error: $work/r/stats.nc: started from the scene's initial condition" "$a" "$work/r/stats.nc" --nc "$out"
refused "error: $work/f/stats.nc: body_force 1.6, but $a has 0.8: not the same flow" "$a" "$work/f/stats.nc" --nc "$out"
# (nccopy: a stats.nc is written from memory, which the netCDF library does not reopen to edit)
nccopy "$b" "$work/b_3d.nc" && ncatted -h -a dimension,global,o,l,3 "$work/b_3d.nc"
refused "error: $work/b_3d.nc: dimension 3, but $a has 2" "$a" "$work/b_3d.nc" --nc "$out"
# a table too (no --nc): the same checks
refused "holds the statistics of run" "$a" "$a"
"$chansph" extract "$a" "$b" --nc "$work/ab.nc" > /dev/null || { echo "FAIL: A B"; exit 1; }
refused "error: $b: holds the statistics of run .*segment a joined file holds" "$work/ab.nc" "$b" --nc "$out"
refused "error: $work/ab.nc: holds the statistics of run" "$a" "$work/ab.nc" --nc "$out"
# one run: A B C, and (A B) C, the same windows
"$chansph" extract "$a" "$b" "$c" --nc "$work/abc.nc" > /dev/null || { echo "FAIL: A B C refused"; exit 1; }
"$chansph" extract "$work/ab.nc" "$c" --nc "$work/ab_c.nc" > /dev/null || { echo "FAIL: (A B) C refused"; exit 1; }
/usr/bin/python3 - "$work/abc.nc" "$work/ab_c.nc" << 'PY' || fails=$((fails + 1))
import sys
import netCDF4
import numpy as np
x, y = (netCDF4.Dataset(p) for p in sys.argv[1:3])
same = all(np.array_equal(x["eulerian"][v][:], y["eulerian"][v][:]) for v in ("windows", "moments"))
print(f"A B C and (A B) C: {x['eulerian']['windows'].shape[0]} rows, same: {same}; "
      f"segment_run_ids {x.segment_run_ids == y.segment_run_ids}")
sys.exit(0 if same and x.segment_run_ids == y.segment_run_ids else "FAIL: (A B) C is not A B C")
PY
# a segment of an earlier version: no record of its start; joined with --force only
nccopy "$b" "$work/b_old.nc" && ncatted -h -a init_from_run_id,global,d,, -a init_from_time,global,d,, "$work/b_old.nc"
refused "error: $work/b_old.nc: does not record the state it started from.*--force" "$a" "$work/b_old.nc" --nc "$out"
"$chansph" extract "$a" "$work/b_old.nc" --nc "$out" --force > /dev/null && [ -e "$out" ] ||
  { echo "FAIL: --force did not join a segment without its start"; fails=$((fails + 1)); }
refused "error: $work/b_old.nc: holds the statistics of run" "$a" "$b" "$work/b_old.nc" --force --nc "$out"
refused "body_force 1.6" "$a" "$work/f/stats.nc" --force --nc "$out"
# point 8: which file lacks the budget records
ncks -h -O -x -v /eulerian/planes "$b" "$work/b_noplanes.nc" 2> /dev/null
refused "error: $work/b_noplanes.nc: lacks the momentum-budget records (planes), but $a holds them" "$a" "$work/b_noplanes.nc" --nc "$out"
# point 8: 65 files name the limit
many=()
for k in $(seq 65); do many+=("$a"); done
refused "more than 64 files: extract joins at most 64 segments" "${many[@]}" --nc "$out"
# point 2: --nc never replaces an input or a run's file
sum() { md5sum "$@" | cut -d' ' -f1 | tr '\n' ' '; }
before=$(sum "$a" "$b" "$run/particles.nc")
ln "$a" "$work/a_link.nc"
keep=1 refused "error: --nc $a is the input $a (the same file)" "$a" --nc "$a"
keep=1 refused "error: --nc $a is the input $a" "$a" --window 0.3:0.6 --nc "$a"
keep=1 refused "error: --nc $b is the input $b" "$a" "$b" --nc "$b"
keep=1 refused "error: --nc $work/a_link.nc is the input $a" "$a" --nc "$work/a_link.nc"
keep=1 refused "error: --nc $run/particles.nc exists and is a run's particle state" "$a" --nc "$run/particles.nc"
keep=1 refused "error: --nc $b exists and is a run's own stats.nc" "$a" --nc "$b"
[ "$(sum "$a" "$b" "$run/particles.nc")" = "$before" ] || { echo "FAIL: an input changed"; fails=$((fails + 1)); }
[ -e "$a.tmp" ] || [ -e "$b.tmp" ] && { echo "FAIL: a temporary file left"; fails=$((fails + 1)); }
# an earlier output of extract is replaced
"$chansph" extract "$a" --window 0.3:0.6 --nc "$work/ab.nc" > /dev/null || { echo "FAIL: an earlier output not replaced"; fails=$((fails + 1)); }
[ $fails -eq 0 ] || { echo "FAIL: $fails checks"; exit 1; }
echo "PASS: extract joins one run's continuation only, and never replaces what it reads"
