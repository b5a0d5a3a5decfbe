#!/usr/bin/env bash
# Issue 42 point 6: checkpoints of older formats.
#   1. A checkpoint whose Reynolds-stress budget records are of format 1.10 (136 fields, the
#      fluctuations about the bin's mean; this build reads 252): the resume is refused (exit
#      1) with a message naming the file, the dataset, both format versions and the remedies
#      (finish with the version that started it, or a new segment with init.from), not "a
#      checkpoint of another scene?".
#   2. A checkpoint without the Reynolds-stress budget dataset (format 1.5 layout) resumes, and
#      says that its budgets cover only the windows after the resume: in log.txt, in the global
#      attribute resumed_without of stats.nc, and still after a second resume (checkpointed).
# usage: restart_format_versions.sh CHANSPH SCENE RUNS
set -u
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3
w=$runs/format_versions
rm -rf "$w" && mkdir -p "$w"
opts=(--set time.t_end=0.6 --set output.t_average_start=0 --set stats.window=0.1)
"$chansph" run "$scene" --out "$w/a" "${opts[@]}" --max-steps 40 > "$w/a.log" 2>&1
[ $? -eq 75 ] || { tail -3 "$w/a.log"; echo "FAIL: the run to step 40"; exit 1; }
status=0
# rewrite DIR's checkpoint as format 1.MINOR: its Reynolds-stress records cut to WIDTH fields
# (0: the dataset removed)
rewrite() {
  /usr/bin/python3 - "$1" "$2" "$3" << 'PY' || exit 1
import glob, sys
import h5py
import numpy as np
path = sorted(glob.glob(sys.argv[1] + "/checkpoints/ckpt_*.h5"))[-1]
minor, width = int(sys.argv[2]), int(sys.argv[3])
with h5py.File(path, "a") as h:
    k = "stats/eulerian/reynolds_budget"
    a = h[k][()]
    del h[k]
    if width:
        h.create_dataset(k, data=a[..., :width], chunks=a[..., :width].shape, fletcher32=True)
    for k in ("output/resumed_without", "sim/init_from_run_id", "sim/init_from_time"):
        del h[k]  # added in 1.12
    h.attrs["format_version_minor"] = np.int32(minor)
print("%s: rewritten as format 1.%d, Reynolds-stress records %s" % (path, minor, width or "removed"))
PY
}
cp -r "$w/a" "$w/v110"
rewrite "$w/v110" 10 136
msg=$("$chansph" resume "$w/v110" 2>&1)
rc=$?
echo "$msg" | grep -E "error|skipped" | head -3
echo "$msg" | grep -q "dataset /stats/eulerian/reynolds_budget has shape (3, 19, 136), this run needs ([0-9]*, 19, 252): written in checkpoint format 1.10, whose records this build (format 1.15) does not read; finish the run with the chansph version that started it, or start a new segment from its state with init.from" &&
  [ $rc -eq 1 ] || { echo "FAIL: a format-1.10 checkpoint: exit $rc, not the versions and remedies"; status=1; }
echo "$msg" | grep -q "another scene" && { echo "FAIL: still 'a checkpoint of another scene?'"; status=1; }
cp -r "$w/a" "$w/v15"
rewrite "$w/v15" 5 0
"$chansph" resume "$w/v15" --max-steps 20 > "$w/v15.log" 2>&1
rc=$?
note="resume: note: .*ckpt_0000000040.h5 lacks stats/eulerian/reynolds_budget (an earlier checkpoint format): what it accumulates starts at this resume, t = [0-9.]*.*the Reynolds-stress budgets cover only the windows after it"
grep "resume: note" "$w/v15/log.txt"
[ $rc -eq 75 ] && grep -q "$note" "$w/v15/log.txt" ||
  { echo "FAIL: a checkpoint without the Reynolds-stress budget: exit $rc, or no note in the log"; status=1; }
"$chansph" resume "$w/v15" > "$w/v15b.log" 2>&1 || { tail -3 "$w/v15b.log"; echo "FAIL: the second resume"; status=1; }
/usr/bin/python3 - "$w/v15/stats.nc" "$w/a/stats.nc" << 'PY' || status=1
import sys
import netCDF4
d, a = netCDF4.Dataset(sys.argv[1]), netCDF4.Dataset(sys.argv[2])
note = getattr(d, "resumed_without", None)
print("stats.nc resumed_without: %r; the uninterrupted file has it: %s" % (note, "resumed_without" in a.ncattrs()))
ok = note is not None and note.startswith("stats/eulerian/reynolds_budget from t = ")
sys.exit(0 if ok and "resumed_without" not in a.ncattrs() else "FAIL: stats.nc does not say it")
PY
[ $status -eq 0 ] && echo "PASS: older checkpoint formats are named, and what they lack is said"
exit $status
