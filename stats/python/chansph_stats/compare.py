"""chansph compare: profiles of a run (stats.nc) against a DNS data set, in wall units.

usage: chansph compare STATS.nc --dns FILE [--out DIR] [--no-plots]
       (or: stats/python/chansph-stats compare STATS.nc --dns FILE ...)

FILE is one file of a DNS set we ship in stats/dns/ (or one in the same formats):
  Moser, Kim & Mansour 1999: chanNNN.means (+ companion chanNNN.reystress, found by name)
  Lee & Moser 2015:          LM_Channel_NNNN_mean_prof.dat (+ derived/LM_Channel_RetauNNN.txt)
                             or the derived table itself.
STATS.nc may itself be a DNS file: comparing a DNS set with itself gives zero error.

Wall units come from the run's own u_tau (stats.nc attribute u_tau). The DNS profiles are
interpolated (linearly in y+) to the run's bin positions; the upper half of an unfolded run
is mirrored onto the lower one. Prints the L2 (root mean square) and Linf (maximum)
differences of U+, u_rms+, v_rms+, w_rms+ and -u'v'+ per y+ range, with the RMS over the range
of our own standard error (batch means over the averaging windows; "stderr"): a difference much
larger than it is a model or resolution error, one of its size is sampling noise. Writes
compare.csv and one PNG per quantity (ours with error bars of 2 standard errors, DNS, law of
the wall).
"""
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .dns import QUANTITIES, read_dns
from .ncfile import attribute, need, open_nc

RANGES = (("viscous sublayer", "y+ < 5"), ("buffer layer", "5 <= y+ < 30"),
          ("log layer", "y+ >= 30, y/delta < 0.3"), ("outer layer", "y+ >= 30, y/delta >= 0.3"))
KAPPA, B_LOG = 0.41, 5.2


def read_run(path):
    """Our profiles in wall units (lower half, upper half mirrored), with standard errors."""
    with open_nc(path) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}

        def v(name):
            return np.ma.filled(need(d, name, path, "a chansph stats.nc with profiles")[:]
                                .astype(float), np.nan)
        y, u, uu, vv, ww, uv = (v(n) for n in ("y_mean", "u_mean", "uu", "vv", "ww", "uv"))
        se = {n: v(n + "_stderr") for n in ("u_mean", "uu", "vv", "ww", "uv")}
        budget = {n: v(n) for n in BUDGET + ("total_stress", "total_stress_expected",
                                             "momentum_change")
                  if n in d.variables} if "pair_stress" in d.variables else {}
        ut, nu, delta = (float(attribute(d, k, path)) for k in ("u_tau", "nu", "delta"))
    if not ut > 0:
        raise InputError("%s: no positive u_tau (attribute u_tau = %r): no averaging window "
                         "completed yet?" % (path, ut))
    upper = y > delta
    y = np.where(upper, 2 * delta - y, y)
    sign = np.where(upper, -1.0, 1.0)
    out = {"yplus": y * ut / nu, "y_delta": y / delta, "re_tau": ut * delta / nu, "label": "chansph",
           "source": "chansph %s (u_tau = %.6g m/s, windows %d)" % (path, ut, a.get("n_windows", 0))}
    out["U+"], out["U+_se"] = u / ut, se["u_mean"] / ut
    for c, s2, name in (("u", uu, "uu"), ("v", vv, "vv"), ("w", ww, "ww")):
        r = np.sqrt(np.abs(s2)) / ut
        out[c + "_rms+"] = r
        out[c + "_rms+_se"] = np.where(r > 0, 0.5 * se[name] / ut ** 2 / np.where(r > 0, r, 1), np.nan)
    for n, x in budget.items():  # the momentum budget, mirrored like -u'v' (wall units)
        out["budget:" + n] = sign * x / ut ** 2
    out["-u'v'+"] = -sign * uv / ut ** 2
    out["-u'v'+_se"] = se["uv"] / ut ** 2
    order = np.argsort(out["yplus"], kind="stable")
    return {k: (val[order] if isinstance(val, np.ndarray) else val) for k, val in out.items()}


BUDGET = ("reynolds_stress", "viscous_pair_stress", "model_pair_stress", "pair_stress",
          "wall_term_stress", "advective_stress")


def print_budget(ours):
    """The split of the total stress at a few heights (docs/stats-format.md, momentum budget)."""
    names = [n for n in BUDGET if "budget:" + n in ours]
    if not names:
        return
    yp = ours["yplus"]
    tot, exp = ours["budget:total_stress"], ours["budget:total_stress_expected"]
    # the unsteady term: total + d/dt = expected in any window (absent in earlier files: 0)
    ddt = np.nan_to_num(ours.get("budget:momentum_change", np.zeros_like(tot)))
    closure = tot + ddt - exp
    print("momentum budget (shares of total_stress; total, d/dt (momentum_change), expected and "
          "closure = total + d/dt - expected in u_tau^2):")
    print("%8s %8s " % ("y+", "y/delta") + " ".join("%10s" % n.replace("_stress", "")[:10]
                                                  for n in names) +
          " %9s %9s %9s %9s" % ("total", "d/dt", "expected", "closure"))
    rows = sorted({int(np.argmin(np.abs(yp - t))) for t in (5.0, 15.0, 30.0, 100.0,
                                                             0.5 * ours["re_tau"])})
    for i in rows:
        print("%8.1f %8.3f " % (yp[i], ours["y_delta"][i]) +
              " ".join("%9.0f%%" % (100 * ours["budget:" + n][i] / tot[i]) for n in names) +
              " %9.4f %9.4f %9.4f %9.4f" % (tot[i], ddt[i], exp[i], closure[i]))
    worst = int(np.nanargmax(np.abs(closure)))
    print("budget closure: max |total + d/dt - expected| = %.4f u_tau^2 at y+ %.1f (over %d bins)"
          % (abs(closure[worst]), yp[worst], np.sum(np.isfinite(closure))))


