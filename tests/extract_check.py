#!/usr/bin/python3
"""chansph extract against stats.nc: the full window range reproduces the stored profiles,
and a sub-range reproduces the count-weighted mean of its windows' raw moment records.

usage: extract_check.py CHANSPH STATS.nc
"""
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ncfile import need, need_group, open_nc  # noqa: E402


def extract(chansph, path, *args):
    res = subprocess.run([chansph, "extract", path] + list(args), capture_output=True, text=True)
    if res.returncode:
        sys.exit("FAIL: chansph extract %s: %s" % (" ".join(args), res.stderr))
    lines = [l for l in res.stdout.splitlines() if not l.startswith("#")]
    head = lines[0].split(",")
    data = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    return {h: data[:, i] for i, h in enumerate(head)}


def main():
    p = cli.parser("extract_check.py", __doc__)
    p.add_argument("chansph")
    p.add_argument("stats", metavar="STATS.nc")
    a = p.parse_args()
    chansph, path = a.chansph, a.stats
    with open_nc(path) as d:
        u = np.ma.filled(need(d, "u_mean", path)[:].astype(float), np.nan)
        uu = np.ma.filled(need(d, "uu", path)[:].astype(float), np.nan)
        g = need_group(d, "eulerian", path)
        t0, t1 = need(g, "window_start", path)[:], need(g, "window_end", path)[:]
        mom = need(g, "moments", path)[:]
    if len(t0) == 0:
        raise cli.InputError(f"{path}: no averaging window (the run has not begun averaging?)")
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
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(cli.run(main))
