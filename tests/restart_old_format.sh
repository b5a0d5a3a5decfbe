#!/usr/bin/env bash
# Issue 25: a run cut at step N1 whose checkpoint is rewritten (h5py) as an older checkpoint
# format writes it resumes to the end, and one group of stats.nc is compared with the
# uninterrupted run's (restart_bitwise_all_stats, fixture ckpt_allstats). The rewrite removes
# what the older format lacks: format <= 1.11 the co-moments with y of the Eulerian moment
# records (stats/eulerian/moments: 25 -> 21 per record) and the per-release and per-window
# batches of the Lagrangian and quadrant standard errors; <= 1.9 the sums of the interval-mean velocities
# (stats/lagrangian/sums and slot_sums: 53 -> 47 per record), <= 1.8 also those of the actual
# lags (-> 46), <= 1.7 the correlation engine's window records (stats/correlations/windows,
# window_samples, window_spectra_1d), <= 1.6 the sums of the displacements (-> 43); every
# mode (<= 1.12) the history of T_L (stats/lagrangian/tl_release, tl_release_time; 1.13) and the
# every-snapshot total of the momentum budget (stats/eulerian/planes_total*, 1.14) and the
# mask sums of the correlations' gap correction (stats/correlations/mask_spectra,
# window_mask_1d, 1.15).
#   lagr112: group lagrangian bit for bit (the batches too), except the history of T_L
#     (T_L_release, release), which holds only the releases completed after the resume: the
#     last rows of the uninterrupted run's, bit for bit, fewer (N1 after the first release
#     completed); the log says what was lacking.
#   lagr16, lagr18, lagr19: group lagrangian bit for bit, except the variables the old records
#     cannot give: rate_var_* (and for 1.8 lag_time_mean, for 1.6 also disp_mean_*,
#     disp_var_*), and the slots of the raw sums (raw_sums) the old records lack, fill values
#     where the stored sums had samples (at least one) and otherwise equal.
#   stats111: the root group: stresses about the bin mean (local_mean 0; uu .. vw equal to
#     uu_bin .. vw_bin, which equal the uninterrupted run's bit for bit), the means bit for
#     bit; groups lagrangian and quadrants bit for bit except their standard errors and batch
#     counts, which count only the releases and windows completed after the resume (fewer).
#     (In every mode but lagr112 the Lagrangian standard errors and batch counts are left out
#     of the bitwise comparison for the same reason; in every mode the history of T_L is
#     compared as in lagr112.)
#   corr17: group correlations bit for bit, except n_batches, which counts only the complete
#     windows after the one of the resume (fewer than the uninterrupted run's), the
#     *_stderr, which are fill values with fewer than 2 batches and finite otherwise, and the
#     window records of stats.nc (dimension window), which start at the window of the resume
#     (flagged partial, not complete) and then equal the uninterrupted run's rows bit for bit
#     (their mask sums too); pair_fraction_x, _z unknown (fill: the mask sums do not cover the
#     planes before the resume), gap_corrected 0 (as the uninterrupted run's: no empty cell).
# usage: restart_old_format.sh stats111|lagr112|lagr16|lagr18|lagr19|corr17 CHANSPH SCENE RUNS N1 [--set k=v ...]
set -u
export CHANSPH_RUN_ID=compare-test
mode=$1 chansph=$2 scene=$3 runs=$4 n1=$5
shift 5
case $mode in
  lagr112) minor=12 part=$runs/lagr_format112_part ;;
  lagr16) minor=6 part=$runs/lagr_format16_part ;;
  lagr18) minor=8 part=$runs/lagr_format18_part ;;
  lagr19) minor=9 part=$runs/lagr_format19_part ;;
  corr17) minor=7 part=$runs/corr_format17_part ;;
  stats111) minor=11 part=$runs/stats_format111_part ;;
  *) echo "usage: $0 stats111|lagr112|lagr16|lagr18|lagr19|corr17 CHANSPH SCENE RUNS N1 [--set k=v ...]"; exit 2 ;;
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
    assert h.attrs["format_version_minor"] == 15, h.attrs["format_version_minor"]
    for k in ("mask_spectra", "window_mask_1d"):
        del h["stats/correlations/" + k]
    done.append("no mask sums of the gap correction (1.15)")
    for k in ("planes_total", "planes_total_kinetic"):
        del h["stats/eulerian/" + k]
    done.append("no every-snapshot total of the momentum budget (1.14)")
    for k in ("tl_release", "tl_release_time"):
        del h["stats/lagrangian/" + k]
    done.append("no history of T_L")
    if minor == 12:
        h.attrs["format_version_minor"] = np.int32(minor)
        print("%s: rewritten as format 1.12 (%s)" % (path, "; ".join(done)))
        sys.exit(0)
    a = h["stats/eulerian/moments"][()]
    assert a.shape[2] == 25, a.shape
    del h["stats/eulerian/moments"]
    h.create_dataset("stats/eulerian/moments", data=a[:, :, :21], chunks=a[:, :, :21].shape,
                     fletcher32=True)
    for k in ("lagrangian/release_batches", "lagrangian/slot_pdf", "lagrangian/pdf_batches",
              "quadrants/window", "quadrants/window_end", "quadrants/batches"):
        del h["stats/" + k]
    done.append("Eulerian moments 21 per record, no batches of 1.12")
    width = 53 if minor >= 10 else 47 if minor == 9 else 46 if minor >= 7 else 43
    for k in ("stats/lagrangian/sums", "stats/lagrangian/slot_sums") if width < 53 else ():
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
grep -q "resume: note: .*ckpt_0*$n1.h5 lacks .*stats/lagrangian/tl_release, stats/lagrangian/tl_release_time.* (an earlier checkpoint format)" "$part/log.txt" ||
  { echo "FAIL: the log does not say that the history of T_L starts at the resume"; grep "resume" "$part/log.txt"; exit 1; }
