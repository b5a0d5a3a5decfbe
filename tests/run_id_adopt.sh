#!/usr/bin/env bash
# Issue 26, point 4: a run directory whose run_id file is missing takes the identity of its
# checkpoints only when they all agree. With a checkpoint of another run among them (here the
# newest), resume exits 1 naming both identities and changes nothing: scene.used.ini stays the
# run's, every checkpoint stays (54d8750 took the newest checkpoint's identity, resumed the
# other run there and its rotation deleted the run's own checkpoints). Once the identity is
# restored, resume skips the other run's checkpoint.
# usage: run_id_adopt.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
unset CHANSPH_RUN_ID
status=0
fail() { echo "FAIL: $*"; status=1; }
a=$runs/id_adopt_a b=$runs/id_adopt_b
rm -rf "$a" "$b"
"$chansph" run "$scene" --out "$a" --set time.t_end=0.1 --set output.t_average_start=0 \
  --set checkpoint.every_steps=5 > /dev/null || fail "run a"
"$chansph" run "$scene" --out "$b" --set time.max_steps=30 --set output.t_average_start=0 \
  --set fluid.nu=0.2 > /dev/null || fail "run b"
ida=$(cat "$a/run_id") idb=$(cat "$b/run_id")
cp "$b/checkpoints/ckpt_0000000030.h5" "$a/checkpoints/"
rm "$a/run_id"
before=$(ls "$a/checkpoints")
out=$("$chansph" resume "$a" --set time.t_end=0.3 --set checkpoint.keep=1 2>&1)
rc=$?
echo "$out" | tail -n 2
[ $rc -eq 1 ] || fail "resume with the checkpoints of two runs and no run_id: exit $rc, expected 1"
echo "$out" | grep -q "run_id is missing and the checkpoints are of two runs .*run_id $idb.*run_id $ida" ||
  fail "no message naming both identities"
grep -q "^nu = 0.1$" "$a/scene.used.ini" || fail "scene.used.ini is no longer a's"
[ "$(ls "$a/checkpoints")" = "$before" ] || fail "the checkpoints changed: $(ls "$a/checkpoints")"
[ -e "$a/run_id" ] && fail "a/run_id was written: $(cat "$a/run_id")"
# the identity restored by hand: resume skips b's checkpoint and continues a
echo "$ida" > "$a/run_id"
out=$("$chansph" resume "$a" --set time.t_end=0.15 2>&1) || fail "resume with run_id restored"
echo "$out" | grep -q "resume: skipped .*ckpt_0000000030.h5 .*a checkpoint of another run" ||
  fail "b's checkpoint was not skipped"
[ $status -eq 0 ] && echo PASS
exit $status
