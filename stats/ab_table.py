#!/usr/bin/python3
"""A/B table of turbulent runs: what each numerical setting does to resolved turbulence.

usage: python3 stats/ab_table.py RUN_DIR... [--from T0] [--to T1] [--markdown]

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
import argparse
import math
import os
import re
import sys

import netCDF4
import numpy as np

MOM_N, MEAN = 0, 1
C2 = MEAN + 8
PL = {"n": 0, "pair": 1, "visc": 2, "model": 3, "wall": 4, "drive": 5, "source": 6}


def window_values(mom, pln, delta, fold, ut, nu):
    """Per-window indicators (arrays over the windows given)."""
    out = []
    for m, p in zip(mom, pln):
        n = m[:, MOM_N]
        ok = n > 0
        y = m[:, MEAN + 5]
        uu, vv, uv = (np.where(ok, m[:, C2 + k] / np.maximum(n, 1), np.nan) for k in (0, 1, 3))
        u = m[:, MEAN]
        if not fold:
            up = y > delta
            y = np.where(up, 2 * delta - y, y)
            uv = np.where(up, -uv, uv)
        yp = y * ut / nu
        muv = -uv / ut**2
        k = int(np.nanargmax(muv))
        band = ok & (yp >= 30) & (yp <= 100)
        r = dict(uv_peak=muv[k], y_peak=yp[k], urms=np.nanmax(np.sqrt(uu)) / ut,
                 vrms=np.nanmax(np.sqrt(vv)) / ut,
                 ruv=np.nanmean(-uv[band] / np.sqrt(uu[band] * vv[band])) if band.any() else math.nan,
                 ub=np.sum(u[ok] * n[ok]) / np.sum(n[ok]) / ut)
        if p is not None and p[:, 0].max() > 0:
            pn = np.maximum(p[:, 0], 1)
            parts = {key: p[:, i] / pn for key, i in PL.items() if key != "n"}
            if not fold:  # mirrored like -u'v' above: the stresses of the upper half change sign
                for key in parts:
                    parts[key] = np.where(up, -parts[key], parts[key])
            rey = -uv  # -u'v' towards the centre (upper half mirrored above)
            total = rey + parts["pair"] + parts["visc"] + parts["model"] + parts["wall"]
            for name, target in (("30", 30.0), ("half", 0.5 * delta * ut / nu)):
                i = int(np.nanargmin(np.abs(yp - target) + np.where(ok, 0, np.inf)))
                r["res_" + name] = rey[i] / total[i]
                r["pair_" + name] = parts["pair"][i] / total[i]
            r["closure"] = np.nanmax(np.abs(total - parts["drive"])) / ut**2
            r["source"] = np.nanmean(parts["source"]) / ut**2
        out.append(r)
    return out


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
    per_ett = (s1 - s0) / (t1 - t0) * delta / ut * int(nfl.group(1))
    r = [float(x) for x in rate[1:] if float(x) > 0]
    return per_ett, per_ett / np.median(r) if r else math.nan


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--from", dest="t0", type=float)
    ap.add_argument("--to", dest="t1", type=float)
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args()
    cols = ["run", "-u'v'+ pk", "u_rms+ pk", "v_rms+ pk", "U_b+", "R_uv",
            "res y+30", "pair y+30", "res d/2", "pair d/2", "closure", "source", "Mp-st/ETT"]
    rows = []
    for run in a.runs:
        try:
            nc = netCDF4.Dataset(os.path.join(run, "stats.nc"))
        except OSError as e:
            sys.exit(f"error: {run}/stats.nc: {e}")
        g = nc.groups["eulerian"]
        delta, nu, fold = float(nc.delta), float(nc.nu), int(nc.fold)
        win = np.asarray(g["windows"][:])
        mom = np.asarray(g["moments"][:])
        pln = np.asarray(g["planes"][:]) if "planes" in g.variables else None
        ut = math.sqrt(delta * win[:, 3].sum() / win[:, 2].sum())
        tend = win[:, 1].max()
        t0 = a.t0 if a.t0 is not None else 0.5 * (win[0, 0] + min(tend, float(nc.t_reached)
                                                                  if hasattr(nc, "t_reached") else tend))
        t1 = a.t1 if a.t1 is not None else math.inf
        sel = [i for i in range(len(win)) if win[i, 0] >= t0 - 1e-12 and win[i, 1] <= t1 + 1e-12
               and win[i, 2] > 0]
        if not sel:
            sys.exit(f"error: {run}: no complete window inside [{t0}, {t1}]")
        vals = window_values(mom[sel], pln[sel] if pln is not None else [None] * len(sel),
                             delta, fold, ut, nu)
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


if __name__ == "__main__":
    main()
