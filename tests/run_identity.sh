#!/usr/bin/env bash
# Issue 13, point 3: every run has an identity (DIR/run_id, created at the first start), stored
# in every checkpoint (root attribute run_id) and in stats.nc and particles.nc; resume skips,
# with a message, a checkpoint of another run and one whose file name disagrees with the step
# stored inside (both renamed *.skipped, nothing deleted), and resumes from the run's own.
# usage: run_identity.sh CHANSPH SCENES RUNS
set -u
chansph=$1 scenes=$2 runs=$3
unset CHANSPH_RUN_ID
status=0
fail() { echo "FAIL: $*"; status=1; }
a=$runs/identity_a b=$runs/identity_b
rm -rf "$a" "$b"
"$chansph" run "$scenes/poiseuille2d.ini" --out "$a" --set time.t_end=0.1 \
  --set output.t_average_start=0 --set checkpoint.every_steps=5 > /dev/null || fail "run a"
"$chansph" run "$scenes/poiseuille3d.ini" --out "$b" --set time.max_steps=30 \
  --set output.t_average_start=0 > /dev/null || fail "run b"
ida=$(cat "$a/run_id") idb=$(cat "$b/run_id")
echo "run a: $ida; run b: $idb"
echo "$ida" | grep -Eq '^[0-9a-f]{8}-[0-9a-f]{4}-4[0-9a-f]{3}-[89ab][0-9a-f]{3}-[0-9a-f]{12}$' ||
  fail "a/run_id is not a UUID: $ida"
[ "$ida" != "$idb" ] || fail "two runs have the same identity"
for f in stats.nc particles.nc; do
  ncdump -h "$a/$f" | grep -q ":run_id = \"$ida\"" || fail "$f has no run_id attribute $ida"
done
for ck in "$a"/checkpoints/ckpt_*.h5; do
  h5dump -a /run_id "$ck" | grep -q "\"$ida\"" || fail "$ck has no root attribute run_id $ida"
done
# a checkpoint of the 3-D run, and one of a's own under the name of another step
cp "$b/checkpoints/ckpt_0000000030.h5" "$a/checkpoints/ckpt_0000000030.h5"
cp "$a/checkpoints/ckpt_0000000010.h5" "$a/checkpoints/ckpt_0000000500.h5"
out=$("$chansph" resume "$a" --set time.t_end=0.15 2>&1)
rc=$?
echo "$out" | grep -E "^resume: (from|skipped)"
[ $rc -eq 0 ] || fail "resume: exit status $rc, expected 0"
echo "$out" | grep -q "resume: skipped .*ckpt_0000000500.h5 (renamed \*.skipped): .*the file name says step 500 but the checkpoint holds step 10" ||
  fail "the misnamed checkpoint was not skipped with a message"
echo "$out" | grep -q "resume: skipped .*ckpt_0000000030.h5 (renamed \*.skipped): .*a checkpoint of another run (run_id $idb; this directory's run is $ida" ||
  fail "the checkpoint of another run was not skipped with a message"
echo "$out" | grep -q "resume: from .*ckpt_0000000020.h5" || fail "not resumed from a's step 20"
[ -e "$a/checkpoints/ckpt_0000000030.h5.skipped" ] && [ -e "$a/checkpoints/ckpt_0000000500.h5.skipped" ] ||
  fail "the skipped files were not kept as *.skipped"
grep -q "^dimension = 2" "$a/scene.used.ini" || fail "scene.used.ini is no longer a's 2-D scene"
ncdump -h "$a/stats.nc" | grep -q ":run_id = \"$ida\"" || fail "stats.nc after resume: run_id"
[ "$(cat "$a/run_id")" = "$ida" ] || fail "a/run_id changed"
# a directory without run_id (a run started before identities existed) takes the checkpoint's
rm "$a/run_id"
"$chansph" resume "$a" --set time.t_end=0.2 > /dev/null 2>&1 || fail "resume without run_id"
[ "$(cat "$a/run_id" 2> /dev/null)" = "$ida" ] || fail "run_id not restored from the checkpoint"
# CHANSPH_RUN_ID names a new run (tests comparing two runs' files byte for byte use it)
CHANSPH_RUN_ID=bad/id "$chansph" run "$scenes/poiseuille2d.ini" --out "$b" --overwrite \
  --set time.t_end=0.02 --set output.t_average_start=0 > /dev/null 2>&1
[ $? -eq 1 ] || fail "CHANSPH_RUN_ID=bad/id accepted"
[ $status -eq 0 ] && echo PASS
exit $status
