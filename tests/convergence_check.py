#!/usr/bin/python3
"""chansph-stats convergence on a shipped stats.nc: its standard error of the -u'v'+ peak over
all the complete windows must be the batch-means error recomputed here from the raw window
moments with numpy (each window's own C2_uv / count at the bin of the merged peak, force-balance
wall units), and its projection n (se / (E value))^2 windows.
Then on a short run of its own (the 3-D Poiseuille scene, 0.5 s of 0.1 s windows, budgets at
every sample, Lagrangian releases every 0.05 s over 0.1 s, unfolded): the budgets' main terms re-averaged
by the tool over every window must be the file's own rsb_* and rsb_*_stderr (the C engine's
reconstruction, euler_rs.c) at their bins, their running average must move (the first point
is not the last), and T_L's curve must be the running mean and standard error (std / sqrt(n))
of the file's history T_L_release recomputed here, point by point at the times the releases
completed, its last point the file's T_L_release_mean and T_L_stderr.
usage: convergence_check.py REPO OUT CHANSPH"""
import csv
import math
import os
import subprocess
import sys

import netCDF4
import numpy as np

repo, out, chansph = sys.argv[1], sys.argv[2], sys.argv[3]
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

# the budgets and T_L on a run of its own
run = os.path.join(out, "run")
res = subprocess.run([chansph, "run", os.path.join(repo, "jobs/scenes/poiseuille3d.ini"), "--out",
                      run, "--overwrite", "--set", "time.t_end=0.6",
                      "--set", "output.t_average_start=0.1", "--set", "stats.window=0.1",
                      "--set", "stats.u_tau_ref=0.6", "--set", "stats.budget_every=1",
                      "--set", "output.stats_every=2", "--set", "lagrangian.y_plus=1,2",
                      "--set", "lagrangian.horizon=0.1", "--set", "lagrangian.release_every=0.05",
                      "--set", "lagrangian.n_lags=5", "--set", "fluid.nu=0.01"], capture_output=True, text=True)
if res.returncode != 0:
    sys.exit("FAIL: the run exited %d: %s" % (res.returncode, res.stderr[-2000:]))
f = os.path.join(run, "stats.nc")
res = subprocess.run([sys.executable, os.path.join(repo, "stats/python/chansph-stats"),
                      "convergence", f, "--no-plot", "--out", out], capture_output=True, text=True)
print(res.stdout[-3000:] + res.stderr[-2000:])
if res.returncode != 0:
    sys.exit("FAIL: convergence exited %d on the run" % res.returncode)
series = {}
for r in csv.reader(open(os.path.join(out, "convergence.csv"))):
    if len(r) == 7 and r[0] != "quantity":
        series.setdefault(r[0], []).append([float(x) for x in r[1:]])
with netCDF4.Dataset(f) as d:
    g = d["eulerian"]
    win = np.asarray(g["windows"][:], float)
    delta, nu = float(d.delta), float(d.nu)
    ut = math.sqrt(delta * win[:, 3].sum() / win[:, 2].sum())
    y = np.ma.filled(d["y_mean"][:].astype(float), np.nan)
    lower = np.isfinite(np.ma.filled(d["u_mean"][:].astype(float), np.nan)) & (y < delta)
    yplus = y * ut / nu
    scale = nu / ut ** 4
    checked = 0
    for target in (15.0, 30.0):
        b = int(np.nanargmin(np.where(lower, np.abs(yplus - target), np.inf)))
        for c, t in (("uu", "production"), ("uu", "pressure"), ("uu", "viscous"),
                     ("vv", "pressure"), ("vv", "viscous"), ("ww", "pressure"),
                     ("ww", "viscous")):
            name = "%s_%s(y+ %.0f)" % (c, t, yplus[b])
            want = float(d["rsb_%s_%s" % (c, t)][b]) * scale
            want_se = float(d["rsb_%s_%s_stderr" % (c, t)][b]) * scale
            top = np.nanmax(np.abs(np.ma.filled(d["rsb_%s_%s" % (c, t)][:], np.nan))) * scale
            ser = series.get(name)
            good = ser is not None and len(ser) >= 2
            if good:
                last = ser[-1]
                good = (abs(last[3] - want) <= 1e-8 * top and
                        abs(last[4] - want_se) <= 1e-6 * abs(want_se) + 1e-12 * top and
                        ser[0][3] != last[3])
            print("%s: last point %s, file %.6g +- %.6g: %s" %
                  (name, "%.6g +- %.6g over %d windows" % (last[3], last[4], last[0])
                   if ser else "missing", want, want_se, "PASS" if good else "FAIL"))
            ok &= good
            checked += 1
    lg = d["lagrangian"]
    releases = int(lg.releases)
    hist = np.ma.filled(lg["T_L_release"][:].astype(float), np.nan)
    hist_t = np.asarray(lg["release"][:], float)
    if hist.shape[0] != releases:
        ok = False
        print("FAIL: the history holds %d rows of %d releases" % (hist.shape[0], releases))
    for lev, yp in enumerate(np.asarray(lg["y_plus"][:], float)):
        for k, comp in enumerate("uvw"):
            m = float(np.ma.filled(lg["T_L_release_mean"][lev, k], np.nan))
            e = float(np.ma.filled(lg["T_L_stderr"][lev, k], np.nan))
            name = "T_L_%s(y+ %g)" % (comp, yp)
            use = np.isfinite(hist[:, lev, k])
            v, tv = hist[use, lev, k], hist_t[use]
            ser = series.get(name)
            if len(v) < 2:
                good = ser is None and not math.isfinite(e)
            else:
                # every point: the running mean and std / sqrt(n) of the first n finite
                # releases, at the time the n-th completed; the last one the file's
                want = [(n, tv[n - 1], np.mean(v[:n]), np.std(v[:n], ddof=1) / math.sqrt(n))
                        for n in range(2, len(v) + 1)]
                good = ser is not None and len(ser) == len(want) and all(
                    p[0] == w[0] and abs(p[1] - w[1]) <= 1e-9 * w[1] and abs(p[3] - w[2]) <= 1e-9 * abs(w[2]) and
                    abs(p[4] - w[3]) <= 1e-9 * abs(w[3]) for p, w in zip(ser, want))
                good = good and abs(ser[-1][3] / m - 1) < 1e-9 and abs(ser[-1][4] / e - 1) < 1e-9
                checked += 1
            print("%s: file %.6g +- %.6g over %d releases (%d finite); curve of %d points, last "
                  "%s: %s" % (name, m, e, releases, len(v), len(ser) if ser else 0,
                              "%.6g +- %.6g at t = %.4g" % (ser[-1][3], ser[-1][4], ser[-1][1])
                              if ser else "-", "PASS" if good else "FAIL"))
            ok &= good
if checked < 15:
    ok = False
    print("FAIL: only %d budget and T_L quantities checked (expected 14 budget terms and T_L)"
          % checked)
sys.exit(0 if ok else 1)
