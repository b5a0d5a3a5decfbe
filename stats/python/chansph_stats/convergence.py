"""Error against run time: the running average of a run's main statistics and its standard error,
window by window, with the projection to a target error.

usage: chansph-stats convergence STATS.nc [--target E] [--log LOG] [--out DIR]

STATS.nc is a run's stats.nc, or the joined segments of one (`chansph extract A/stats.nc
B/stats.nc --nc J.nc`). For every number n of complete averaging windows from 2 on, the
running average over the first n and its batch-means standard error over them are formed for:
  - the peaks of u_rms+, v_rms+, w_rms+ and -u'v'+ (each at the bin of its peak in the whole
    range; wall units of the force balance; each window's own value at that bin is a batch),
    from the window records of group eulerian;
  - the energy <u'u'>, <v'v'>, <w'w'> of the spectra at each level of group correlations (the
    y+ = 15 and 40 of the quick-start), the sum over k_x of each window's 1-D spectrum
    divided by its planes, relative to its final value;
  - the main terms of the Reynolds-stress budgets at the bins nearest y+ = 15 and 30 (lower
    half): production, pressure and viscous terms of uu, pressure and viscous terms of vv and
    ww (rsb_*, wall units term nu / u_tau^4), each re-averaged over the first n windows from
    the window records of group eulerian exactly as `chansph extract --window` does
    (rs_merge.py, the Python side of euler_rs.c), with the batch-means standard error over
    those windows; the last point covers every window of the file, the open one included, so
    it is the file's own rsb_* and rsb_*_stderr (records of a format before 1.11: not drawn);
  - T_L of each level and component of group lagrangian: from the history T_L_release
    (each completed release's own T_L, checkpoint format 1.13), the running mean of the finite
    per-release values over the first n and its standard error (their standard deviation /
    sqrt(n)), at the time the n-th completed (coordinate release), counted in releases; the
    last point is the file's T_L_release_mean and T_L_stderr. Files without the whole history
    (older formats, or a resume from an older checkpoint) give one point, T_L_release_mean and
    T_L_stderr at the time the file reached. The projection counts releases of
    lagrangian.release_every.
The x axes are the simulated time at the end of the n-th window and, when the run's log is
found (LOG, default log.txt beside STATS.nc; not for a joined file), the wall time spent to
reach it (from the log's particle-steps/s). For each quantity the projection to a relative
standard error E (default 0.01) assumes the n^-1/2 law of batch means: n (se / E / value)^2
windows (releases for T_L), printed as simulated (and wall) time.
Writes DIR/convergence.csv (quantity, windows (releases for T_L), t_end, wall_s, value,
stderr, relative) and
DIR/convergence.png (relative standard error against simulated time, log-log, with the n^-1/2
projection and the target), and prints the table of the last window with the projections.
"""
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .merge import merged_moments, merged_profile
from .ncfile import open_nc, read_windows
from .rs_merge import COMPS, T, rs_range, rs_records

PEAKS = ("u_rms+", "v_rms+", "w_rms+", "-u'v'+")
# the budgets' main terms (component, term) and the heights of their bins
BUDGET_TERMS = (("uu", "production"), ("uu", "pressure"), ("uu", "viscous"), ("vv", "pressure"),
                ("vv", "viscous"), ("ww", "pressure"), ("ww", "viscous"))
BUDGET_Y_PLUS = (15.0, 30.0)


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


