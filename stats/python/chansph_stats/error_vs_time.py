"""Error against run time: how far a turbulent channel run is from the DNS, window by window.

usage: chansph-stats error_vs_time --dns FILE [--dns FILE2] [--group T] [--out DIR]
                                      LABEL=RUN_DIR[+RUN_DIR...] ...

Each series is one or more run directories (stats.nc, log.txt; without log.txt the particle-steps
come from stats.nc's steps and n_fluid, spread evenly over its time, and the wall seconds are
unknown: a shipped segment), the later ones continuing the
earlier (a run started from an earlier one's particles with its time restarting at 0 is shifted
to follow it). The averaging windows of stats.nc are grouped into consecutive groups of length T
in delta/u_tau (default 0.25); for each group the profiles of U+, u_rms+, v_rms+, w_rms+ and
-u'v'+ are formed from the raw window sums (upper half mirrored when not folded; wall units from
the force balance u_tau^2 = delta f) and compared with each DNS file over the bins inside its y+
range: relative L2 error = rms(ours - DNS) / rms(DNS). The x axes are the particle-steps spent
since the start of the series (from the log's step lines and the fluid-particle count) and the
wall seconds (from the log's particle-steps/s of each interval: what the machine delivered,
shared or not).

With --cumulative T0 each group instead gives the running average from T0 to its end (the
error a user gets for the run time spent: the convergence of the averages, and the bias that
remains).

Writes DIR/error_vs_time.csv (one row per series, group and DNS set) and
DIR/error_vs_time.png (one panel per quantity, error against particle-steps), and prints the
last group of each series. DNS files: those `chansph compare` reads (dns.py).
"""
import math
import os
import re

import numpy as np

from . import cli
from .cli import InputError
from .dns import QUANTITIES, read_dns, rel_l2
from .merge import merged_profile
from .ncfile import open_nc, read_windows


def stats_cost(run):
    """(t, particle-steps, wall seconds) from stats.nc alone (a shipped segment without its
    log): the file's steps times n_fluid, spread evenly over 0 .. t_reached (the time step
    varies by a few percent); wall seconds unknown (NaN)."""
    with open_nc(os.path.join(run, "stats.nc")) as d:
        attrs = d.ncattrs()
        if not all(k in attrs for k in ("steps", "n_fluid", "t_reached")):
            raise InputError(f"{run}: no log.txt, and stats.nc has no steps, n_fluid, t_reached")
        steps, n = float(d.getncattr("steps")), float(d.getncattr("n_fluid"))
        t1 = float(d.getncattr("t_reached"))
    print(f"note: {run}: no log.txt; particle-steps from stats.nc ({steps:.0f} steps x "
          f"{n:.0f} particles over t = 0 .. {t1:.4g}), wall seconds unknown")
    return np.array([0.0, t1]), np.array([0.0, steps * n]), np.array([math.nan, math.nan])


def log_cost(run):
    """Arrays (t, cumulative particle-steps, cumulative wall seconds) at the log's step lines;
    from stats.nc alone where the run directory has no log.txt (stats_cost)."""
    path = os.path.join(run, "log.txt")
    if not os.path.exists(path) and os.path.exists(os.path.join(run, "stats.nc")):
        return stats_cost(run)
    try:
        log = open(path, encoding="utf-8").read()
    except OSError as e:
        raise InputError(f"{run}/log.txt: {e.strerror}")
    nfl = re.search(r"(\d+) fluid", log)
    rows = re.findall(r"^step\s+(\d+)\s+t\s+(\S+)\s+dt.*?(\S+) p-steps/s", log, re.M)
    if not nfl or len(rows) < 2:
        raise InputError(f"{run}/log.txt: no step lines with particle-steps/s")
    n = int(nfl.group(1))
    step = np.array([int(r[0]) for r in rows], float)
    t = np.array([float(r[1]) for r in rows])
    rate = np.array([float(r[2]) for r in rows])
    keep = np.concatenate(([True], np.diff(step) > 0))  # a resumed run repeats a step line
    step, t, rate = step[keep], t[keep], rate[keep]
    psteps = (step - step[0]) * n
    dwall = np.where(rate[1:] > 0, np.diff(psteps) / np.maximum(rate[1:], 1e-300), 0.0)
    return t, psteps, np.concatenate(([0.0], np.cumsum(dwall)))


