"""Plot u_mean of a chansph stats.nc against its reference profile.

For a laminar run the reference is the analytical Poiseuille profile of the run's body force.
Prints the verdict of the laminar check: PASS when the relative L2 error of u_mean against the
profile is at most --tol (default 0.01), else FAIL and exit status 1.
usage: chansph-stats plot_profile runs/laminar/stats.nc [-o profile.png] [--tol 0.01]
"""
import os

import numpy as np

from . import cli
from .ncfile import laminar_profile, need_keys, read_stats


def main(argv, prog):
    p = cli.parser(prog, __doc__, raw=True)
    p.add_argument("stats")
    p.add_argument("-o", "--output", default=None)
    p.add_argument("--tol", type=cli.number(float, 0), default=0.01,
                   help="largest relative L2 error of a PASS (default 0.01)")
    a = p.parse_args(argv)
    s = read_stats(a.stats)
    need_keys(s, a.stats, ("y_mean", "u_mean"), ("body_force", "delta", "nu", "dr", "dimension"))
    at = s["attrs"]
    y, u = s["y_mean"], s["u_mean"]
    ok = np.isfinite(u)
    if not ok.any():
        raise cli.InputError(f"{a.stats}: u_mean has no value (no averaging window yet?)")
    ref = laminar_profile(at, y)
    err = np.sqrt(np.sum((u[ok] - ref[ok]) ** 2) / np.sum(ref[ok] ** 2))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    yy = np.linspace(0, 2 * at["delta"], 201)
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(laminar_profile(at, yy), yy, "k-", label="analytical Poiseuille")
    ax.plot(u[ok], y[ok], "o", ms=4, label="chansph u_mean")
    ax.set_xlabel("u [m/s]")
    ax.set_ylabel("y [m]")
    ax.set_title("%dD channel, 2 delta/dr = %g, rel. L2 error %.2e" %
                 (at["dimension"], 2 * at["delta"] / at["dr"], err), fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = a.output or os.path.join(os.path.dirname(a.stats) or ".", "profile.png")
    fig.savefig(out, dpi=110)
    print("profile plot: %s (relative L2 error against the analytical profile %.3e)" % (out, err))
    ok = err <= a.tol
    print("laminar check: %s: u_mean %s the analytic Poiseuille profile (relative L2 error %.3e, "
          "limit %g)" % ("PASS" if ok else "FAIL", "matches" if ok else "does NOT match", err, a.tol))
    return 0 if ok else 1
