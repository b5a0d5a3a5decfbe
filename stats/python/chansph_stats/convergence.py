"""Error against run time: the running average of a run's main statistics and its standard error,
window by window, with the projection to a target error (issue 43, point 4).

usage: chansph-stats convergence STATS.nc [--target E] [--log LOG] [--out DIR]

STATS.nc is a run's stats.nc, or the joined segments of one (`chansph extract A/stats.nc
B/stats.nc --nc J.nc`). For every number n of complete averaging windows from 2 on, the
running average over the first n and its batch-means standard error over them are formed for:
  - the peaks of u_rms+, v_rms+, w_rms+ and -u'v'+ (each at the bin of its peak in the whole
    range; wall units of the force balance; each window's own value at that bin is a batch),
    from the window records of group eulerian;
  - the energy <u'u'>, <v'v'>, <w'w'> of the spectra at each level of group correlations (the
    y+ = 15 and 40 of the quick-start), the sum over k_x of each window's 1-D spectrum
    divided by its planes, relative to its final value.
The x axes are the simulated time at the end of the n-th window and, when the run's log is
found (LOG, default log.txt beside STATS.nc; not for a joined file), the wall time spent to
reach it (from the log's particle-steps/s). For each quantity the projection to a relative
standard error E (default 0.01) assumes the n^-1/2 law of batch means: n (se / E / value)^2
windows, printed as simulated (and wall) time.
Not drawn: T_L and the Lagrangian functions (stats.nc keeps their per-release batches as
running sums, not per release, so there is no history to redraw; their standard errors are in
the file) and the Reynolds-stress budgets (their per-window terms need the budget records'
local-mean reconstruction of the engine, euler_rs.c).
Writes DIR/convergence.csv (quantity, windows, t_end, wall_s, value, stderr, relative) and
DIR/convergence.png (relative standard error against simulated time, log-log, with the n^-1/2
projection and the target), and prints the table of the last window with the projections.
"""
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .merge import merged_profile
from .ncfile import open_nc, read_windows

PEAKS = ("u_rms+", "v_rms+", "w_rms+", "-u'v'+")


def batch_se(values):
    """Standard error of the mean of batch values (NaN below 2)."""
    v = np.asarray([x for x in values if np.isfinite(x)], float)
    return float(np.std(v, ddof=1) / math.sqrt(len(v))) if len(v) >= 2 else math.nan


def peak_series(path):
    """{quantity: [(n, t_end, value, se)]} of the profiles' peaks over the first n windows."""
    r = read_windows(path)
    with open_nc(path) as d:
        flags = np.asarray(d["eulerian"]["window_complete"][:])
    complete = [i for i in range(len(r["win"])) if r["done"][i] and flags[i]]
    if len(complete) < 2:
        raise InputError(f"{path}: fewer than 2 complete windows")
    whole = merged_profile(r, complete)
    bins = {q: int(np.nanargmax(whole[q])) for q in PEAKS}
    per = [merged_profile(r, [i]) for i in complete]
    out = {q: [] for q in PEAKS}
    for n in range(2, len(complete) + 1):
        run = merged_profile(r, complete[:n])
        for q in PEAKS:
            b = bins[q]
            out[q].append((n, r["win"][complete[n - 1], 1], run[q][b],
                           batch_se([p[q][b] for p in per[:n]])))
    return out, [r["win"][i] for i in complete]


def spectra_series(path):
    """{quantity: [(n, t_end, value, se)]} of the spectra's energies at each correlation level,
    relative to their final value (empty without window records)."""
    with open_nc(path) as d:
        if "correlations" not in d.groups:
            return {}
        g = d["correlations"]
        if "window_spectra_kx" not in g.variables:
            return {}
        spec = np.ma.filled(g["window_spectra_kx"][:].astype(float), 0.0)
        planes = np.ma.filled(g["window_samples"][:].astype(float), 0.0)
        comp = np.asarray(g["window_complete"][:]) > 0
        t_end = np.asarray(g["windows"][:, 1], float)
        yplus = np.asarray(g["y_plus"][:], float)
    out = {}
    rows = [i for i in range(len(comp)) if comp[i]]
    for lev, yp in enumerate(yplus):
        for s, name in enumerate(("uu", "vv", "ww")):
            use = [i for i in rows if planes[i, lev] > 0]
            if len(use) < 2:
                continue
            e = np.array([spec[i, lev, :, s].sum() / planes[i, lev] for i in use])
            w = np.array([planes[i, lev] for i in use])
            final = float(np.sum(e * w) / np.sum(w))
            if not final > 0:
                continue
            key = "E_%s(y+ %g)" % (name, yp)
            out[key] = [(n, t_end[use[n - 1]], float(np.sum(e[:n] * w[:n]) / np.sum(w[:n])) / final,
                         batch_se(e[:n] / final)) for n in range(2, len(use) + 1)]
    return out