/usr/bin/python3 - "$full/stats.nc" "$part/stats.nc" "$mode" <<'PYEOF'
import sys
import netCDF4
import numpy as np
mode = sys.argv[3]


BATCHES = ("release_batches", "pdf_release_batches", "n_batches")


def batched(k):
    """A standard error, batch count or raw Welford record (release_welford,
    pdf_release_welford, batch_welford) of the per-release or per-window batches of format
    1.12 (T_L's batches, T_L_stderr and T_L_welford, are older): after a resume from an older
    format they count only the batches completed after it."""
    return k in BATCHES or (k.endswith(("_stderr", "_welford")) and
                            k not in ("T_L_stderr", "T_L_welford"))


def fewer_batches(a, b, names):
    """Every batch count of b at most a's, and fewer in all."""
    tot = [0, 0]
    for k in names:
        x, y = np.ma.filled(a[k][:], 0), np.ma.filled(b[k][:], 0)
        if np.any(y > x):
            return False
        tot[0], tot[1] = tot[0] + x.sum(), tot[1] + y.sum()
    return tot[1] < tot[0]


def lagr(a, b, unknown):
    """Group lagrangian: the variables starting with one of unknown may be fill values where
    the uninterrupted run has a value (at least one of each such family), the rest bitwise
    but the batches of format 1.12 (fewer in b; lagr112: bitwise too) and the history of T_L
    (format 1.13: b's rows the last of a's, fewer)."""
    bad, nan = [], {u: 0 for u in unknown}
    if mode != "lagr112" and not fewer_batches(a, b, ("release_batches", "pdf_release_batches")):
        bad.append("release_batches (not fewer after the resume)")
    na, nb = len(a.dimensions["release"]), len(b.dimensions["release"])
    if not (0 < nb < na if mode == "lagr112" else nb <= na):
        bad.append("history of T_L: %d releases after the resume of %d" % (nb, na))
    for k, v in a.variables.items():
        if "release" in v.dimensions:
            x, y = v[:], b.variables[k][:]
            if nb <= na and not np.array_equal(np.ma.filled(x[na - nb:], np.nan),
                                              np.ma.filled(y, np.nan), equal_nan=True):
                bad.append(k + " (not the uninterrupted run's last rows)")
            continue
        if batched(k) and mode != "lagr112":
            continue
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
    ok = not bad and all(n > 0 for n in nan.values()) if unknown else not bad
    print("%s: group lagrangian of the run resumed from format 1.%s sums: %s; fill values "
          "(unknown) in %s, the others equal; history of T_L: %d of %d releases" %
          ("PASS" if ok else "FAIL", mode[5:] if mode.startswith("lagr1") else "11",
           "bitwise equal" if not bad else "DIFFERENT: " + ", ".join(bad),
           ", ".join("%d of %s*" % (n, u) for u, n in nan.items()), nb, na))
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
              "window_complete", "window_bounds", "window_mask_kx", "window_mask_kz",
              "window_mask_planes", "window_empty_cells"):
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
        if k.startswith("pair_fraction_"):  # no mask sums before the resume: unknown
            ok = np.all(np.isnan(y)) and np.all(np.isfinite(x))
        elif k.endswith("_stderr"):
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


