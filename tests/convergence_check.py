#!/usr/bin/python3
"""chansph-stats convergence on a shipped stats.nc: its standard error of the -u'v'+ peak over
all the complete windows must be the batch-means error recomputed here from the raw window
moments with numpy (each window's own C2_uv / count at the bin of the merged peak, force-balance
wall units), and its projection n (se / (E value))^2 windows.
usage: convergence_check.py REPO OUT"""
import csv
import math
import os
import subprocess
import sys

import netCDF4
import numpy as np

repo, out = sys.argv[1], sys.argv[2]
f = os.path.join(repo, "jobs/states/mfu180w_dr6c4_s1_stats.nc")
res = subprocess.run([sys.executable, os.path.join(repo, "stats/python/chansph-stats"),
                      "convergence", f, "--no-plot", "--out", out, "--target", "0.02"],
                     capture_output=True, text=True)
print(res.stdout[-2000:] + res.stderr[-2000:])
if res.returncode != 0:
    sys.exit("FAIL: convergence exited %d" % res.returncode)
with netCDF4.Dataset(f) as d:
    g = d["eulerian"]
    mom, win = np.asarray(g["moments"][:], float), np.asarray(g["windows"][:], float)
    done = np.asarray(g["window_complete"][:]) > 0
    delta = float(d.delta)
ut2 = delta * win[:, 3].sum() / win[:, 2].sum()
m = mom[done & (win[:, 2] > 0)]
n = m[:, :, 0]
uvw = -m[:, :, 12] / np.where(n > 0, n, 1) / ut2           # each window's -u'v'+
N = n.sum(axis=0)
mean_u, mean_v = (np.sum(m[:, :, k] * n, axis=0) / N for k in (1, 2))
c2 = np.sum(m[:, :, 12] + n * (m[:, :, 1] - mean_u) * (m[:, :, 2] - mean_v), axis=0)
b = int(np.argmax(-c2 / N / ut2))                           # the bin of the merged peak
se = np.std(uvw[:, b], ddof=1) / math.sqrt(len(uvw))
rows = [r for r in csv.reader(open(os.path.join(out, "convergence.csv"))) if r and r[0] == "-u'v'+"]
last = rows[-1]
got_se, got_v, got_n = float(last[5]), float(last[4]), int(last[1])
checks = [abs(got_se / se - 1) < 1e-8, got_n == len(uvw), abs(got_v / (-c2[b] / N[b] / ut2) - 1) < 1e-8]
ok = all(checks)
need = got_n * (abs(got_se / got_v) / 0.02) ** 2
line = [l for l in res.stdout.splitlines() if l.startswith("-u'v'+")][0]
ok &= abs(float(line.split()[-2]) / need - 1) < 1e-3
print("-u'v'+ peak over %d windows: %.6g +- %.6g (recomputed %.6g +- %.6g), %.1f windows to 2%%: %s"
      % (got_n, got_v, got_se, -c2[b] / N[b] / ut2, se, need, "PASS" if ok else "FAIL"))
sys.exit(0 if ok else 1)
