"""Scored A/B table of numerical settings: what each does to the redistribution of energy,
the pressure noise and the profiles (docs/validation/scheme_ab.md).

usage: chansph-stats ab_score RUN_DIR... [--from T0] [--to T1] [--dns FILE] [--csv FILE]
                                          [--markdown]

For each run directory (stats.nc with the Reynolds-stress budgets, log.txt), in wall units of
the force balance (u_tau^2 = delta f), over the windows inside [T0, T1] (default: all) for the
profiles and over the run's averaging range for the budgets:
  redist 20-40   (vv pressure + wall + ww pressure) / (-uu pressure), the terms summed over the
                 bins with 20 <= y+ <= 40: the share of the energy the pressure term takes out
                 of u that reaches v and w (MKM: about 0.95; the rest is dissipated by the
                 pressure noise);
  noise/visc 10-30, noise/visc 28
                 the k pressure noise (the configurational part of the pressure term) over the
                 k viscous term, summed over 10 <= y+ <= 30, and in the bin nearest y+ = 28;
  vv visc/MKM 10-30
                 the vv viscous term over MKM's dissipation + viscous diffusion of vv, summed
                 over the same bins (MKM interpolated to each bin's y+);
  pair 12, pair 30
                 the numerical pair (pressure) stress share of the total stress in the bins
                 nearest y+ = 12 and 30 (momentum budget, window by window);
  v_rms+, w_rms+, -u'v'+ peaks
                 of the profile over the windows taken, and its deviation from the DNS peak of
                 --dns (default: the same-box mesh DNS stats/dns/samebox/box_2x2x1.4.txt);
  u_rms+ y+ ... -u'v'+ y+ (a table of their own)
                 the peaks' positions: the vertex of the parabola through the largest bin and
                 its two neighbours, and the DNS's the same way;
  p mean, p' wall
                 from the run's particles.nc (its last state): the mean pressure and the standard
                 deviation of the particle pressure within 0.1 delta of the walls, over rho0
                 u_tau^2 (the turbulence's own pressure fluctuation is 2-3 there): the mean acts
                 as a background pressure, the rest is mostly particle-scale acoustic noise;
  Mp-st/ETT, s/ETT
                 particle-steps and wall seconds per eddy turnover delta/u_tau (from log.txt;
                 the wall seconds depend on what else the machine ran).
Standard errors: the budget terms carry the engine's batch-means standard errors per bin
(summed bins: root sum of squares; a ratio a/b: |a/b| sqrt((se_a/a)^2 + (se_b/b)^2)); the
window quantities the scatter of the window values over sqrt(number of windows). Windows
shorter than the flow's correlation time make both too small: the table says what one turnover
resolves, not the whole truth (a second start state checks it).
--csv writes one row per run with every value and its standard error.
"""
import csv
import math
import os
import sys

import numpy as np

from . import budget_compare as bc
from . import cli
from .ab_table import cost, table
from .cli import InputError
from .dns import read_dns
from .merge import merged_profile, peak_position, window_values
from .ncfile import read_windows
from .twopoint import DNS_ROOT

SAMEBOX = os.path.normpath(os.path.join(DNS_ROOT, "..", "samebox", "box_2x2x1.4.txt"))


def band_sum(t, yp, comp, terms, lo, hi):
    """Sum over the bins with lo <= y+ <= hi of the terms of component comp, and its standard
    error (root sum of squares)."""
    sel = (yp >= lo) & (yp <= hi)
    if not sel.any():
        raise InputError(f"no bin with {lo} <= y+ <= {hi}")
    v = sum(t[comp][n][0][sel].sum() for n in terms)
    se = math.sqrt(sum((t[comp][n][1][sel] ** 2).sum() for n in terms))
    return v, se


def ratio(a, b):
    """a / b with the standard error of independent a and b: ((value, se), (value, se))."""
    r = a[0] / b[0]
    return r, abs(r) * math.hypot(a[1] / a[0] if a[0] else 0.0, b[1] / b[0])


