#!/usr/bin/env bash
# Acceptance 5 of issue 4: a checkpoint that cannot be written (file size limit, ulimit -f) gives
# a clear error naming the file, leaves the previous checkpoint intact and no temporary file,
# and the run stops with exit code 74 instead of continuing unprotected.
# usage: restart_write_fail.sh CHANSPH SCENE RUNS
set -u
chansph=$1 scene=$2 runs=$3
d=$runs/write_fail
rm -rf "$d"
status=0
fail() { echo "FAIL: $*"; status=1; }
"$chansph" run "$scene" --out "$d" --set time.t_end=1 --set output.t_average_start=0.5 \
  --max-steps 20 > /dev/null
[ $? -eq 75 ] || { echo "FAIL: first job"; exit 1; }
ck=$d/checkpoints/ckpt_0000000020.h5
cp "$ck" "$runs/write_fail_copy.h5"
size=$(stat -c %s "$ck")
# a file size limit below the checkpoint size (ulimit -f counts 1024-byte blocks in bash)
# PMIX_MCA_gds=hash: Open MPI's singleton start-up keeps its shared-memory store under the limit
out=$(ulimit -f $((size / 2048)) && PMIX_MCA_gds=hash "$chansph" resume "$d" --set checkpoint.every_steps=5 2>&1)
rc=$?
echo "$out" | grep -E "^error" | head -n 3
[ $rc -eq 74 ] || fail "exit status $rc, expected 74"
echo "$out" | grep -Eq "error: cannot write checkpoint .*ckpt_0000000025.h5.tmp .*File too large" ||
  fail "no message naming the file and the cause"
echo "$out" | grep -q "stopped at step 25: cannot write a checkpoint (the previous ones are intact)" ||
  fail "no stop message"
cmp -s "$ck" "$runs/write_fail_copy.h5" || fail "the previous checkpoint changed"
ls "$d/checkpoints"
[ -z "$(ls "$d/checkpoints" | grep -v '^ckpt_0000000020.h5$')" ] || fail "files left behind"
"$chansph" resume "$d" > /dev/null || fail "resume after the limit is lifted"
[ $status -eq 0 ] && echo PASS
exit $status
