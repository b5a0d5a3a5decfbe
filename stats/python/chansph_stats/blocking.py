"""Blocking analysis of a long run: how large the standard errors really are.

usage: chansph-stats blocking [--units wall|force] [--min-blocks N] LABEL=RUN_DIR[+RUN_DIR...]@T0:T1

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
"""
import math

import numpy as np

from . import cli
from .cli import InputError
from .merge import merged_profile, pooled_windows

QUANTITIES = ("-u'v'+ peak", "u_rms+ peak", "v_rms+ peak", "w_rms+ peak", "U+ y+30", "U+ centre",
              "U_b+")


def window_quantities(pool, i):
    """The QUANTITIES of window i of a pooled record, in the record's units."""
    p = merged_profile(pool, [i])
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


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("spec", help="LABEL=RUN_DIR[+RUN_DIR...]@T0:T1")
    ap.add_argument("--units", choices=("wall", "force"), default="wall")
    ap.add_argument("--min-blocks", type=int, default=4)
    a = ap.parse_args(argv)
    label, dirs, t0, t1 = cli.run_spec(a.spec)
    if a.min_blocks < 2:
        raise InputError(f"--min-blocks {a.min_blocks}: need at least 2")
    pool, times = pooled_windows(dirs, t0, t1, a.units)
    n = len(times)
    if n < 2 * a.min_blocks:
        raise InputError(f"{a.spec}: {n} windows; blocking needs at least {2 * a.min_blocks}")
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
    return 0