def budget_scores(path, mkm):
    """The budget scores of one stats.nc (force units) as {name: (value, se)}, or None."""
    b = bc.read_budgets(path, "force")
    if b is None:
        return None
    yp, t = b["yplus"], b["terms"]
    if "pressure_noise" not in t["k"]:
        raise InputError(f"{path}: no rsb_k_pressure_noise (a file of before 2026-12-03)")
    gain = band_sum(t, yp, "vv", ("pressure", "wall"), 20, 40)
    gain_w = band_sum(t, yp, "ww", ("pressure",), 20, 40)
    loss = band_sum(t, yp, "uu", ("pressure",), 20, 40)
    out = {"redist 20-40": ratio((gain[0] + gain_w[0], math.hypot(gain[1], gain_w[1])),
                                 (-loss[0], loss[1]))}
    out["noise/visc 10-30"] = ratio(band_sum(t, yp, "k", ("pressure_noise",), 10, 30),
                                    band_sum(t, yp, "k", ("viscous",), 10, 30))
    k = int(np.argmin(np.abs(yp - 28.0)))
    out["noise/visc 28"] = ratio(band_sum(t, yp, "k", ("pressure_noise",), yp[k], yp[k]),
                                 band_sum(t, yp, "k", ("viscous",), yp[k], yp[k]))
    sel = (yp >= 10) & (yp <= 30)
    ref = np.interp(yp[sel], mkm["vv"]["y+"], mkm["vv"]["dissip"] + mkm["vv"]["v-diff"]).sum()
    vis = band_sum(t, yp, "vv", ("viscous",), 10, 30)
    out["vv visc/MKM 10-30"] = (vis[0] / ref, vis[1] / abs(ref))
    return out


def mkm_redistribution(mkm):
    """MKM's (vv + ww pressure terms) / (-uu pressure term) over 20 <= y+ <= 40."""
    def s(c):
        d = mkm[c]
        sel = (d["y+"] >= 20) & (d["y+"] <= 40)
        return (d["p-strain"][sel] + d["p-diff"][sel]).sum()
    return (s("vv") + s("ww")) / -s("uu")


def pressure_scores(run, ut):
    """Mean pressure and the wall layer's pressure deviation of the last state in particles.nc,
    over rho0 u_tau^2 (rho0 and delta: attributes of the run's stats.nc); NaN without it."""
    from .ncfile import open_nc
    path = os.path.join(run, "particles.nc")
    if not os.path.exists(path):
        return {"p mean": (math.nan, math.nan), "p' wall": (math.nan, math.nan)}
    with open_nc(os.path.join(run, "stats.nc")) as d:
        rho0, delta = float(d.getncattr("rho0")), float(d.getncattr("delta"))
    with open_nc(path) as d:
        def last(k):
            v = d[k]
            return np.asarray(v[-1] if v.ndim == 2 else v[:], dtype=float)
        p, y = last("p"), last("y")
    scale = rho0 * ut ** 2
    near = np.minimum(y, 2 * delta - y) < 0.1 * delta
    return {"p mean": (p.mean() / scale, math.nan), "p' wall": (p[near].std() / scale, math.nan)}


def window_scores(run, t0, t1, dns):
    """The profile and momentum-budget scores over the windows inside [t0, t1]."""
    r = read_windows(os.path.join(run, "stats.nc"))
    win = r["win"]
    sel = [i for i in range(len(win)) if r["done"][i] and win[i, 0] >= t0 - 1e-12
           and win[i, 1] <= t1 + 1e-12]
    if len(sel) < 2:
        raise InputError(f"{run}: fewer than 2 complete windows inside [{t0}, {t1}]")
    out = {}
    prof = merged_profile(r, sel)
    each = [merged_profile(r, [i]) for i in sel]
    for q in ("u_rms+", "v_rms+", "w_rms+", "-u'v'+"):
        per = np.array([peak_position(p["yplus"], p[q]) for p in each])
        out[q + " y+"] = (peak_position(prof["yplus"], prof[q]),
                          float(np.std(per, ddof=1) / math.sqrt(len(per))))
    for q in ("v_rms+", "w_rms+", "-u'v'+"):
        pk = float(np.nanmax(prof[q]))
        per = np.array([np.nanmax(p[q]) for p in each])
        out[q + " pk"] = (pk, float(np.std(per, ddof=1) / math.sqrt(len(per))))
        ref = float(np.nanmax(dns[q]))
        out[q + " dev"] = (pk / ref - 1.0, out[q + " pk"][1] / ref)
    vals = window_values(r["mom"][sel], r["pln"][sel] if r["pln"] is not None else
                         [None] * len(sel), r["delta"], r["fold"], r["ut"], r["nu"])
    for name in ("pair_12", "pair_30"):
        x = np.array([v.get(name, math.nan) for v in vals], dtype=float)
        out[name.replace("_", " ")] = (float(np.nanmean(x)),
                                       float(np.nanstd(x, ddof=1) / math.sqrt(len(x))))
    out.update(pressure_scores(run, r["ut"]))
    steps, wall = cost(run, r["ut"], r["delta"])
    out["Mp-st/ETT"] = (steps / 1e6, math.nan)
    out["s/ETT"] = (wall, math.nan)
    return out, (win[sel[0], 0], win[sel[-1], 1], len(sel))