def filled_share(g, planes):
    """Per window and level the filled share of the grid's cells, P(0) of the gap correction
    (docs/stats-format.md), the window's empty cells, and whether its mask sums cover its
    planes (all False in files before checkpoint format 1.15)."""
    if "window_mask_kx" not in g.variables:
        return np.ones_like(planes), np.zeros_like(planes), np.zeros(planes.shape, bool)
    mx = np.ma.filled(g["window_mask_kx"][:].astype(float), 0.0)
    mp = np.ma.filled(g["window_mask_planes"][:].astype(float), 0.0)
    me = np.ma.filled(g["window_empty_cells"][:].astype(float), 0.0)
    nx, nz = g.dimensions["separation_x"].size, g.dimensions["separation_z"].size
    m = np.arange(mx.shape[2])
    f = np.where((m == 0) | (2 * m == nx), 1.0, 2.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        p0 = (mx * f).sum(axis=2) / ((nx * nz) ** 2 * mp)
    return p0, me, (mp == planes) & (mp > 0)


def spectra_series(path):
    """{quantity: [(n, t_end, value, se)]} of the spectra's energies at each correlation level,
    relative to their final value (empty without window records); gap-corrected as the engine
    is (over the first n windows: their zero-filled energies over their filled shares, both
    weighted by the planes)."""
    with open_nc(path) as d:
        if "correlations" not in d.groups:
            return {}
        g = d["correlations"]
        if "window_spectra_kx" not in g.variables:
            return {}
        spec = np.ma.filled(g["window_spectra_kx"][:].astype(float), 0.0)
        planes = np.ma.filled(g["window_samples"][:].astype(float), 0.0)
        share, empty, covered = filled_share(g, planes)
        nx = g.dimensions["separation_x"].size
        comp = np.asarray(g["window_complete"][:]) > 0
        t_end = np.asarray(g["windows"][:, 1], float)
        yplus = np.asarray(g["y_plus"][:], float)
    out = {}
    rows = [i for i in range(len(comp)) if comp[i]]
    m = np.arange(spec.shape[2])  # the k_x >= 0 entries, the others their partners: R(0)
    f = np.where((m == 0) | (2 * m == nx), 1.0, 2.0)
    for lev, yp in enumerate(yplus):
        use = [i for i in rows if planes[i, lev] > 0]
        if len(use) < 2:
            continue
        w = np.array([planes[i, lev] for i in use])
        # the engine's rule for the range: corrected if the mask sums cover every window's
        # planes and some cell was empty (else the zero-filled energies, P(0) = 1)
        fix = all(covered[i, lev] for i in use) and sum(empty[i, lev] for i in use) > 0
        p0 = np.array([share[i, lev] if fix else 1.0 for i in use])
        for s, name in enumerate(("uu", "vv", "ww")):
            e = np.array([(spec[i, lev, :, s] * f).sum() / planes[i, lev] for i in use])
            final = float(np.sum(e * w) / np.sum(p0 * w))
            if not final > 0:
                continue
            key = "E_%s(y+ %g)" % (name, yp)
            out[key] = [(n, t_end[use[n - 1]],
                         float(np.sum(e[:n] * w[:n]) / np.sum(p0[:n] * w[:n])) / final,
                         batch_se(e[:n] / p0[:n] / final)) for n in range(2, len(use) + 1)]
    return out


def budget_series(path):
    """{quantity: [(n, t_end, value, se)]} of the budgets' main terms (wall units) over the
    first n complete windows, the last point over every window of the file (empty without
    budget records of the current layout: then a note says why)."""
    r = read_windows(path)
    with open_nc(path) as d:
        rec = rs_records(d, path)
        if rec is None:
            if "reynolds_budget" in d["eulerian"].variables:
                print("# budgets: the records are of a format before 1.11 (as chansph extract, "
                      "not re-averaged): not drawn")
            return {}
        flags = np.asarray(d["eulerian"]["window_complete"][:]) > 0
    rsb, cfg = rec
    rows = [i for i in range(len(r["win"])) if r["done"][i]]
    complete = [i for i in rows if flags[i]]
    if len(complete) < 2:
        return {}
    whole = merged_moments(r, rows)
    yplus = whole["y"] * r["ut"] / r["nu"]
    lower = whole["ok"] & (whole["y"] < r["delta"])
    if not lower.any():
        return {}
    bins = {yp: int(np.nanargmin(np.where(lower, np.abs(yplus - yp), np.inf)))
            for yp in BUDGET_Y_PLUS}
    ends = [complete[n - 1] for n in range(2, len(complete) + 1)]
    if rows[-1] > ends[-1]:
        ends.append(rows[-1])  # every window: the file's own rsb_*
    scale = r["nu"] / r["ut"] ** 4
    t_reached = r["t_reached"] if r["t_reached"] is not None else math.inf
    out = {}
    use = sorted(set(bins.values()))  # y+ 15 and 30 may fall in one bin (a coarse or slow run)
    for last in ends:
        value, se = rs_range(r, rsb, cfg, [i for i in rows if i <= last], flags, use)
        n = sum(1 for i in complete if i <= last)
        for b in use:
            for c, t in BUDGET_TERMS:
                k = (COMPS.index(c), T[t])
                key = "%s_%s(y+ %.0f)" % (c, t, yplus[b])
                out.setdefault(key, []).append(
                    (n, min(r["win"][last, 1], t_reached), value[b][k] * scale, se[b][k] * scale))
    return {q: ser for q, ser in out.items() if all(math.isfinite(p[2]) for p in ser)}


def lagrangian_series(path):
    """({quantity: [(releases, t, value, se)]}, {quantity: (t0, release spacing)}, history) of
    T_L per level and component: from the history T_L_release (checkpoint format 1.13), the
    running mean of the finite per-release values over the first n and its standard error, at
    the time the n-th of them completed, for every n from 2; without a whole history (older
    files, or a resume from an older checkpoint: fewer rows than releases) one point, the
    file's T_L_release_mean and T_L_stderr at the time it reached (history False)."""
    with open_nc(path) as d:
        if "lagrangian" not in d.groups:
            return {}, {}, False
        g = d["lagrangian"]
        if "T_L_release_mean" not in g.variables or "T_L_stderr" not in g.variables:
            return {}, {}, False
        mean = np.ma.filled(g["T_L_release_mean"][:].astype(float), np.nan)
        se = np.ma.filled(g["T_L_stderr"][:].astype(float), np.nan)
        yplus = np.asarray(g["y_plus"][:], float)
        releases = int(g.releases)
        every = float(g.release_every) if float(g.release_every) > 0 else float(g.horizon)
        t = float(d.t_reached) if "t_reached" in d.ncattrs() else float(d.t_end)
        t0 = float(d.t_average_start)
        hist = hist_t = None
        if "T_L_release" in g.variables and "release" in g.variables:
            hist = np.ma.filled(g["T_L_release"][:].astype(float), np.nan)
            hist_t = np.asarray(g["release"][:], float)
    whole = hist is not None and hist.shape[0] == releases
    if hist is not None and not whole:
        print("# T_L: the history holds %d of the %d releases (the run resumed from a checkpoint "
              "without it): one point per quantity" % (hist.shape[0], releases))
    out, spacing = {}, {}
    for lev, yp in enumerate(yplus):
        for c, name in enumerate("uvw"):
            key = "T_L_%s(y+ %g)" % (name, yp)
            if whole:
                use = np.isfinite(hist[:, lev, c])
                v, tv = hist[use, lev, c], hist_t[use]
                ser = [(n, float(tv[n - 1]), float(np.mean(v[:n])), batch_se(v[:n]))
                       for n in range(2, len(v) + 1)]
                if ser:
                    out[key], spacing[key] = ser, (t0, every)
            elif releases >= 2 and math.isfinite(mean[lev, c]) and math.isfinite(se[lev, c]):
                out[key] = [(releases, t, float(mean[lev, c]), float(se[lev, c]))]
                spacing[key] = (t0, every)
    return out, spacing, whole


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
    series.update(budget_series(a.stats))
    lagr, spacing, lagr_history = lagrangian_series(a.stats)
    series.update(lagr)
    log = a.log or os.path.join(os.path.dirname(os.path.abspath(a.stats)), "log.txt")
    out_dir = a.out or os.path.join(os.path.dirname(os.path.abspath(a.stats)), "convergence")
    os.makedirs(out_dir, exist_ok=True)
    length = float(np.median([w[1] - w[0] for w in wins]))
    for q in series:
        spacing.setdefault(q, (wins[0][0], length))
    rows = []
    width = max(16, max(len(q) for q in series))
    print("%-*s %8s %10s %12s %12s %9s %14s %14s" % (width, "quantity", "windows", "t_end",
                                                     "value", "stderr", "relative",
                                                     "windows needed", "t at target"))
    for q, ser in series.items():
        ts = np.array([s[1] for s in ser])
        wall = wall_clock(log, ts)
        for k, (n, t, v, se) in enumerate(ser):
            rows.append((q, n, t, wall[k] if wall is not None else math.nan, v, se,
                         abs(se / v) if v else math.nan))
        n, t, v, se = ser[-1]
        rel = abs(se / v) if v else math.nan
        need = n * (rel / a.target) ** 2 if math.isfinite(rel) else math.nan
        t_at = spacing[q][0] + need * spacing[q][1] if math.isfinite(need) else math.nan
        print("%-*s %8d %10.4g %12.5g %12.4g %9.4f %14.1f %14.4g" % (width, q, n, t, v, se, rel,
                                                                     need, t_at))
    if lagr and lagr_history:
        print("# T_L: windows = releases with a finite T_L, the running mean of the history "
              "T_L_release at the time each completed; its projection counts releases")
    elif lagr:
        print("# T_L: windows = completed releases, one point (no whole per-release history in "
              "stats.nc); its projection counts releases")
    with open(os.path.join(out_dir, "convergence.csv"), "w") as f:
        f.write("# %s: running averages and batch-means standard errors; target %g\n"
                "quantity,windows,t_end,wall_s,value,stderr,relative\n" % (a.stats, a.target))
        for r in rows:
            f.write("%s,%d,%.10g,%.10g,%.12g,%.10g,%.10g\n" % r)
    if not a.no_plot:
        plot(series, a.target, spacing, os.path.join(out_dir, "convergence.png"), a.stats)
    print("wrote %s/convergence.csv%s" % (out_dir, "" if a.no_plot else " and convergence.png"))
    return 0


def group_of(q):
    """The panel of a quantity in the figure."""
    if q in PEAKS:
        return "profile peaks"
    if q.startswith("E_"):
        return "spectra (energy at each level)"
    if q.startswith("T_L"):
        return "T_L (running mean over the releases)"
    return "Reynolds-stress budgets (main terms)"


def plot(series, target, spacing, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = []
    for q in series:
        if group_of(q) not in groups:
            groups.append(group_of(q))
    cols = 1 if len(groups) == 1 else 2
    rows = (len(groups) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(7 * cols, 4.5 * rows), squeeze=False)
    for g, ax in zip(groups, axes.flat):
        for q, ser in series.items():
            if group_of(q) != g:
                continue
            t = np.array([s[1] for s in ser])
            rel = np.array([abs(s[3] / s[2]) if s[2] else np.nan for s in ser])
            line, = ax.loglog(t, rel, "o-", ms=3, label=q)
            if np.isfinite(rel[-1]) and rel[-1] > 0:  # the n^-1/2 projection from the last point
                n, length = ser[-1][0], spacing[q][1]
                need = n * (rel[-1] / target) ** 2
                tt = np.linspace(t[-1], t[-1] + max(need - n, 0) * length, 20)
                ax.loglog(tt, rel[-1] * np.sqrt(n / (n + (tt - t[-1]) / length)), "--",
                          color=line.get_color(), lw=0.8)
        ax.axhline(target, color="k", lw=0.8, ls=":", label="target %g" % target)
        ax.set_xlabel("simulated time at the end of the window [s]")
        ax.set_ylabel("relative standard error")
        ax.set_title("%s: %s (dashed: n^-1/2 projection)" % (os.path.basename(title), g),
                     fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    for ax in list(axes.flat)[len(groups):]:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
