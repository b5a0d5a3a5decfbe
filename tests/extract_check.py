#!/usr/bin/python3
"""chansph extract against stats.nc: the full window range reproduces the stored profiles,
and a sub-range reproduces the count-weighted mean of its windows' raw moment records.

usage: extract_check.py CHANSPH STATS.nc
"""
import subprocess
import sys

import netCDF4
import numpy as np


def extract(chansph, path, *args):
    res = subprocess.run([chansph, "extract", path] + list(args), capture_output=True, text=True)
    if res.returncode:
        sys.exit("FAIL: chansph extract %s: %s" % (" ".join(args), res.stderr))
    lines = [l for l in res.stdout.splitlines() if not l.startswith("#")]
    head = lines[0].split(",")
    data = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    return {h: data[:, i] for i, h in enumerate(head)}


def main():
    chansph, path = sys.argv[1], sys.argv[2]
    with netCDF4.Dataset(path) as d:
        u = np.ma.filled(d["u_mean"][:].astype(float), np.nan)
        uu = np.ma.filled(d["uu"][:].astype(float), np.nan)
        g = d.groups["eulerian"]
        t0, t1 = g["window_start"][:], g["window_end"][:]
        mom = g["moments"][:]
    ok = True
    full = extract(chansph, path, "--var", "u_mean,uu", "--units", "outer")
    e1 = np.nanmax(np.abs(full["u_mean"] - u) / np.nanmax(np.abs(u)))
    e2 = np.nanmax(np.abs(full["uu"] - uu) / np.nanmax(np.abs(uu)))
    print("all windows: extract vs stored u_mean %.2e, uu %.2e (relative, limit 1e-8)" % (e1, e2))
    ok &= e1 < 1e-8 and e2 < 1e-8
    nw = len(t0)
    a, b = nw // 3, max(nw // 3 + 1, 2 * nw // 3)
    part = extract(chansph, path, "--var", "u_mean", "--units", "outer", "--window",
                   "%.17g:%.17g" % (t0[a], t1[b - 1]))
    n = mom[a:b, :, 0]
    ref = (n * mom[a:b, :, 1]).sum(axis=0) / n.sum(axis=0)
    e3 = np.nanmax(np.abs(part["u_mean"] - ref) / np.nanmax(np.abs(ref)))
    print("windows %d..%d (t = %g .. %g): extract vs count-weighted window means %.2e "
          "(limit 1e-8)" % (a, b - 1, t0[a], t1[b - 1], e3))
    ok &= e3 < 1e-8
    bad = subprocess.run([chansph, "extract", path, "--window", "1e9:2e9"], capture_output=True,
                         text=True)
    ok &= bad.returncode == 1 and "no averaging window" in bad.stderr
    print("empty range: exit %d, %s" % (bad.returncode, bad.stderr.strip()))
    print("PASS" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
