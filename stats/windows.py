#!/usr/bin/python3
"""Per-window turbulence indicators of a run: is it turbulent, and is it decaying?

usage: python3 stats/windows.py STATS.nc [--every K] [--u-tau U]

For every averaging window (stats.window) of stats.nc, from its raw sums (group eulerian):
the -u'v'+ peak and where it lies, the u_rms+ and v_rms+ peaks, the correlation coefficient
R_uv = -u'v' / (u_rms v_rms) averaged over 30 <= y+ <= 100 (about 0.4-0.5 in wall turbulence,
near 0 for particle noise), the bulk velocity U_b+, and with the momentum budget the share of
the stress that the resolved turbulence carries at y+ = 30. Wall units use u_tau from the
force balance of the whole run (or --u-tau). With fold = 0 the upper half is mirrored.
A run whose -u'v'+ peak falls window after window is decaying; one near the DNS (0.72 at
Re_tau = 180, 0.84 at 395) with R_uv about 0.45 is sustaining resolved turbulence.
"""
import argparse
import math
import os
import sys

import netCDF4
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ab_table import window_values  # noqa: E402  (the same indicators as the A/B table)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("stats")
    ap.add_argument("--every", type=int, default=1, help="print every K-th window")
    ap.add_argument("--u-tau", type=float, default=0.0)
    a = ap.parse_args()
    try:
        nc = netCDF4.Dataset(a.stats)
    except OSError as e:
        sys.exit(f"error: {a.stats}: {e}")
    g = nc.groups.get("eulerian")
    if g is None:
        sys.exit(f"error: {a.stats}: no group 'eulerian'")
    delta, nu, fold = float(nc.delta), float(nc.nu), int(nc.fold)
    win = np.asarray(g["windows"][:])
    mom = np.asarray(g["moments"][:])
    fx = win[:, 3].sum() / max(win[:, 2].sum(), 1)
    ut = a.u_tau if a.u_tau > 0 else math.sqrt(max(delta * fx, 0.0))
    print(f"# {a.stats}: {len(win)} windows, u_tau = {ut:.4g} (force balance), "
          f"Re_tau = {ut * delta / nu:.1f}")
    print(f"# {'t0':>7} {'t1':>7} {'-uv+pk':>7} {'y+pk':>6} {'urms+pk':>7} {'vrms+pk':>7} "
          f"{'R_uv':>6} {'U_b+':>6}")
    pln = np.asarray(g["planes"][:]) if "planes" in g.variables else None
    rows = [r for r in range(0, len(win), a.every) if win[r, 2] > 0]
    vals = window_values(mom[rows], pln[rows] if pln is not None else [None] * len(rows),
                         delta, fold, ut, nu)
    for r, v in zip(rows, vals):
        print(f"  {win[r, 0]:7.3f} {win[r, 1]:7.3f} {v['uv_peak']:7.3f} {v['y_peak']:6.1f} "
              f"{v['urms']:7.3f} {v['vrms']:7.3f} {v['ruv']:6.3f} {v['ub']:6.2f}")


if __name__ == "__main__":
    main()
