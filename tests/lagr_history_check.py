#!/usr/bin/python3
"""The history of T_L in group lagrangian of stats.nc (checkpoint format 1.13): each completed
release's own T_L per level and component (T_L_release, dimension release, its coordinate the
time each release completed).
In FULL (an uninterrupted run) and PART (the same run cut and resumed, restart_bitwise.sh):
  - as many rows as completed releases (attribute releases), completion times increasing;
  - per level and component, the mean of the finite values equals T_L_release_mean and their
    standard deviation (ddof 1) / sqrt(count) equals T_L_stderr (relative 1e-12), fill values
    where fewer than 1 (mean) or 2 (stderr) are finite; at least one component with 3 or more;
  - PART's history equals FULL's bit for bit.
usage: lagr_history_check.py FULL/stats.nc PART/stats.nc"""
import sys

import netCDF4
import numpy as np


def history(path):
    with netCDF4.Dataset(path) as d:
        g = d["lagrangian"]
        get = lambda k: np.ma.filled(g[k][:].astype(float), np.nan)  # noqa: E731
        return (int(g.releases), get("release"), get("T_L_release"), get("T_L_release_mean"),
                get("T_L_stderr"))


ok, runs = True, [history(p) for p in sys.argv[1:3]]
for path, (releases, t, h, mean, se) in zip(sys.argv[1:3], runs):
    bad = []
    if h.shape[0] != releases or len(t) != releases:
        bad.append("%d rows of %d releases" % (h.shape[0], releases))
    if not np.all(np.diff(t) > 0):
        bad.append("completion times not increasing: %s" % t)
    fin = np.isfinite(h)
    n = fin.sum(axis=0)
    hm = np.where(n > 0, np.nansum(h, axis=0) / np.maximum(n, 1), np.nan)
    dev = np.where(fin, h - hm, 0.0)
    hs = np.where(n >= 2, np.sqrt((dev ** 2).sum(axis=0) / np.maximum(n - 1, 1)) /
                  np.sqrt(np.maximum(n, 1)), np.nan)
    for want, got, name in ((mean, hm, "T_L_release_mean"), (se, hs, "T_L_stderr")):
        same_nan = np.array_equal(np.isnan(want), np.isnan(got))
        close = np.allclose(np.nan_to_num(got), np.nan_to_num(want), rtol=1e-12, atol=0.0)
        if not (same_nan and close):
            bad.append("%s %s, from the history %s" % (name, want.tolist(), got.tolist()))
    if n.max() < 3:
        bad.append("no component with 3 finite releases (finite counts %s)" % n.tolist())
    print("%s: %d releases ending at t = %s; finite per level and component %s; mean %s +- %s: %s"
          % (path, releases, np.round(t, 4).tolist(), n.tolist(), np.round(hm, 6).tolist(),
             np.round(hs, 6).tolist(), "PASS" if not bad else "FAIL: " + "; ".join(bad)))
    ok &= not bad
same = all(np.array_equal(a, b, equal_nan=True) for a, b in zip(runs[0][1:3], runs[1][1:3]))
print("history of the resumed run %s the uninterrupted run's: %s" %
      ("equals" if same else "differs from", "PASS" if same else "FAIL"))
sys.exit(0 if ok and same else 1)
