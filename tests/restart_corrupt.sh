#!/usr/bin/env bash
# Acceptance 4 of issue 4: a truncated checkpoint, one with flipped bytes, a missing one, one of a
# future format version and an incomplete one each give a clear message; resume falls back to the
# previous valid checkpoint and ends with the results of an uninterrupted run; nothing is deleted
# (skipped files are renamed *.skipped). Also: forbidden and accepted scene changes on resume.
# usage: restart_corrupt.sh CHANSPH H5_SET_ATTR SCENE RUNS
set -u
# the runs compared here share one identity (issue 13: DIR/run_id, stored in every file)
export CHANSPH_RUN_ID=compare-test
chansph=$1 setattr=$2 scene=$3 runs=$4
base=$runs/corrupt_base
opts=(--set time.t_end=1 --set output.t_average_start=0.5 --set checkpoint.every_steps=50
      --set checkpoint.keep=10)
rm -rf "$base"
"$chansph" run "$scene" --out "$base" "${opts[@]}" > /dev/null || { echo "FAIL: base run"; exit 1; }
newest=ckpt_0000000193.h5 prev=ckpt_0000000150.h5
status=0
fail() { echo "FAIL: $*"; status=1; }

# case NAME EXPECTED_EXIT REGEX [command to damage the copy, run in DIR/checkpoints]
case_() {
  local name=$1 want=$2 regex=$3 damage=$4
  local d=$runs/corrupt_$name
  rm -rf "$d" && cp -a "$base" "$d" && rm -f "$d/stats.nc" "$d/particles.nc"
  (cd "$d/checkpoints" && eval "$damage")
  local before
  before=$(cd "$d/checkpoints" && ls | sort)
  out=$("$chansph" resume "$d" 2>&1)
  rc=$?
  echo "$out" | grep -E "warning|error" | head -n 3
  [ $rc -eq "$want" ] || fail "$name: exit status $rc, expected $want"
  echo "$out" | grep -Eq -- "$regex" || fail "$name: no message matching: $regex"
  for f in $before; do # every file is still there, perhaps renamed *.skipped
    [ -e "$d/checkpoints/$f" ] || [ -L "$d/checkpoints/$f" ] || [ -e "$d/checkpoints/$f.skipped" ] ||
      [ -L "$d/checkpoints/$f.skipped" ] || fail "$name: $f was deleted"
  done
  if [ "$want" -eq 0 ]; then
    grep -q "resume: from .*$prev" "$d/log.txt" || fail "$name: did not fall back to $prev"
    for f in stats.nc particles.nc; do
      diff <("$(dirname "$0")/nc_content.sh" "$base/$f") <("$(dirname "$0")/nc_content.sh" "$d/$f") \
        > /dev/null || fail "$name: $f differs from the uninterrupted run"
    done
  fi
  [ $status -eq 0 ] && echo "$name: ok"
}

case_ truncated 0 "$newest: cannot open as HDF5 \(truncated or corrupt\) \(HDF5: truncated file" \
  "truncate -s 60000 $newest"
case_ flipped 0 "$newest: cannot read dataset /particles/x \(checksum mismatch or corrupt data\) \(HDF5: data error detected by Fletcher32 checksum\)" \
  "h5dump -d /particles/x -b LE -o x.bin $newest > /dev/null && python3 -c \"
b = bytearray(open('$newest', 'rb').read()); x = open('x.bin', 'rb').read()
o = b.find(x[:64]); assert o > 0
for k in range(o + 200, o + 204): b[k] ^= 0x5a
open('$newest', 'wb').write(b)\" && rm x.bin"
case_ missing 0 "ckpt_0000000194.h5: cannot open checkpoint: No such file or directory" \
  "ln -s gone.h5 ckpt_0000000194.h5 && mv $newest ../moved_away.h5"
case_ future_version 0 "$newest: written in checkpoint format 2\.[0-9]+ by a newer chansph; this build \(.*\) reads format 1.x only" \
  "$setattr $newest format_version_major 2 > /dev/null"
case_ incomplete 0 "$newest: incomplete checkpoint \(no completion mark 'complete' = 1\)" \
  "$setattr $newest complete 0 > /dev/null"
# issue 13, point 8: a metadata checksum failure is named as such, not "not a chansph checkpoint"
case_ metadata 0 "$newest: cannot read the root group's attributes \(metadata checksum mismatch or corrupt file\) \(HDF5: incorrect metadata checksum" \
  "python3 -c \"
b = bytearray(open('$newest', 'rb').read()); o = b.find(b'chansph-checkpoint'); assert o > 0
b[o + 3] ^= 0x20; open('$newest', 'wb').write(b)\""
case_ none_valid 1 "none of the 1 checkpoint\(s\) is valid \(see above\); nothing was deleted" \
  "rm ckpt_0000000050.h5 ckpt_0000000100.h5 $prev && truncate -s 1000 $newest"
case_ no_checkpoint 1 "checkpoints: no checkpoint to resume from" "rm ckpt_*.h5"

# scene changes on resume: the domain is refused (named), the end time accepted and logged
d=$runs/corrupt_changes
rm -rf "$d" && cp -a "$base" "$d"
out=$("$chansph" resume "$d" --set domain.dr=0.025 2>&1)
rc=$?
echo "$out" | head -n 1
[ $rc -eq 1 ] && echo "$out" | grep -q "key 'domain.dr' cannot change on resume" ||
  fail "changes: domain.dr accepted (exit $rc)"
"$chansph" resume "$d" --set time.t_end=1.2 > /dev/null || fail "changes: t_end refused"
grep -q "resume: time.t_end changed from 1 to 1.2" "$d/log.txt" || fail "changes: not logged"
grep -q "t_end = 1.2" "$d/scene.used.ini" || fail "changes: scene.used.ini not updated"
[ $status -eq 0 ] && echo PASS
exit $status