def region_masks(yp, yd):
    return (yp < 5, (yp >= 5) & (yp < 30), (yp >= 30) & (yd < 0.3), (yp >= 30) & (yd >= 0.3))


def main(argv, prog="chansph compare"):
    p = cli.parser(prog, __doc__, raw=True)
    p.add_argument("stats", help="stats.nc of a run (or a DNS file)")
    p.add_argument("--dns", required=True, help="one file of a DNS set")
    p.add_argument("--out", help="directory for compare.csv and the PNGs (default: beside STATS)")
    p.add_argument("--no-plots", action="store_true")
    p.add_argument("--max-error", type=cli.number(float, 0),
                   help="exit with status 1 if any L2 or Linf error exceeds this (tests)")
    args = p.parse_args(argv)
    dns = read_dns(args.dns)
    ours = read_run(args.stats) if args.stats.endswith(".nc") else read_dns(args.stats)
    out_dir = args.out or os.path.join(os.path.dirname(os.path.abspath(args.stats)), "compare")
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise InputError("%s: cannot create the output directory (%s)" % (out_dir, e.strerror))
    print("ours: %s, Re_tau = %.2f" % (ours["source"], ours["re_tau"]))
    print("DNS:  %s, Re_tau = %.2f" % (dns["source"], dns["re_tau"]))
    yp, yd = ours["yplus"], ours["y_delta"]
    inside = (yp >= dns["yplus"][0]) & (yp <= dns["yplus"][-1])
    masks = region_masks(yp, yd)
    rows = []
    print("%-8s %-17s %6s %12s %12s %12s %12s" % ("quantity", "range", "points", "L2", "Linf",
                                                   "L2 relative", "stderr"))
    for q in QUANTITIES:
        if dns.get(q) is None or ours.get(q) is None:
            print("%-8s (not in both data sets)" % q)
            continue
        ref = np.interp(yp, dns["yplus"], dns[q])
        diff = ours[q] - ref
        for (name, _), m in zip(RANGES, masks):
            sel = m & inside & np.isfinite(diff)
            if not sel.any():
                rows.append((q, name, 0, math.nan, math.nan, math.nan, math.nan))
                print("%-8s %-17s %6d %12s %12s %12s %12s" % (q, name, 0, "-", "-", "-", "-"))
                continue
            l2 = math.sqrt(np.mean(diff[sel] ** 2))
            linf = float(np.max(np.abs(diff[sel])))
            scale = math.sqrt(np.mean(ref[sel] ** 2))
            se = ours.get(q + "_se")
            se_rms = math.sqrt(np.mean(se[sel] ** 2)) if se is not None else math.nan
            rows.append((q, name, int(sel.sum()), l2, linf, l2 / scale if scale > 0 else math.nan,
                         se_rms))
            print("%-8s %-17s %6d %12.4e %12.4e %12.4e %12.4e" % rows[-1])
    with open(os.path.join(out_dir, "compare.csv"), "w") as f:
        f.write("# ours: %s\n# DNS: %s\nquantity,range,points,L2,Linf,L2_relative,stderr\n" %
                (ours["source"], dns["source"]))
        for r in rows:
            f.write("%s,%s,%d,%.6e,%.6e,%.6e,%.6e\n" % r)
    if not args.no_plots:
        plots(ours, dns, out_dir)
    print_budget(ours)
    print("wrote %s/compare.csv%s" % (out_dir, "" if args.no_plots else " and one PNG per quantity"))
    if args.max_error is not None:
        worst = max((max(r[3], r[4]) for r in rows if r[2] > 0), default=math.nan)
        ok = worst <= args.max_error
        print("largest error %.3e (limit %.3g): %s" % (worst, args.max_error, "PASS" if ok else "FAIL"))
        return 0 if ok else 1
    return 0


def plots(ours, dns, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    for q in QUANTITIES:
        if dns.get(q) is None or ours.get(q) is None:
            continue
        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.semilogx(dns["yplus"][1:], dns[q][1:], "k-", lw=1.2, label="DNS: " + dns["name"])
        se = ours.get(q + "_se")
        yerr = None
        if se is not None and np.isfinite(se).any():
            yerr = np.where(np.isfinite(se), 2 * se, 0.0)
        ax.errorbar(ours["yplus"], ours[q], yerr=yerr, fmt="o", ms=3, capsize=2,
                    label="%s (bars: 2 standard errors)" % ours["label"])
        if q == "U+":
            y = np.logspace(-1, math.log10(max(dns["yplus"][-1], ours["yplus"][-1])), 200)
            ax.semilogx(y[y < 12], y[y < 12], "g--", lw=0.8, label="U+ = y+")
            ax.semilogx(y[y > 5], np.log(y[y > 5]) / KAPPA + B_LOG, "r--", lw=0.8,
                        label="log law (kappa 0.41, B 5.2)")
        ax.set_xlabel("y+")
        ax.set_ylabel(q)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        name = q.replace("'", "").replace("-", "minus_").replace("+", "plus")
        fig.savefig(os.path.join(out_dir, "%s.png" % name), dpi=110)
        plt.close(fig)
