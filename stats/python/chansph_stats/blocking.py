"""Blocking analysis of a long run: how large the standard errors really are.

usage: chansph-stats blocking [--units wall|force] [--min-blocks N] [--blocks K [--dns FILE]]
                             LABEL=RUN_DIR[+RUN_DIR...]@T0:T1

The standard errors of stats.nc are batch means over its averaging windows; they hold only if
the window means are uncorrelated, i.e. the windows span several correlation times. This tool
takes the completed windows inside [T0, T1] (chained runs as in error_vs_time), forms per window
the quantities below from the raw window sums (in wall units of the whole range's wall shear
stress, or of the force balance), and repeats the batch-means estimate with blocks of
L = 1, 2, 4, ... consecutive windows while at least N blocks (default 4) remain (Flyvbjerg &
Petersen 1989, J. Chem. Phys. 91, 461): se(L) = sd(block means) / sqrt(blocks). se(L) rises
with L until the blocks are longer than the correlation time and then levels off; the plateau is
the honest standard error. Printed per quantity: se(L) in % of the mean for every L, the
statistical inefficiency s = se(L)^2 / se(1)^2 at the largest L (the window values' variance
inflation), the correlation time
s * window / 2 it implies, and whether se levelled off (the last two se within 25% of each
other). Quantities: the peaks of -u'v'+, u_rms+, v_rms+, w_rms+ (the peak of each window's
profile), U+ at y+ = 30 and at the centre, and U_b+ (the bins' mean of U+).

--blocks K adds the estimate a reference DNS usually quotes: the range cut into K equal
consecutive blocks of whole windows (the remainder left out), each quantity formed from each
block's own pooled profile, se = sd(K block values) / sqrt(K), without a correction for the
correlation between blocks. With --dns FILE, a same-box table with standard errors
(stats/dns/samebox: K = 5 blocks of 3 turnovers), the reference's own errors are printed
beside, at its peaks, at y+ = 30 and at the centre, so that a run and its reference are
compared by the same estimator.
"""
import math

import numpy as np

from . import cli
from .cli import InputError
from .dns import read_dns
from .merge import merged_profile, pooled_windows

QUANTITIES = ("-u'v'+ peak", "u_rms+ peak", "v_rms+ peak", "w_rms+ peak", "U+ y+30", "U+ centre",
              "U_b+")


def window_quantities(pool, i):
    """The QUANTITIES of window i of a pooled record, in the record's units."""
    return profile_quantities(merged_profile(pool, [i]))


def profile_quantities(p):
    """The QUANTITIES of a merged profile (merged_profile)."""
    yp, u = p["yplus"], p["U+"]
    ok = np.isfinite(yp) & np.isfinite(u)
    k30 = int(np.nanargmin(np.abs(np.where(ok, yp, np.inf) - 30.0)))
    kc = int(np.nanargmax(np.where(ok, yp, -np.inf)))
    return [np.nanmax(p["-u'v'+"]), np.nanmax(p["u_rms+"]), np.nanmax(p["v_rms+"]),
            np.nanmax(p["w_rms+"]), u[k30], u[kc], np.nanmean(u[ok])]


def blocking(x, min_blocks):
    """[(L, blocks, se)] for L = 1, 2, 4, ... with at least min_blocks blocks."""
    out, L = [], 1
    while len(x) // L >= max(min_blocks, 2):
        nb = len(x) // L
        m = x[:nb * L].reshape(nb, L).mean(axis=1)
        out.append((L, nb, np.std(m, ddof=1) / math.sqrt(nb)))
        L *= 2
    return out


def equal_blocks(pool, n, k):
    """The QUANTITIES of k equal consecutive blocks of the n windows of pool, each from the
    block's pooled profile: an array (k, len(QUANTITIES))."""
    size = n // k
    return np.array([profile_quantities(merged_profile(pool, list(range(b * size, (b + 1) * size))))
                     for b in range(k)])


