#!/usr/bin/env bash
# Acceptance 1 of issue 4: a run of the whole length and a run cut into three jobs
# (run --max-steps N1, resume --max-steps N2, resume to the end) give bitwise identical
# stats.nc and particles.nc data and identical final checkpoints (h5diff, and cmp of the files).
# usage: restart_bitwise.sh CHANSPH SCENE RUNS NAME N1 N2 [--set k=v ...]
set -u
# the runs compared here share one identity (issue 13: DIR/run_id, stored in every file)
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3 name=$4 n1=$5 n2=$6
shift 6
full=$runs/bitwise_${name}_full part=$runs/bitwise_${name}_part
rm -rf "$full" "$part"
"$chansph" run "$scene" --out "$full" "$@" > /dev/null || { echo "FAIL: full run"; exit 1; }
"$chansph" run "$scene" --out "$part" --max-steps "$n1" "$@" > /dev/null
rc=$?
[ $rc -eq 75 ] || { echo "FAIL: run --max-steps $n1 exited $rc, expected 75"; exit 1; }
"$chansph" resume "$part" --max-steps "$n2" > /dev/null
rc=$?
[ $rc -eq 75 ] || { echo "FAIL: resume --max-steps $n2 exited $rc, expected 75"; exit 1; }
"$chansph" resume "$part" > /dev/null || { echo "FAIL: final resume"; exit 1; }
status=0
for f in stats.nc particles.nc; do
  if diff <("$(dirname "$0")/nc_content.sh" "$full/$f") <("$(dirname "$0")/nc_content.sh" "$part/$f") \
    > /dev/null; then
    echo "$name $f: data identical"
  else
    echo "$name $f: DIFFERENT"; status=1
  fi
done
if [ -d "$full/snapshots" ]; then
  snaps=$(cd "$full/snapshots" && ls snap_*.h5)
  [ "$snaps" = "$(cd "$part/snapshots" && ls snap_*.h5)" ] || { echo "$name snapshots: DIFFERENT files"; status=1; }
  for s in $snaps; do
    h5diff "$full/snapshots/$s" "$part/snapshots/$s" > /dev/null || { echo "$name $s: DIFFERENT"; status=1; }
  done
  echo "$name snapshots: $(echo $snaps | wc -w) files compared"
fi
last=$(cd "$full/checkpoints" && ls ckpt_*.h5 | tail -n 1)
if h5diff "$full/checkpoints/$last" "$part/checkpoints/$last" > /dev/null; then
  echo "$name $last: h5diff finds no difference"
else
  echo "$name $last: h5diff DIFFERENT"; status=1
fi
cmp -s "$full/checkpoints/$last" "$part/checkpoints/$last" && echo "$name $last: files identical"
steps=${last#ckpt_}; steps=$((10#${steps%.h5}))
echo "$name: cut at steps $n1 and $((n1 + n2)) of $steps"
[ $status -eq 0 ] && echo PASS
exit $status
