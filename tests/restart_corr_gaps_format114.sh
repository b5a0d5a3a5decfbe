#!/usr/bin/env bash
# The correlations' gap correction across a resume from a checkpoint written before it (format
# 1.14: no stats/correlations/mask_spectra, window_mask_1d). A run with empty grid cells
# (restart_bitwise_corr_gaps' settings) is cut at step N1, its checkpoint rewritten (h5py)
# without the mask sums and marked 1.14, and resumed to the end. Against the uninterrupted run
# (fixture ckpt_corrgaps, gap-corrected on every level):
#   - the log says what the checkpoint lacks;
#   - group correlations is uncorrected: gap_corrected 0 and pair_fraction_x, _z fill values on
#     every level, and R (the zero-filled estimate) equals the uninterrupted run's corrected R
#     times its P(l) (1e-12 of each row's largest value): the same sums, one estimator;
#   - rho equals R / R(0) of those, and the standard errors are finite (uncorrected windows:
#     each batch of the same estimator as the mean);
#   - the window records after the resume's window have mask sums covering their planes, those
#     before none (and the resume's own window fewer than its planes).
# usage: restart_corr_gaps_format114.sh CHANSPH SCENE RUNS N1 [--set k=v ...]
set -u
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3 n1=$4
shift 4
part=$runs/corr_gaps_format114_part full=$runs/bitwise_corrgaps_full
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
    assert h.attrs["format_version_minor"] == 15, h.attrs["format_version_minor"]
    for k in ("mask_spectra", "window_mask_1d"):
        del h["stats/correlations/" + k]
    h.attrs["format_version_minor"] = np.int32(14)
print("%s: rewritten as format 1.14 (no mask sums)" % path)
PYEOF
"$chansph" resume "$part" > "$part.log" 2>&1 || { echo "FAIL: resume"; cat "$part.log"; exit 1; }
grep -q "resume: note: .*lacks .*stats/correlations/mask_spectra, stats/correlations/window_mask_1d" "$part/log.txt" ||
  { echo "FAIL: the log does not say that the mask sums are missing"; grep "resume" "$part/log.txt"; exit 1; }
/usr/bin/python3 - "$full/stats.nc" "$part/stats.nc" <<'PYEOF'
import sys
import netCDF4
import numpy as np
a = netCDF4.Dataset(sys.argv[1])["correlations"]
b = netCDF4.Dataset(sys.argv[2])["correlations"]
bad = []
if not (np.all(a["gap_corrected"][:] == 1) and np.all(b["gap_corrected"][:] == 0)):
    bad.append("gap_corrected %s (uninterrupted %s)" % (list(b["gap_corrected"][:]),
                                                        list(a["gap_corrected"][:])))
for d in "xz":
    if not np.all(np.ma.getmaskarray(b["pair_fraction_" + d][:])):
        bad.append("pair_fraction_%s not a fill value" % d)
    P = np.ma.filled(a["pair_fraction_" + d][:], np.nan)
    for c in ("uu", "vv", "ww", "uv"):
        k = "R_%s_%s" % (c, d)
        want = np.ma.filled(a[k][:], np.nan) * P
        got = np.ma.filled(b[k][:], np.nan)
        scale = np.nanmax(np.abs(want), axis=1, keepdims=True)
        if not np.all(np.abs(got - want) <= 1e-12 * scale):
            bad.append("%s != the uninterrupted R times P (largest difference %.3g of the row)" %
                       (k, np.nanmax(np.abs(got - want) / scale)))
        r0 = np.ma.filled(b["R_%s_%s" % ("uu" if c == "uv" else c, d)][:, :1], np.nan)
        if not np.allclose(np.ma.filled(b["rho_%s_%s" % (c, d)][:], np.nan), got / r0,
                           rtol=1e-12, atol=0):
            bad.append("rho_%s_%s != R / R(0)" % (c, d))
        if not np.all(np.isfinite(np.ma.filled(b[k + "_stderr"][:], np.nan))):
            bad.append(k + "_stderr not finite")
planes, samp = b["window_mask_planes"][:], b["window_samples"][:]
full_rows = [r for r in range(planes.shape[0]) if np.all(planes[r] == samp[r])]
short = [r for r in range(planes.shape[0]) if np.any(planes[r] != samp[r])]
if not (len(short) >= 1 and all(r < min(full_rows) for r in short) and np.all(planes[short[0]] == 0)):
    bad.append("window mask planes: rows covering their planes %s, not %s" % (full_rows, short))
print("%s: a gappy run resumed from format 1.14: %s; windows with mask sums %s, without or "
      "partly %s" % ("PASS" if not bad else "FAIL", "uncorrected, R = the uninterrupted R x P, "
                     "rho and standard errors consistent" if not bad else "; ".join(bad),
                     full_rows, short))
sys.exit(1 if bad else 0)
PYEOF
