#!/usr/bin/python3
"""Compare two short LES runs from the same start, one with les.strain_lag = 0 (eddy viscosity
from a separate pass at the current state) and one with 1 (from the force loop of the previous
step): the one-step lag must change the mean eddy viscosity by less than REL_NU of its maximum
and the mean velocity by less than REL_U of its maximum, and must change something (else the
key would not be in effect).

usage: strain_lag_check.py UNLAGGED/stats.nc LAGGED/stats.nc [--rel-nu X] [--rel-u X]
"""
import argparse
import sys

import netCDF4
import numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("unlagged")
ap.add_argument("lagged")
ap.add_argument("--rel-nu", type=float, default=0.005)
ap.add_argument("--rel-u", type=float, default=1e-4)
args = ap.parse_args()
a, b = netCDF4.Dataset(args.unlagged), netCDF4.Dataset(args.lagged)
fail = 0
for name, tol in (("nu_t_mean", args.rel_nu), ("u_mean", args.rel_u), ("k_r_mean", 2 * args.rel_nu)):
    x, y = np.asarray(a[name][:], float), np.asarray(b[name][:], float)
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        print(f"FAIL: {name} holds NaN or Inf")
        fail = 1
        continue
    rel = np.abs(x - y).max() / np.abs(x).max()
    ok = rel < tol
    print(f"{name}: max |lagged - unlagged| / max |unlagged| = {rel:.3g} (limit {tol:g}) "
          f"{'ok' if ok else 'FAIL'}")
    fail |= not ok
    if name == "nu_t_mean" and rel == 0.0:
        print("FAIL: the lagged run equals the unlagged one: les.strain_lag not in effect")
        fail = 1
sys.exit(fail)
