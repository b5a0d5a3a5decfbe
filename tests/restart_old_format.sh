#!/usr/bin/env bash
# Issue 25: a run cut at step N1 whose checkpoint is rewritten (h5py) as an older checkpoint
# format writes it resumes to the end, and one group of stats.nc is compared with the
# uninterrupted run's (restart_bitwise_all_stats, fixture ckpt_allstats). The rewrite removes
# what the older format lacks: format <= 1.9 the sums of the interval-mean velocities
# (stats/lagrangian/sums and slot_sums: 53 -> 47 per record), <= 1.8 also those of the actual
# lags (-> 46), <= 1.7 the correlation engine's window records (stats/correlations/windows,
# window_samples, window_spectra_1d), <= 1.6 the sums of the displacements (-> 43).
#   lagr16, lagr18, lagr19: group lagrangian bit for bit, except the variables the old records
#     cannot give: rate_var_* (and for 1.8 lag_time_mean, for 1.6 also disp_mean_*,
#     disp_var_*), fill values where the stored sums had samples (at least one) and otherwise
#     equal.
#   corr17: group correlations bit for bit, except n_batches, which counts only the complete
#     windows after the one of the resume (fewer than the uninterrupted run's), the
#     *_stderr, which are fill values with fewer than 2 batches and finite otherwise, and the
#     window records of stats.nc (dimension window), which start at the window of the resume
#     (flagged partial, not complete) and then equal the uninterrupted run's rows bit for bit.
# usage: restart_old_format.sh lagr16|lagr18|lagr19|corr17 CHANSPH SCENE RUNS N1 [--set k=v ...]
set -u
export CHANSPH_RUN_ID=compare-test
mode=$1 chansph=$2 scene=$3 runs=$4 n1=$5
shift 5
case $mode in
  lagr16) minor=6 part=$runs/lagr_format16_part ;;
  lagr18) minor=8 part=$runs/lagr_format18_part ;;
  lagr19) minor=9 part=$runs/lagr_format19_part ;;
  corr17) minor=7 part=$runs/corr_format17_part ;;
  *) echo "usage: $0 lagr16|lagr18|lagr19|corr17 CHANSPH SCENE RUNS N1 [--set k=v ...]"; exit 2 ;;
esac
full=$runs/bitwise_allstats_full
rm -rf "$part"
"$chansph" run "$scene" --out "$part" --max-steps "$n1" "$@" > /dev/null
rc=$?
[ $rc -eq 75 ] || { echo "FAIL: run --max-steps $n1 exited $rc, expected 75"; exit 1; }
/usr/bin/python3 - "$part" "$minor" <<'PYEOF' || exit 1
import glob, sys
import h5py
import numpy as np
path, minor = sorted(glob.glob(sys.argv[1] + "/checkpoints/ckpt_*.h5"))[-1], int(sys.argv[2])
done = []
with h5py.File(path, "a") as h:
    assert h.attrs["format_version_minor"] == 12, h.attrs["format_version_minor"]
    width = 47 if minor == 9 else 46 if minor >= 7 else 43  # sums per record
    for k in ("stats/lagrangian/sums", "stats/lagrangian/slot_sums"):
        a = h[k][()]
        assert a.shape[2] == 53, (k, a.shape)
        del h[k]
        h.create_dataset(k, data=a[:, :, :width], chunks=a[:, :, :width].shape, fletcher32=True)
    done.append("Lagrangian sums %d per record" % width)
    if minor <= 7:
        for k in ("windows", "window_samples", "window_spectra_1d"):
            del h["stats/correlations/" + k]
        done.append("correlation window records removed")
    h.attrs["format_version_minor"] = np.int32(minor)
print("%s: rewritten as format 1.%d (%s)" % (path, minor, "; ".join(done)))
PYEOF
"$chansph" resume "$part" > "$part.log" 2>&1 || { echo "FAIL: resume"; cat "$part.log"; exit 1; }
grep -q "resume: from .*ckpt_0*$n1.h5" "$part.log" || { echo "FAIL: not resumed from step $n1"; cat "$part.log"; exit 1; }
/usr/bin/python3 - "$full/stats.nc" "$part/stats.nc" "$mode" <<'PYEOF'
import sys
import netCDF4
import numpy as np
mode = sys.argv[3]


def lagr(a, b, unknown):
    """Group lagrangian: the variables starting with one of unknown may be fill values where
    the uninterrupted run has a value (at least one of each such family), the rest bitwise."""
    bad, nan = [], {u: 0 for u in unknown}
    for k, v in a.variables.items():
        x, y = v[:], b.variables[k][:]
        if x.dtype.kind != "f":
            bad += [] if np.array_equal(x, y) else [k]
            continue
        x, y = np.ma.filled(x, np.nan), np.ma.filled(y, np.nan)
        fam = [u for u in unknown if k.startswith(u)]
        if fam:
            extra = np.isnan(y) & ~np.isnan(x)
            nan[fam[0]] += int(extra.sum())
            same = np.array_equal(np.where(extra, np.nan, x), y, equal_nan=True)
        else:
            same = np.array_equal(x, y, equal_nan=True)
        bad += [] if same else [k]
    ok = not bad and all(n > 0 for n in nan.values())
    print("%s: group lagrangian of the run resumed from format 1.%s sums: %s; fill values "
          "(unknown) in %s, the others equal" %
          ("PASS" if ok else "FAIL", mode[-1],
           "bitwise equal" if not bad else "DIFFERENT: " + ", ".join(bad),
           ", ".join("%d of %s*" % (n, u) for u, n in nan.items())))
    return ok


def corr_windows(a, b):
    """The window records of the resumed run b: one partial window (the resume's), then the
    rows of the uninterrupted run a from the same start on, bit for bit."""
    wa, wb = a["windows"][:], b["windows"][:]
    part = np.nonzero(wb[:, 3])[0]
    if len(part) != 1 or b["window_complete"][part[0]] != 0:
        return ["windows (partial flags %s)" % list(wb[:, 3])]
    j = part[0] + 1
    i = int(np.searchsorted(wa[:, 0], wb[j, 0])) if j < len(wb) else len(wa)
    if len(wa) - i != len(wb) - j or j == len(wb):
        return ["windows (rows %d of %d after the resume)" % (len(wb) - j, len(wa) - i)]
    bad = []
    for k in ("windows", "window_samples", "window_spectra_kx", "window_spectra_kz",
              "window_complete", "window_bounds"):
        if not np.array_equal(a[k][i:], b[k][j:]):
            bad.append(k)
    return bad


def corr(a, b):
    bad = corr_windows(a, b)
    na, nb = a.variables["n_batches"][:], b.variables["n_batches"][:]
    for k, v in a.variables.items():
        if k == "n_batches" or "window" in v.dimensions:
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
    print("%s: group correlations of the run resumed from a checkpoint without window "
          "records: %s; batches %s (uninterrupted %s)" %
          ("PASS" if ok else "FAIL", "whole-run variables bitwise equal, standard errors as "
           "expected" if not bad else "DIFFERENT: " + ", ".join(bad), list(nb), list(na)))
    return ok


fa, fb = netCDF4.Dataset(sys.argv[1]), netCDF4.Dataset(sys.argv[2])
if mode == "corr17":
    ok = corr(fa.groups["correlations"], fb.groups["correlations"])
else:
    unknown = ["rate_var_"] + (["lag_time_mean"] if mode != "lagr19" else []) + \
        (["disp_mean_", "disp_var_"] if mode == "lagr16" else [])
    ok = lagr(fa.groups["lagrangian"], fb.groups["lagrangian"], unknown)
sys.exit(0 if ok else 1)
PYEOF
