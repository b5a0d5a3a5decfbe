#!/usr/bin/python3
"""chansph-stats blocking (issue 24: honest standard errors of a long run).

1. The estimator on synthetic series of known correlation: an AR(1) series x_i = phi x_(i-1) +
   e_i (phi = 0.8, 8192 values, fixed seed) has the variance of its mean inflated by
   s = (1 + phi) / (1 - phi) = 9; blocks of 256 give a standard error within 25% of the exact
   sqrt(s var / n), while single values underestimate it threefold (se(1) < 0.5 of it); an
   uncorrelated series keeps se(64) within 25% of se(1).
2. The per-window quantities on a real stats.nc: each window's -u'v'+ and u_rms+ peaks and U+
   at the centre as the tool forms them equal those of window_profile over that window alone
   (force units), and the command prints every quantity and exits 0.
3. --blocks K: each block's quantities are those of window_profile over the block's whole
   span, the reference's own errors (--dns, a same-box table) are its *_se over its value at its
   peak, and the command prints both; --dns without --blocks is an input error (exit 1).

usage: blocking_check.py ROOT STATS_RUN_DIR T0:T1
"""
import math
import os
import subprocess
import sys

import numpy as np

ROOT, RUN, SPAN = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, os.path.join(ROOT, "stats", "python"))
from chansph_stats.blocking import (QUANTITIES, blocking, equal_blocks,  # noqa: E402
                                    reference_errors, window_quantities)
from chansph_stats.dns import read_dns  # noqa: E402
from chansph_stats.merge import pooled_windows, window_profile  # noqa: E402
from passfail import check, finish  # noqa: E402


rng = np.random.default_rng(1)
n, phi = 8192, 0.8
e = rng.standard_normal(n)
x = np.empty(n)
x[0] = e[0] / math.sqrt(1 - phi * phi)
for i in range(1, n):
    x[i] = phi * x[i - 1] + e[i]
exact = math.sqrt((1 + phi) / (1 - phi) * (1 / (1 - phi * phi)) / n)
res = {L: se for L, _, se in blocking(x, 32)}
check(abs(res[256] / exact - 1) < 0.25 and res[1] < 0.5 * exact,
      f"AR(1) phi = 0.8: se(256) / exact = {res[256] / exact:.3f}, se(1) / exact = "
      f"{res[1] / exact:.3f}")
iid = {L: se for L, _, se in blocking(e, 32)}
check(abs(iid[64] / iid[1] - 1) < 0.25, f"uncorrelated: se(64) / se(1) = {iid[64] / iid[1]:.3f}")

t0, t1 = (float(v) for v in SPAN.split(":"))
pool, times = pooled_windows(RUN, t0, t1, "force")
worst = 0.0
for i, (a, b) in enumerate(times):
    q = window_quantities(pool, i)
    p, _ = window_profile(RUN, a, b, "force")
    ref = [np.nanmax(p["-u'v'+"]), np.nanmax(p["u_rms+"]), p["U+"][int(np.nanargmax(p["yplus"]))]]
    got = [q[0], q[1], q[5]]
    worst = max(worst, max(abs(g - r) / max(abs(r), 1e-300) for g, r in zip(got, ref)))
check(len(times) >= 4 and worst < 1e-12,
      f"{len(times)} windows: per-window quantities = window_profile's, worst {worst:.1e}")
out = subprocess.run([os.path.join(ROOT, "stats", "python", "chansph-stats"), "blocking",
                      "--units", "force", "--min-blocks", "2", f"run={RUN}@{SPAN}"],
                     capture_output=True, text=True)
print(out.stdout, end="")
check(out.returncode == 0 and all(q in out.stdout for q in QUANTITIES),
      f"the command (exit {out.returncode}) prints all {len(QUANTITIES)} quantities {out.stderr}")

# 3. equal blocks and the reference's own errors
bv = equal_blocks(pool, len(times), 2)
size = len(times) // 2
worst = 0.0
for b in range(2):
    p, _ = window_profile(RUN, times[b * size][0], times[(b + 1) * size - 1][1], "force")
    ref = [np.nanmax(p["-u'v'+"]), np.nanmax(p["u_rms+"]), np.nanmax(p["v_rms+"]),
           np.nanmax(p["w_rms+"]), p["U+"][int(np.nanargmax(p["yplus"]))]]
    got = [bv[b, 0], bv[b, 1], bv[b, 2], bv[b, 3], bv[b, 5]]
    worst = max(worst, max(abs(g - r) / max(abs(r), 1e-300) for g, r in zip(got, ref)))
check(worst < 1e-12, f"2 blocks of {size} windows: block quantities = window_profile over the "
      f"block's span, worst {worst:.1e}")
box = os.path.join(ROOT, "stats", "dns", "samebox", "box_2x2x1.4.txt")
d = read_dns(box)
kv = int(np.argmax(d["v_rms+"]))
re = reference_errors(box)
check(abs(re[2] - 100 * d["v_rms+_se"][kv] / d["v_rms+"][kv]) < 1e-12 and 1.0 < re[2] < 3.0,
      f"same-box reference: v_rms+ se at its peak {re[2]:.3f}% = its table's")
tool = os.path.join(ROOT, "stats", "python", "chansph-stats")
out = subprocess.run([tool, "blocking", "--units", "force", "--min-blocks", "2", "--blocks", "2",
                      "--dns", box, f"run={RUN}@{SPAN}"], capture_output=True, text=True)
print(out.stdout, end="")
check(out.returncode == 0 and "2 equal blocks" in out.stdout and "reference" in out.stdout,
      f"--blocks 2 --dns: exit {out.returncode}, prints the blocks and the reference {out.stderr}")
bad = subprocess.run([tool, "blocking", "--dns", box, f"run={RUN}@{SPAN}"],
                     capture_output=True, text=True)
check(bad.returncode == 1 and "--dns goes with --blocks" in bad.stderr,
      f"--dns without --blocks: exit {bad.returncode}, {bad.stderr.strip()}")
finish()
