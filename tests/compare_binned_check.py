#!/usr/bin/python3
"""chansph compare --binned: the DNS as a particle-binned profile sees it (dns.through_bins).

usage: compare_binned_check.py ROOT CHANSPH STATS.nc OUT
  1. A linear mean profile U+ = a y+ with uniform stresses, through a bin of width w+: U+ is
     a times the bin centre, u_rms+^2 gains exactly the spread of U+ over the bin,
     (a w+)^2 / 12 (midpoint rule: times 1 - 1/n^2), v_rms+, w_rms+ and -u'v'+ nothing; the
     wall bin [0, 9] with its particles' mean at 3 is seen over [0, 6].
  2. compare --binned on a run's stats.nc says it compares with the binned DNS, and its
     errors differ from the interpolated comparison's only where the bins change the DNS;
     a DNS file (no bins) is refused with a message, exit 1.
Prints PASS or FAIL lines; exit status 1 on any FAIL.
"""
import os
import subprocess
import sys

import numpy as np

ROOT, CHANSPH, STATS, OUT = sys.argv[1:5]
sys.path.insert(0, os.path.join(ROOT, "stats", "python"))
from chansph_stats.dns import through_bins  # noqa: E402
from passfail import check, finish  # noqa: E402


a, n = 0.5, 400
y = np.linspace(0.0, 200.0, 2001)
dns = {"yplus": y, "U+": a * y, "u_rms+": np.full_like(y, 2.0), "v_rms+": np.full_like(y, 0.7),
       "w_rms+": np.full_like(y, 0.9), "-u'v'+": np.full_like(y, 0.6)}
lo, hi, at = np.array([10.0, 0.0]), np.array([16.0, 9.0]), np.array([13.0, 3.0])
b = through_bins(dns, lo, hi, at, n)
width = np.array([6.0, 6.0])  # the wall bin: [0, 6], centred on its particles' mean
expect_u2 = 4.0 + (a * width) ** 2 / 12.0 * (1.0 - 1.0 / n ** 2)
check(np.allclose(b["U+"], a * at, rtol=1e-12), "U+ through the bins = a y+ at the bin centre")
check(np.allclose(b["u_rms+"] ** 2, expect_u2, rtol=1e-10),
      "u_rms+^2 gains (a w+)^2/12: %s (expected %s)" % (b["u_rms+"] ** 2, expect_u2))
check(all(np.allclose(b[q], dns[q][0], rtol=1e-12) for q in ("v_rms+", "w_rms+", "-u'v'+")),
      "v_rms+, w_rms+ and -u'v'+ unchanged by the bins")


def compare(*extra):
    p = subprocess.run([CHANSPH, "compare", *extra, "--no-plots"], capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def csv(path):
    rows = {}
    for line in open(path):
        f = line.strip().split(",")
        if line.startswith("#") or f[0] == "quantity":
            continue
        rows[(f[0], f[1])] = float(f[4])  # Linf
    return rows


mkm = os.path.join(ROOT, "stats", "dns", "mkm1999", "chan180.means")
rc, out = compare(STATS, "--dns", mkm, "--out", OUT + "/binned", "--binned")
check(rc == 0 and "the DNS as the run's bins see it" in out, "compare --binned runs and says so")
rc, _ = compare(STATS, "--dns", mkm, "--out", OUT + "/points")
binned, points = csv(OUT + "/binned/compare.csv"), csv(OUT + "/points/compare.csv")
changed = {k for k in points if abs(binned[k] - points[k]) > 1e-12 * max(1.0, abs(points[k]))}
check(rc == 0 and any(k[0] == "u_rms+" for k in changed),
      "the binned DNS changes the u_rms+ errors (%d rows changed)" % len(changed))
rc, out = compare(mkm, "--dns", mkm, "--out", OUT + "/dns", "--binned")
check(rc == 1 and "no bin bounds" in out and "Traceback" not in out,
      "a DNS file with --binned: refused, exit 1 (%d: %s)" % (rc, out.strip()[-120:]))
finish()
