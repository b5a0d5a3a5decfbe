"""chansph-stats figures: the figures of a run for a talk, redrawn from its stats.nc.

Writes to --out (default: the folder "figures" beside STATS.nc):
  profiles.png       one figure, five panels (U+, u_rms+, v_rms+, w_rms+, -u'v'+ against y+):
                     the run with a band of 2 standard errors (batch means over its windows),
                     the DNS, and for U+ the law of the wall; the title names the run, Re_tau,
                     the u_tau of the wall units (--u-tau) and the averaging span
  rs_budget_<c>.png  where stats.nc has the Reynolds-stress budgets (rsb_*): one figure per
                     component (uu, vv, ww, uv, k) against the MKM Re_tau = 180 balances, the
                     figures of `chansph-stats rs_budget --out`
Prints the names of the files it wrote.
"""
import math
import os

import numpy as np

from . import budget_compare, cli
from .cli import InputError
from .compare import B_LOG, KAPPA, read_run
from .dns import QUANTITIES, read_dns

XLOG = {"U+": True}


def title(ours):
    a = ours["u_tau_label"]
    return "%s: Re_tau = %.0f\nwall units of %s" % (ours["run"], ours["re_tau"], a)


def panel(ax, q, ours, dns):
    """One quantity: the DNS (line), ours (points, 2-stderr band), the law of the wall for U+."""
    yp, v = ours["yplus"], ours[q]
    ax.plot(dns["yplus"][1:], dns[q][1:], "k-", lw=1.2, label="DNS " + dns["name"])
    se = ours.get(q + "_se")
    if se is not None and np.isfinite(se).any() and ours["n_windows"] >= 2:
        s = np.where(np.isfinite(se), 2 * se, 0.0)
        ax.fill_between(yp, v - s, v + s, color="C0", alpha=0.3, lw=0, label="2 stderr")
    ax.plot(yp, v, "o-", color="C0", ms=2.5, lw=0.8, label="chansph")
    if q == "U+":
        y = np.logspace(-1, math.log10(max(dns["yplus"][-1], yp[-1])), 200)
        ax.plot(y[y < 12], y[y < 12], "g--", lw=0.8, label="U+ = y+")
        ax.plot(y[y > 5], np.log(y[y > 5]) / KAPPA + B_LOG, "r--", lw=0.8, label="log law")
    ax.set_xscale("log")
    ax.set_xlim(0.8, max(dns["yplus"][-1], float(np.nanmax(yp))) * 1.1)
    ax.set_xlabel("y+")
    ax.set_ylabel(q)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def profiles(ours, dns, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5))
    for ax, q in zip(axes.flat, QUANTITIES):
        panel(ax, q, ours, dns)
    axes.flat[-1].axis("off")
    text = title(ours)
    fig.suptitle(text, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    fig.savefig(path, dpi=110, metadata={"Title": text.replace("\n", " ")})
    plt.close(fig)
    return path


def main(argv, prog="chansph-stats figures"):
    p = cli.parser(prog, __doc__, raw=True)
    p.add_argument("stats", help="stats.nc of a run")
    p.add_argument("--dns", default=os.path.join(os.path.dirname(os.path.dirname(
        os.path.dirname(os.path.abspath(__file__)))), "dns", "mkm1999", "chan180.means"),
        help="one file of a DNS set (default: stats/dns/mkm1999/chan180.means)")
    p.add_argument("--u-tau", default="wall", metavar="wall|force|VALUE",
                   help="u_tau of the wall units: wall (default), force or a value [m/s]")
    p.add_argument("--out", help="output folder (default: figures/ beside STATS)")
    a = p.parse_args(argv)
    cli.regular_file(a.stats, "statistics file")
    out = a.out or os.path.join(os.path.dirname(os.path.abspath(a.stats)), "figures")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise InputError("%s: cannot create the output directory (%s)" % (out, e.strerror))
    written = [profiles(read_run(a.stats, a.u_tau), read_dns(a.dns),
                        os.path.join(out, "profiles.png"))]
    budgets = budget_compare.read_budgets(a.stats, a.u_tau)
    if budgets is not None:
        written += budget_compare.plots(budgets, budget_compare.read_dns(), out)
    for w in written:
        print("wrote %s" % w)
    return 0
