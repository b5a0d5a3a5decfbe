"""A/B table of turbulent runs: what each numerical setting does to resolved turbulence.

usage: chansph-stats ab_table RUN_DIR... [--from T0] [--to T1] [--markdown]

For each run directory (its stats.nc, log.txt and scene.used.ini), over the averaging windows
that lie inside [T0, T1] (default: the second half of the run), from the raw window sums:
the -u'v'+ peak, the u_rms+ peak, v_rms+ at its peak, U_b+, the correlation coefficient
R_uv = -u'v' / (u_rms v_rms) over 30 <= y+ <= 100, and the momentum budget (method of
planes; docs/stats-format.md): the shares of the total stress carried by the resolved
turbulence (-u'v') and by the pressure pair forces (the scheme's numerical stress) at y+ = 30
and y = delta/2, and by the eddy viscosity (LES; 0 in a quasi-DNS) at y+ = 30, with
batch-means standard errors of the window values; the closure error and
the momentum source; and the cost per eddy turnover delta/u_tau in particle-steps (wall
seconds depend on what else the machine ran; divide by `chansph bench`'s rate). Wall units from the force balance (u_tau^2 = delta f).
Runs whose stats.nc has the Reynolds-stress budgets get a second table over their averaging
range (output.t_average_start on): the redistribution terms of vv (pressure + wall) and ww
(pressure) at y+ = 15 and 40 against MKM's pressure-strain + pressure-diffusion, and the
pressure noise of k over its viscous term at y+ = 30.
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
            "res y+30", "pair y+30", "model y+30", "res d/2", "pair d/2", "closure", "source", "Mp-st/ETT"]
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
                     ms("ub"), ms("ruv"), ms("res_30"), ms("pair_30"), ms("model_30"), ms("res_half"),
                     ms("pair_half"), f"{np.nanmax([v.get('closure', math.nan) for v in vals]):.3f}",
                     ms("source"), f"{pst / 1e6:.0f}"])
        print(f"# {run}: windows {win[sel[0], 0]:.3g}-{win[sel[-1], 1]:.3g} ({len(sel)}), "
              f"u_tau {ut:.4g}", file=sys.stderr)
    table(cols, rows, a.markdown)
    budget_table(a.runs, a.markdown)


def table(cols, rows, markdown):
    """Print rows under cols, as markdown or aligned text."""
    if markdown:
        print("| " + " | ".join(cols) + " |")
        print("|" + "---|" * len(cols))
        for r in rows:
            print("| " + " | ".join(r) + " |")
    else:
        w = [max(len(c), *(len(r[i]) for r in rows)) for i, c in enumerate(cols)]
        print("  ".join(c.rjust(w[i]) for i, c in enumerate(cols)))
        for r in rows:
            print("  ".join(x.rjust(w[i]) for i, x in enumerate(r)))


# the budget columns: the redistribution into v and w against MKM (pressure + wall
# for vv, whose wall part holds the wall layer's wall-normal pressure; pressure for ww; MKM's
# pressure-strain + pressure-diffusion), at y+ = 15 and 40, and the pressure noise as a share
# of the viscous term of k at y+ = 30
BUDGET_COLS = (("vv p+w 15", "vv", ("pressure", "wall"), 15.0),
               ("vv p+w 40", "vv", ("pressure", "wall"), 40.0),
               ("ww p 15", "ww", ("pressure",), 15.0), ("ww p 40", "ww", ("pressure",), 40.0))


def budget_table(runs, markdown):
    """The Reynolds-stress budget columns of the runs whose stats.nc has them (over each run's
    averaging range, output.t_average_start to its end; wall units of the force balance):
    ours / MKM for BUDGET_COLS, and the k pressure noise over the k viscous term at y+ = 30."""
    from . import budget_compare as bc
    dns, rows = None, []
    for run in runs:
        ours = bc.read_budgets(os.path.join(run, "stats.nc"), "force")
        if ours is None:
            continue
        dns = dns or bc.read_dns()
        yp, t, row = ours["yplus"], ours["terms"], [os.path.basename(run.rstrip("/"))]
        for _, c, terms, level in BUDGET_COLS:
            k = int(np.argmin(np.abs(yp - level)))
            ref = np.interp(yp[k], dns[c]["y+"], dns[c]["p-strain"] + dns[c]["p-diff"])
            val = sum(t[c][n][0][k] for n in terms)
            se = math.sqrt(sum(t[c][n][1][k] ** 2 for n in terms))
            row.append(f"{val:.4f}±{se:.4f} ({ref:.4f})")
        k = int(np.argmin(np.abs(yp - 30.0)))
        noise = t["k"]["pressure_noise"][0][k] if "pressure_noise" in t["k"] else math.nan
        row.append(f"{noise / t['k']['viscous'][0][k]:.2f}")
        rows.append(row)
    if rows:
        print("\nReynolds-stress budgets over each run's averaging range, u_tau^4/nu (force "
              "balance); in brackets MKM's p-strain + p-diff at the bin's y+; noise/visc: k pressure "
              "noise over the k viscous term at y+ = 30:")
        table(["run"] + [c[0] for c in BUDGET_COLS] + ["noise/visc 30"], rows, markdown)