def stats111(a, b):
    """The root group and groups quadrants and lagrangian after a resume from format 1.11."""
    bad = []
    for k, v in a.variables.items():
        if "y" not in v.dimensions or v.dimensions != ("y",):
            continue
        x, y = np.ma.filled(v[:], np.nan), np.ma.filled(b[k][:], np.nan)
        if k in ("uu", "vv", "ww", "uv", "uw", "vw"):
            same = np.array_equal(y, np.ma.filled(b[k + "_bin"][:], np.nan), equal_nan=True)
        elif k == "local_mean":
            same = np.all((y == 0) | np.isnan(y)) and np.any(y == 0)
        elif k.startswith(("rsb_", "reynolds_stress", "advective_stress", "total_stress")) or \
                k.endswith("_stderr") or k in ("viscous_stress", "correlation_time_bin",
                                               "n_eff_windows", "short_windows",
                                               "momentum_change_all"):
            continue  # functions of the stresses, or of the batches: about the bin mean now;
            # the every-snapshot total (format 1.14): from the resume on
        else:
            same = np.array_equal(x, y, equal_nan=True)
        bad += [] if same else [k]
    qa, qb = a.groups["quadrants"], b.groups["quadrants"]
    for k in qa.variables:
        if not batched(k) and not np.array_equal(qa[k][:], qb[k][:]):
            bad.append("quadrants/" + k)
    if not fewer_batches(qa, qb, ("n_batches",)):
        bad.append("quadrants/n_batches (not fewer)")
    print("%s: root group of the run resumed from format 1.11: stresses about the bin mean "
          "(local_mean 0, uu .. vw = uu_bin .. vw_bin), the rest and group quadrants bitwise "
          "but their batches: %s" % ("FAIL" if bad else "PASS",
                                     "DIFFERENT: " + ", ".join(bad) if bad else "as expected"))
    return not bad and lagr(a.groups["lagrangian"], b.groups["lagrangian"], [])


fa, fb = netCDF4.Dataset(sys.argv[1]), netCDF4.Dataset(sys.argv[2])
if mode == "stats111":
    ok = stats111(fa, fb)
elif mode == "corr17":
    ok = corr(fa.groups["correlations"], fb.groups["correlations"])
else:
    unknown = [] if mode == "lagr112" else ["rate_var_", "raw_sums"] + \
        (["lag_time_mean"] if mode != "lagr19" else []) + \
        (["disp_mean_", "disp_var_"] if mode == "lagr16" else [])
    ok = lagr(fa.groups["lagrangian"], fb.groups["lagrangian"], unknown)
sys.exit(0 if ok else 1)
PYEOF