COLUMNS = ("redist 20-40", "noise/visc 10-30", "noise/visc 28", "vv visc/MKM 10-30", "pair 12",
           "pair 30", "v_rms+ pk", "v_rms+ dev", "w_rms+ pk", "w_rms+ dev", "-u'v'+ pk",
           "-u'v'+ dev", "p mean", "p' wall", "Mp-st/ETT", "s/ETT")
# the peak positions, in a table of their own (and in the CSV)
POSITIONS = ("u_rms+ y+", "v_rms+ y+", "w_rms+ y+", "-u'v'+ y+")


def fmt(name, v):
    value, se = v
    if not math.isfinite(value):
        return "-"
    if name.endswith("dev"):
        return f"{100 * value:+.0f}±{100 * se:.0f}%"
    if name.endswith("/ETT"):
        return f"{value:.0f}"
    if name in ("p mean", "p' wall"):
        return f"{value:.1f}"
    return f"{value:.3f}±{se:.3f}" if math.isfinite(se) else f"{value:.3f}"


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--from", dest="t0", type=cli.number(), default=-math.inf)
    ap.add_argument("--to", dest="t1", type=cli.number(), default=math.inf)
    ap.add_argument("--dns", default=SAMEBOX)
    ap.add_argument("--csv")
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args(argv)
    dns = read_dns(a.dns)
    mkm = bc.read_dns()
    rows, rows_pos, recs = [], [], []
    for run in a.runs:
        scores, (w0, w1, nw) = window_scores(run, a.t0, a.t1, dns)
        b = budget_scores(os.path.join(run, "stats.nc"), mkm)
        if b is None:
            raise InputError(f"{run}/stats.nc: no Reynolds-stress budgets (rsb_*): run with "
                             "output.stats_every and the budgets on")
        scores.update(b)
        name = os.path.basename(run.rstrip("/"))
        rows.append([name] + [fmt(c, scores[c]) for c in COLUMNS])
        rows_pos.append([name] + [f"{scores[c][0]:.1f}±{scores[c][1]:.1f}" for c in POSITIONS])
        recs.append((name, scores))
        print(f"# {run}: windows {w0:.3g}-{w1:.3g} ({nw})", file=sys.stderr)
    print(f"Scores in force units (u_tau^2 = delta f); dev: peak against {dns['source']}; "
          f"MKM's redistributed fraction over 20 <= y+ <= 40: {mkm_redistribution(mkm):.3f}")
    table(["run"] + list(COLUMNS), rows, a.markdown)
    print(f"\nPeak positions (the parabola through the largest bin and its neighbours; +- the "
          f"scatter of the windows' positions over sqrt(windows)); {dns['source']}: "
          + ", ".join(f"{c} {peak_position(dns['yplus'], dns[c.rsplit(' ', 1)[0]]):.1f}"
                      for c in POSITIONS))
    table(["run"] + list(POSITIONS), rows_pos, a.markdown)
    if a.csv:
        try:
            with open(a.csv, "w", newline="") as f:
                w = csv.writer(f)
                cols = COLUMNS + POSITIONS
                w.writerow(["run"] + [x for c in cols for x in (c, c + " se")])
                for name, s in recs:
                    w.writerow([name] + [f"{x:.6g}" for c in cols for x in s[c]])
        except OSError as e:
            raise InputError(f"{a.csv}: cannot write: {e.strerror}")
    return 0