def reference_errors(path):
    """A same-box DNS table's own standard errors (in % of its value) of the QUANTITIES it has:
    at its peaks (rms and -u'v'+), at y+ = 30 and at the centre (U+); NaN for U_b+."""
    d = read_dns(path)
    if d.get("U+_se") is None:
        raise InputError(f"--dns {path}: the table has no standard errors (a same-box table has)")
    out = []
    for q in ("-u'v'+", "u_rms+", "v_rms+", "w_rms+"):
        k = int(np.argmax(d[q]))
        out.append(100.0 * d[q + "_se"][k] / d[q][k])
    k30 = int(np.argmin(np.abs(d["yplus"] - 30.0)))
    kc = int(np.argmax(d["yplus"]))
    out += [100.0 * d["U+_se"][k30] / d["U+"][k30], 100.0 * d["U+_se"][kc] / d["U+"][kc], math.nan]
    return out


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("spec", help="LABEL=RUN_DIR[+RUN_DIR...]@T0:T1")
    ap.add_argument("--units", choices=("wall", "force"), default="wall")
    ap.add_argument("--min-blocks", type=int, default=4)
    ap.add_argument("--blocks", type=int, default=0,
                    help="also the standard error from K equal blocks (a reference's estimate)")
    ap.add_argument("--dns", help="with --blocks: a same-box table whose own errors to print")
    a = ap.parse_args(argv)
    if a.dns and not a.blocks:
        raise InputError("--dns goes with --blocks K")
    ref = reference_errors(a.dns) if a.dns else None
    label, dirs, t0, t1 = cli.run_spec(a.spec)
    if a.min_blocks < 2:
        raise InputError(f"--min-blocks {a.min_blocks}: need at least 2")
    pool, times = pooled_windows(dirs, t0, t1, a.units)
    n = len(times)
    if n < 2 * a.min_blocks:
        raise InputError(f"{a.spec}: {n} windows; blocking needs at least {2 * a.min_blocks}")
    if a.blocks and not 2 <= a.blocks <= n:
        raise InputError(f"--blocks {a.blocks}: need 2 to {n} (the windows of {a.spec})")
    lens = np.array([b - s for s, b in times])
    w = float(np.median(lens))
    vals = np.array([window_quantities(pool, i) for i in range(n)])
    print(f"# {label}: {n} windows of {w:.4g} delta/u_tau, t = {times[0][0]:.4g}-{times[-1][1]:.4g}"
          f", {a.units} units (u_tau {pool['ut']:.4g}); se(L) in % of the mean, blocks of L "
          f"windows")
    res = [blocking(vals[:, q], a.min_blocks) for q in range(len(QUANTITIES))]
    head = "  ".join(f"L={L:<2d}({nb:2d})" for L, nb, _ in res[0])
    print(f"# {'quantity':<12} {'mean':>7}  {head}   ineff  corr time  plateau")
    for q, name in enumerate(QUANTITIES):
        mean = np.mean(vals[:, q])
        se = [s for _, _, s in res[q]]
        scale = 100.0 / abs(mean) if abs(mean) > 0 else math.nan  # NaN mean: NaN too
        cells = "  ".join(f"{s * scale:8.2f}%" for s in se)
        ineff = se[-1] ** 2 / se[0] ** 2 if se[0] > 0 else math.nan
        flat = len(se) >= 2 and se[-1] <= 1.25 * se[-2]
        print(f"  {name:<12} {mean:7.3f}  {cells}   {ineff:5.1f}  {0.5 * ineff * w:9.3g}  "
              f"{'yes' if flat else 'no'}")
    if a.blocks:
        size = n // a.blocks
        bv = equal_blocks(pool, n, a.blocks)
        print(f"# {a.blocks} equal blocks of {size} windows ({size * w:.4g} delta/u_tau; "
              f"{n - a.blocks * size} left out): se = sd(block values) / sqrt({a.blocks}), in % of "
              f"the mean" + (f"; reference {a.dns}: its own se at its peak" if ref else ""))
        for q, name in enumerate(QUANTITIES):
            m = np.mean(bv[:, q])
            se = np.std(bv[:, q], ddof=1) / math.sqrt(a.blocks)
            pct = 100.0 * se / abs(m) if abs(m) > 0 else math.nan
            extra = f"   reference {ref[q]:6.2f}%" if ref and math.isfinite(ref[q]) else ""
            print(f"  {name:<12} {m:7.3f}  {pct:6.2f}%{extra}")
    return 0