def group_profiles(run, group, since=None):
    """[(t0, t1, profiles dict)] of the window groups of a run; with since, each group's
    profiles are the running average of the windows from since to the group's end."""
    r = read_windows(os.path.join(run, "stats.nc"))
    win, done = r["win"], r["done"]
    out = []
    t_start = win[0, 0]
    k = 0
    while k < len(win):
        t_lo = t_start + math.floor((win[k, 0] - t_start) / group + 1e-9) * group
        sel = [i for i in range(k, len(win)) if win[i, 0] < t_lo + group - 1e-9]
        k = sel[-1] + 1
        sel = [i for i in sel if done[i]]
        if since is not None:
            sel = [i for i in range(k) if done[i] and win[i, 0] >= since - 1e-9]
        if not sel:
            continue
        out.append((win[sel[0], 0], win[sel[-1], 1], merged_profile(r, sel)))
    return out


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("series", nargs="+", help="LABEL=RUN_DIR[+RUN_DIR...]")
    ap.add_argument("--dns", action="append", required=True)
    ap.add_argument("--group", type=cli.number(float, 0, above=True), default=0.25,
                    help="window group length [delta/u_tau]")
    ap.add_argument("--out", default=".")
    ap.add_argument("--cumulative", type=cli.number(float, 0), default=None, metavar="T0",
                    help="the error of the running average from T0 [delta/u_tau] to the end "
                         "of each group (within each run directory), instead of each group's own")
    a = ap.parse_args(argv)
    dns = [read_dns(p) for p in a.dns]
    rows = []
    for spec in a.series:
        label, _, dirs = spec.partition("=")
        if not dirs:
            raise InputError(f"{spec}: expected LABEL=RUN_DIR[+RUN_DIR...]")
        t_off = ps_off = wall_off = 0.0
        for run in dirs.split("+"):
            t, ps, wall = log_cost(run)
            groups = group_profiles(run, a.group, a.cumulative)
            if not groups:
                w = read_windows(os.path.join(run, "stats.nc"))["win"]
                raise InputError(
                    "%s: no complete window%s (its windows span t = %.6g .. %.6g): "
                    "give a --cumulative T0 inside that span" % (
                        os.path.join(run, "stats.nc"),
                        "" if a.cumulative is None else " starts at or after --cumulative %g"
                        % a.cumulative, w[0, 0] if len(w) else math.nan,
                        w[-1, 1] if len(w) else math.nan))
            for t0, t1, prof in groups:
                p1, w1 = np.interp(t1, t, ps), np.interp(t1, t, wall)
                errs = [[rel_l2(prof, d, q) for q in QUANTITIES] for d in dns]
                rows.append((label, t_off + t0, t_off + t1, ps_off + p1, wall_off + w1, errs))
            t_off += groups[-1][1] if groups else t[-1]
            ps_off += ps[-1]
            wall_off += wall[-1]
    os.makedirs(a.out, exist_ok=True)
    csv = os.path.join(a.out, "error_vs_time.csv")
    with open(csv, "w") as f:
        f.write("series,dns,t0,t1,particle_steps,wall_seconds," +
                ",".join("rel_L2_" + q.replace("'", "").replace("+", "p").replace("-", "m")
                         for q in QUANTITIES) + "\n")
        for lab, t0, t1, ps, wall, errs in rows:
            for d, e in zip(dns, errs):
                f.write(f"{lab},{d['name']},{t0:.4f},{t1:.4f},{ps:.6e},{wall:.1f}," +
                        ",".join(f"{x:.4f}" for x in e) + "\n")
    print(f"# relative L2 errors of the last window group of each series against {dns[0]['name']}")
    print(f"# {'series':<14} {'t':>11} {'Gp-steps':>9} {'wall s':>8} " +
          " ".join(f"{q:>7}" for q in QUANTITIES))
    last = {}
    for r in rows:
        last[r[0]] = r
    for lab, t0, t1, ps, wall, errs in last.values():
        print(f"  {lab:<14} {t0:5.2f}-{t1:5.2f} {ps / 1e9:9.3f} {wall:8.0f} " +
              " ".join(f"{x:7.3f}" for x in errs[0]))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"wrote {csv} (no matplotlib: no plot)")
        return
    nq = len(QUANTITIES)
    fig, axes = plt.subplots(2, nq, figsize=(4 * nq, 6.8))
    for k, q in enumerate(QUANTITIES):
        for row, (col, xlabel) in enumerate(((3, "particle-steps since the start"),
                                              (2, "t u_tau / delta (end of the window group)"))):
            ax = axes[row][k]
            for lab in dict.fromkeys(r[0] for r in rows):
                rr = [r for r in rows if r[0] == lab]
                for j, d in enumerate(dns):
                    ax.plot([r[col] for r in rr], [r[5][j][k] for r in rr],
                            "o-" if j == 0 else "x--", ms=3,
                            label=f"{lab} vs {d['name'][:14]}" if k == 0 and row == 0 else None)
            if row == 0:
                ax.set_xscale("log")
            ax.set_xlabel(xlabel)
            ax.set_title(f"{q}: relative L2 error")
            ax.set_ylim(bottom=0)
            ax.grid(alpha=0.3)
    fig.legend(loc="lower center", ncol=4, fontsize=7)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    png = os.path.join(a.out, "error_vs_time.png")
    fig.savefig(png, dpi=110)
    print(f"wrote {csv} and {png}")