def wall_clock(log, times):
    """Wall seconds at the simulated times (None without a usable log)."""
    if not log or not os.path.exists(log):
        return None
    from .error_vs_time import log_cost
    try:
        t, _, wall = log_cost(os.path.dirname(os.path.abspath(log)) or ".")
    except InputError:
        return None
    return np.interp(times, t, wall)


def main(argv, prog):
    p = cli.parser(prog, __doc__)
    p.add_argument("stats")
    p.add_argument("--target", type=cli.number(float, 0.0, above=True), default=0.01,
                   help="relative standard error to project to (default 0.01)")
    p.add_argument("--log", default=None, help="the run's log.txt (default: beside STATS.nc)")
    p.add_argument("--out", default=None, help="output directory (default: beside STATS.nc)")
    p.add_argument("--no-plot", action="store_true")
    a = p.parse_args(argv)
    series, wins = peak_series(a.stats)
    series.update(spectra_series(a.stats))
    log = a.log or os.path.join(os.path.dirname(os.path.abspath(a.stats)), "log.txt")
    out_dir = a.out or os.path.join(os.path.dirname(os.path.abspath(a.stats)), "convergence")
    os.makedirs(out_dir, exist_ok=True)
    length = float(np.median([w[1] - w[0] for w in wins]))
    rows = []
    print("%-16s %8s %10s %12s %12s %9s %14s %14s" % ("quantity", "windows", "t_end", "value",
                                                      "stderr", "relative", "windows needed",
                                                      "t at target"))
    for q, ser in series.items():
        ts = np.array([s[1] for s in ser])
        wall = wall_clock(log, ts)
        for k, (n, t, v, se) in enumerate(ser):
            rows.append((q, n, t, wall[k] if wall is not None else math.nan, v, se,
                         abs(se / v) if v else math.nan))
        n, t, v, se = ser[-1]
        rel = abs(se / v) if v else math.nan
        need = n * (rel / a.target) ** 2 if math.isfinite(rel) else math.nan
        t_at = wins[0][0] + need * length if math.isfinite(need) else math.nan
        print("%-16s %8d %10.4g %12.5g %12.4g %9.4f %14.1f %14.4g" % (q, n, t, v, se, rel, need,
                                                                      t_at))
    with open(os.path.join(out_dir, "convergence.csv"), "w") as f:
        f.write("# %s: running averages and batch-means standard errors; target %g\n"
                "quantity,windows,t_end,wall_s,value,stderr,relative\n" % (a.stats, a.target))
        for r in rows:
            f.write("%s,%d,%.10g,%.10g,%.12g,%.10g,%.10g\n" % r)
    if not a.no_plot:
        plot(series, a.target, length, os.path.join(out_dir, "convergence.png"), a.stats)
    print("wrote %s/convergence.csv%s" % (out_dir, "" if a.no_plot else " and convergence.png"))
    return 0


def plot(series, target, length, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for q, ser in series.items():
        t = np.array([s[1] for s in ser])
        rel = np.array([abs(s[3] / s[2]) if s[2] else np.nan for s in ser])
        line, = ax.loglog(t, rel, "o-", ms=3, label=q)
        if np.isfinite(rel[-1]) and rel[-1] > 0:  # the n^-1/2 projection from the last point
            n = ser[-1][0]
            need = n * (rel[-1] / target) ** 2
            tt = np.linspace(t[-1], t[-1] + max(need - n, 0) * length, 20)
            ax.loglog(tt, rel[-1] * np.sqrt(n / (n + (tt - t[-1]) / length)), "--",
                      color=line.get_color(), lw=0.8)
    ax.axhline(target, color="k", lw=0.8, ls=":", label="target %g" % target)
    ax.set_xlabel("simulated time at the end of the window [s]")
    ax.set_ylabel("relative standard error")
    ax.set_title("%s: running averages (dashed: n^-1/2 projection)" % title, fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
