"""A/B table of turbulent runs: what each numerical setting does to resolved turbulence.

usage: chansph-stats ab_table RUN_DIR... [--from T0] [--to T1] [--markdown]

For each run directory (its stats.nc, log.txt and scene.used.ini), over the averaging windows
that lie inside [T0, T1] (default: the second half of the run), from the raw window sums:
the -u'v'+ peak, the u_rms+ peak, v_rms+ at its peak, U_b+, the correlation coefficient
R_uv = -u'v' / (u_rms v_rms) over 30 <= y+ <= 100, and the momentum budget (method of
planes; docs/stats-format.md): the shares of the total stress carried by the resolved
turbulence (-u'v') and by the pressure pair forces (the scheme's numerical stress) at y+ = 30
and y = delta/2, with batch-means standard errors of the window values; the closure error and
the momentum source; and the cost per eddy turnover delta/u_tau in particle-steps (wall
seconds depend on what else the machine ran; divide by `chansph bench`'s rate). Wall units from the force balance (u_tau^2 = delta f).
"""
import math
import os
import re
import sys

import numpy as np

from . import cli
from .cli import InputError
from .merge import window_values
from .ncfile import read_windows


def cost(run, ut, delta):
    """(particle-steps, wall seconds) per eddy turnover delta/u_tau from the log."""
    try:
        log = open(os.path.join(run, "log.txt")).read()
    except OSError:
        return math.nan, math.nan
    steps = re.findall(r"step\s+(\d+)\s+t\s+(\S+)\s+dt", log)
    rate = re.findall(r"(\S+) p-steps/s", log)
    nfl = re.search(r"(\d+) fluid", log)
    if len(steps) < 2 or not nfl:
        return math.nan, math.nan
    (s0, t0), (s1, t1) = steps[1], steps[-1]
    s0, s1, t0, t1 = int(s0), int(s1), float(t0), float(t1)
    if not t1 > t0:  # a log with fewer than two step lines after the first
        return math.nan, math.nan
    per_ett = (s1 - s0) / (t1 - t0) * delta / ut * int(nfl.group(1))
    r = [float(x) for x in rate[1:] if float(x) > 0]
    return per_ett, per_ett / np.median(r) if r else math.nan


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--from", dest="t0", type=cli.number())
    ap.add_argument("--to", dest="t1", type=cli.number())
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args(argv)
    cols = ["run", "-u'v'+ pk", "u_rms+ pk", "v_rms+ pk", "U_b+", "R_uv",
            "res y+30", "pair y+30", "res d/2", "pair d/2", "closure", "source", "Mp-st/ETT"]
    rows = []
    for run in a.runs:
        r = read_windows(os.path.join(run, "stats.nc"))
        win, mom, pln, delta, ut = r["win"], r["mom"], r["pln"], r["delta"], r["ut"]
        tend = win[:, 1].max()
        t_end = r["t_reached"] if r["t_reached"] is not None else tend
        t0 = a.t0 if a.t0 is not None else 0.5 * (win[0, 0] + min(tend, t_end))
        t1 = a.t1 if a.t1 is not None else math.inf
        sel = [i for i in range(len(win)) if win[i, 0] >= t0 - 1e-12 and win[i, 1] <= t1 + 1e-12
               and r["done"][i]]
        if not sel:
            raise InputError(f"{run}: no complete window inside [{t0}, {t1}]")
        vals = window_values(mom[sel], pln[sel] if pln is not None else [None] * len(sel),
                             delta, r["fold"], ut, r["nu"])

        def ms(key):
            x = np.array([v.get(key, math.nan) for v in vals], dtype=float)
            m = np.nanmean(x)
            se = np.nanstd(x, ddof=1) / math.sqrt(np.sum(np.isfinite(x))) if len(x) > 1 else math.nan
            return f"{m:.3f}±{se:.3f}"
        pst, wall = cost(run, ut, delta)
        rows.append([os.path.basename(run.rstrip("/")), ms("uv_peak"), ms("urms"), ms("vrms"),
                     ms("ub"), ms("ruv"), ms("res_30"), ms("pair_30"), ms("res_half"),
                     ms("pair_half"), f"{np.nanmax([v.get('closure', math.nan) for v in vals]):.3f}",
                     ms("source"), f"{pst / 1e6:.0f}"])
        print(f"# {run}: windows {win[sel[0], 0]:.3g}-{win[sel[-1], 1]:.3g} ({len(sel)}), "
              f"u_tau {ut:.4g}", file=sys.stderr)
    if a.markdown:
        print("| " + " | ".join(cols) + " |")
        print("|" + "---|" * len(cols))
        for r in rows:
            print("| " + " | ".join(r) + " |")
    else:
        w = [max(len(c), *(len(r[i]) for r in rows)) for i, c in enumerate(cols)]
        print("  ".join(c.rjust(w[i]) for i, c in enumerate(cols)))
        for r in rows:
            print("  ".join(x.rjust(w[i]) for i, x in enumerate(r)))
