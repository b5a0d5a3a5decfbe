#!/usr/bin/python3
"""The numerical pair stress read as a viscosity (stats/python/chansph_stats/numvisc.py).

usage: numvisc_check.py ROOT CHANSPH STATS.nc OUT
  1. Synthetic: the same-box DNS in the wall units of nu (1 + c), c = 0.5 (y+ = 1.5 y*+, bins
     of 4.5 wall units), with the pair stress c dU+/dy+: nu_num / nu comes out as c, y*+ as
     y+ / 1.5, the deviations in y*+ vanish (U+, the stresses below 0.5% of their peaks) where
     those in y+ do not (above 5%), and the peaks come back to the DNS's positions in y*+. An
     unfolded run (every position twice) gives the same; a constant c of 0 leaves y*+ = y+; a
     run with no bins over 10 < y+ < 60 prints the ratio and no table (no NaN).
  2. compare on a run's stats.nc with the momentum budget prints the table and writes
     numerical_viscosity.csv, whose nu_num / nu equals pair_stress / (nu dU/dy) computed here
     from the file in SI units (the same central differences: equal to the CSV's 7 significant
     digits, 2e-6).
Prints PASS or FAIL lines; exit status 1 on any FAIL.
"""
import contextlib
import io
import os
import subprocess
import sys

import netCDF4
import numpy as np

ROOT, CHANSPH, STATS, OUT = sys.argv[1:5]
sys.path.insert(0, os.path.join(ROOT, "stats", "python"))
from chansph_stats import numvisc  # noqa: E402
from chansph_stats.dns import QUANTITIES, read_dns  # noqa: E402
from passfail import check, finish  # noqa: E402

os.makedirs(OUT, exist_ok=True)
dns = read_dns(os.path.join(ROOT, "stats", "dns", "samebox", "box_2x2x1.4.txt"))
c = 0.5
yp = 2.25 + 4.5 * np.arange(40)
ystar = yp / (1 + c)
ours = {"yplus": yp, "source": "synthetic"}
for q in QUANTITIES:
    ours[q] = np.interp(ystar, dns["yplus"], dns[q])
# dU+/dy+ by the same central differences the tool uses: nu_num / nu = c exactly
ours["budget:pair_stress"] = c * np.gradient(ours["U+"], yp)
res = numvisc.report(ours, dns, OUT, QUANTITIES)
check(res is not None, "a run with the pair stress gets the table")
r, ys = res
inner = (yp > 5) & (yp < 150)
check(np.allclose(r[inner], c, rtol=1e-12), "nu_num / nu = %g (got %.6f-%.6f)"
      % (c, np.nanmin(r[inner]), np.nanmax(r[inner])))
check(np.allclose(ys, ystar, rtol=1e-12), "y*+ = y+ / (1 + c) (largest difference %.2e)"
      % np.max(np.abs(ys - ystar)))
nominal = numvisc.deviations(yp, ours, dns, QUANTITIES, 10, 60)
effective = numvisc.deviations(ys, ours, dns, QUANTITIES, 10, 60)
check(all(effective[q][0] < 0.005 for q in effective),
      "deviations in y*+ below 0.5%% of the peaks: %s"
      % {q: round(100 * v[0], 3) for q, v in effective.items()})
check(all(nominal[q][0] > 0.05 for q in ("U+", "u_rms+", "-u'v'+")),
      "deviations in y+ above 5%%: %s" % {q: round(100 * v[0], 1) for q, v in nominal.items()})
for q in ("u_rms+", "-u'v'+"):
    want = numvisc.peak_position(dns["yplus"], dns[q])
    check(abs(effective[q][1] - want) < 1.0 and abs(nominal[q][1] - (1 + c) * want) < 1.5,
          "%s peak at y*+ %.1f (DNS %.1f), at y+ %.1f (1.5 times)" % (q, effective[q][1], want,
                                                                       nominal[q][1]))
# unfolded: each position twice (the mirrored upper half, equal to rounding)
twice = {k: (np.repeat(v, 2) if isinstance(v, np.ndarray) else v) for k, v in ours.items()}
twice["yplus"] = np.repeat(yp, 2) * (1 + np.tile([0.0, 1e-14], 40))
r2, ys2 = numvisc.report(twice, dns, OUT, QUANTITIES)
check(len(ys2) == 40 and np.allclose(ys2, ys, rtol=1e-12) and np.allclose(r2[inner], c),
      "an unfolded run (every position twice) gives the same y*+ and nu_num / nu")
zero = dict(ours, **{"budget:pair_stress": np.zeros_like(yp)})
_, ys0 = numvisc.report(zero, dns, OUT, QUANTITIES)
check(np.allclose(ys0, yp, rtol=1e-12), "no pair stress: y*+ = y+")
low = {k: (v[:2] if isinstance(v, np.ndarray) else v) for k, v in ours.items()}  # y+ < 7
printed = io.StringIO()
with contextlib.redirect_stdout(printed):
    numvisc.report(low, dns, OUT, QUANTITIES)
check("no comparison in y*+" in printed.getvalue() and "nan" not in printed.getvalue(),
      "a run without bins over 10 < y+ < 60 (a laminar or tiny one): the ratio, no table, no NaN "
      "(%s)" % printed.getvalue().strip().splitlines()[-1])
check(numvisc.report({"yplus": yp, "U+": ours["U+"]}, dns, OUT, QUANTITIES) is None,
      "a file without the momentum budget: no table")

# 2. compare on a run's file
samebox = os.path.join(ROOT, "stats", "dns", "samebox", "box_2x2x1.4.txt")
p = subprocess.run([CHANSPH, "compare", STATS, "--dns", samebox, "--out", OUT + "/run",
                    "--no-plots"], capture_output=True, text=True)
text = p.stdout + p.stderr
check(p.returncode == 0 and "numerical viscosity" in text and "dev y*+" in text,
      "compare prints the numerical viscosity table (exit %d)" % p.returncode)
csv = os.path.join(OUT, "run", "numerical_viscosity.csv")
check(os.path.exists(csv), "compare writes numerical_viscosity.csv")
if os.path.exists(csv):
    a = np.loadtxt(csv, delimiter=",", comments="#", skiprows=3)
    with netCDF4.Dataset(STATS) as d:
        nu, delta = float(d.nu), float(d.delta)
        y, u, pair = d["y_mean"][:].filled(np.nan), d["u_mean"][:].filled(np.nan), \
            d["pair_stress"][:].filled(np.nan)
        ut = float(d.u_tau_wall)
        folded = int(d.getncattr("fold")) == 1 if "fold" in d.ncattrs() else False
    if folded:
        g = np.gradient(u, y)
        want = np.where(g > 0, pair / (nu * np.where(g > 0, g, 1)), np.nan)
        got = np.interp(y * ut / nu, a[:, 0], a[:, 2])
        ok = np.isfinite(want) & (y * ut / nu > 5) & (y * ut / nu < 150)
        check(ok.sum() > 10 and np.allclose(got[ok], want[ok], rtol=2e-6, atol=0),
              "nu_num / nu of the CSV = pair_stress / (nu dU/dy) from the file (%d bins, largest "
              "relative difference %.1e)" % (ok.sum(), np.max(np.abs(got[ok] / want[ok] - 1))))
    else:  # an unfolded file: the CSV has each position once
        check(len(a) == int((y < delta).sum()) and np.all(np.diff(a[:, 0]) > 0),
              "an unfolded file's CSV has each position once (%d rows)" % len(a))
finish()
