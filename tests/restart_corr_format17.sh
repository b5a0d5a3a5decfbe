#!/usr/bin/env bash
# Issue 25: a run cut at step N1 whose checkpoint has no per-window records of the correlation
# engine (checkpoint format 1.7: the datasets stats/correlations/windows, window_samples and
# window_spectra_1d removed here with h5py) resumes to the end: every variable of group
# correlations equals the uninterrupted run's (restart_bitwise_all_stats, fixture
# ckpt_allstats) bit for bit, except n_batches, which counts only the complete windows after
# the one of the resume (fewer than the uninterrupted run's), and the *_stderr, which are fill
# values with fewer than 2 batches and finite otherwise.
# usage: restart_corr_format17.sh CHANSPH SCENE RUNS N1 [--set k=v ...]
set -u
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3 n1=$4
shift 4
full=$runs/bitwise_allstats_full part=$runs/corr_format17_part
rm -rf "$part"
"$chansph" run "$scene" --out "$part" --max-steps "$n1" "$@" > /dev/null
rc=$?
[ $rc -eq 75 ] || { echo "FAIL: run --max-steps $n1 exited $rc, expected 75"; exit 1; }
/usr/bin/python3 - "$part" <<'PYEOF' || exit 1
import glob, sys
import h5py
import numpy as np
path = sorted(glob.glob(sys.argv[1] + "/checkpoints/ckpt_*.h5"))[-1]
with h5py.File(path, "a") as h:
    for k in ("windows", "window_samples", "window_spectra_1d"):
        del h["stats/correlations/" + k]
    h.attrs["format_version_minor"] = np.int32(7)
print("%s: correlation window records removed (format 1.7)" % path)
PYEOF
"$chansph" resume "$part" > "$part.log" 2>&1 || { echo "FAIL: resume"; cat "$part.log"; exit 1; }
grep -q "resume: from .*ckpt_0*$n1.h5" "$part.log" || { echo "FAIL: not resumed from step $n1"; cat "$part.log"; exit 1; }
/usr/bin/python3 - "$full/stats.nc" "$part/stats.nc" <<'PYEOF'
import sys
import netCDF4
import numpy as np
a = netCDF4.Dataset(sys.argv[1]).groups["correlations"]
b = netCDF4.Dataset(sys.argv[2]).groups["correlations"]
bad = []
na, nb = a.variables["n_batches"][:], b.variables["n_batches"][:]
for k, v in a.variables.items():
    if k == "n_batches":
        continue
    x, y = v[:], b.variables[k][:]
    if x.dtype.kind != "f":
        bad += [] if np.array_equal(x, y) else [k]
        continue
    x, y = np.ma.filled(x, np.nan), np.ma.filled(y, np.nan)
    if k.endswith("_stderr"):
        few = (nb < 2)[:, None]
        ok = np.all(np.isnan(y) == np.broadcast_to(few, y.shape)) and np.all(np.isfinite(x))
    else:
        ok = np.array_equal(x, y, equal_nan=True)
    bad += [] if ok else [k]
fewer = bool(np.all(nb < na))
ok = not bad and fewer
print("%s: group correlations of the run resumed from a checkpoint without window records: "
      "%s; batches %s (uninterrupted %s)" %
      ("PASS" if ok else "FAIL", "whole-run variables bitwise equal, standard errors as expected"
       if not bad else "DIFFERENT: " + ", ".join(bad), list(nb), list(na)))
sys.exit(0 if ok else 1)
PYEOF
