"""chansph compare: profiles of a run (stats.nc) against a DNS data set, in wall units.

Also run as: stats/python/chansph-stats compare STATS.nc --dns FILE ...

FILE is one file of a DNS set we ship in stats/dns/ (or one in the same formats):
  Moser, Kim & Mansour 1999: chanNNN.means (+ companion chanNNN.reystress, found by name)
  Lee & Moser 2015:          LM_Channel_NNNN_mean_prof.dat (+ derived/LM_Channel_RetauNNN.txt)
                             or the derived table itself.
STATS.nc may itself be a DNS file: comparing a DNS set with itself gives zero error.

Wall units come from the run's u_tau, chosen with --u-tau: "wall" (default: the wall stress
averaged over the averaging range, stats.nc attribute u_tau_wall), "force" (the force
balance, u_tau_force: the driving u_tau of a force-driven run) or a number in m/s. Every table,
compare.csv and every plot title say which u_tau and over which span (average_start ..
average_end, number of windows); the summary names the largest error. A warning is printed
with fewer than 2 windows (no standard errors: the plots then have no error bars) and when the
run's Re_tau differs from the DNS's by more than 20%. The DNS profiles are
interpolated (linearly in y+) to the run's bin positions; the upper half of an unfolded run
is mirrored onto the lower one. Files from checkpoint format 1.12 on hold the stresses about
the local mean U(y) (the engine removes the mean's spread over each bin): the default
comparison is then fair at the wall too. With --binned the DNS is instead seen through the
run's bins (dns.through_bins): bin averages, and u_rms+ broadened by the spread of the mean
velocity over the bin (+76% in the wall bin of dr+ = 6, +5% at y+ = 12, below 2% beyond
y+ = 15), against our stresses about the bin mean (uu_bin ...; an older file has only those):
the like-for-like comparison of binned estimates. Standard errors are widened by
sqrt(n_windows / n_eff_windows) where the file has it, and bins whose windows are shorter than
their correlation time are marked. Prints the L2 (root mean square) and Linf (maximum)
differences of U+, u_rms+, v_rms+, w_rms+ and -u'v'+ per y+ range, with the RMS over the range
of our own standard error (batch means over the averaging windows; "stderr"): a difference much
larger than it is a model or resolution error, one of its size is sampling noise. Writes
compare.csv and one PNG per quantity (ours with error bars of 2 standard errors, DNS, law of
the wall).
A run whose stats.nc has the Reynolds-stress budgets (rsb_*) also gets their table against the
MKM Re_tau = 180 balances at y+ = 10, 15, 30, 50, rs_budget.csv and (without --no-plots)
rs_budget_<c>.png in the output directory (`chansph-stats rs_budget --help`).
A run with the momentum budget also gets the numerical pair stress read as a viscosity
(numvisc.py): nu_num / nu = pair+ / (dU+/dy+) at a few heights, and the deviations and peak
positions over 10 < y < 60 in y+ and in the wall units of nu + nu_num, y*+
(numerical_viscosity.csv).
"""
import argparse
import math
import os

import numpy as np

from . import budget_compare, cli, numvisc
from .budget_compare import read_budgets
from .cli import InputError
from .dns import QUANTITIES, read_dns, through_bins
from .merge import peak_position
from .ncfile import attribute, attribute_or_nan, need, open_nc

RANGES = (("viscous sublayer", "y+ < 5"), ("buffer layer", "5 <= y+ < 30"),
          ("log layer", "y+ >= 30, y/delta < 0.3"), ("outer layer", "y+ >= 30, y/delta >= 0.3"))
KAPPA, B_LOG = 0.41, 5.2


def pick_u_tau(a, choice, path):
    """The u_tau of choice ("wall", "force" or a number) and the words that say which and over
    which span, from the global attributes a of a stats.nc."""
    span = "t = %.6g .. %.6g s, %d windows" % (a.get("average_start", math.nan),
                                               a.get("average_end", math.nan),
                                               int(a.get("n_windows", 0)))
    if choice in ("wall", "force"):
        ut = float(a.get("u_tau_" + choice, math.nan))
        what = "wall stress" if choice == "wall" else "force balance"
        if not ut > 0:
            raise InputError("%s: no positive u_tau (%s, attribute u_tau_%s = %r): no averaging "
                             "window completed yet?" % (path, what, choice, ut))
        return ut, "u_tau = %.6g m/s (%s, %s)" % (ut, what, span)
    try:
        ut = float(choice)
    except ValueError:
        raise InputError("--u-tau %s: expected force, wall or a number in m/s" % choice)
    if not (math.isfinite(ut) and ut > 0):
        raise InputError("--u-tau %s: must be a positive number" % choice)
    return ut, "u_tau = %.6g m/s (given with --u-tau; run averaged over %s)" % (ut, span)


def read_run(path, u_tau="wall", binned=False):
    """Our profiles in wall units of u_tau (pick_u_tau; lower half, upper half mirrored), with
    standard errors: the stresses about the local mean U(y) where the file has them (variable
    local_mean), about the bin mean with binned (uu_bin ...; files without them have only
    those); the standard errors widened by sqrt(n_windows / n_eff_windows) where the file has
    the effective number of windows, and the bins of short windows (short_windows) marked."""
    with open_nc(path) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}

        def v(name):
            return np.ma.filled(need(d, name, path, "a chansph stats.nc with profiles")[:]
                                .astype(float), np.nan)
        has_local = "local_mean" in d.variables
        names = ("uu", "vv", "ww", "uv")
        if binned and has_local:
            names = tuple(n + "_bin" for n in names)
        y, u, uu, vv, ww, uv = (v(n) for n in ("y_mean", "u_mean") + names)
        local = v("local_mean") if has_local else np.zeros_like(y)
        bounds = v("y_bounds") if "y_bounds" in d.variables else None
        se = {n: v(n + "_stderr") for n in ("u_mean", "uu", "vv", "ww", "uv")}
        n_eff = v("n_eff_windows") if "n_eff_windows" in d.variables else None
        short = v("short_windows") if "short_windows" in d.variables else np.zeros_like(y)
        nwin = float(a.get("n_windows", 0))
        if n_eff is not None and nwin >= 2:
            widen = np.sqrt(np.where(np.isfinite(n_eff) & (n_eff > 0),
                                     np.maximum(nwin / np.where(n_eff > 0, n_eff, 1), 1.0), 1.0))
            se = {n: x * widen for n, x in se.items()}
        budget = {n: v(n) for n in BUDGET + ("total_stress", "total_stress_expected",
                                             "momentum_change") + ALL
                  if n in d.variables} if "pair_stress" in d.variables else {}
        nu, delta = (float(attribute(d, k, path)) for k in ("nu", "delta"))
        if u_tau == "wall" and "u_tau_wall" not in a:  # no wall stress: the file's u_tau
            a["u_tau_wall"] = attribute_or_nan(d, "u_tau")
    ut, ut_label = pick_u_tau(a, u_tau, path)
    upper = y > delta
    y = np.where(upper, 2 * delta - y, y)
    sign = np.where(upper, -1.0, 1.0)
    out = {"yplus": y * ut / nu, "y_delta": y / delta, "re_tau": ut * delta / nu, "label": "chansph",
           "source": "chansph %s (%s)" % (path, ut_label), "u_tau_label": ut_label,
           "n_windows": int(a.get("n_windows", 0)), "run": path,
           "short": np.nan_to_num(short) > 0, "local": np.nan_to_num(local) > 0,
           "has_local": has_local, "widened": n_eff is not None and nwin >= 2}
    if bounds is not None:  # the bins in y+, mirrored like y
        lo = np.where(upper, 2 * delta - bounds[:, 1], bounds[:, 0])
        hi = np.where(upper, 2 * delta - bounds[:, 0], bounds[:, 1])
        out["yplus_lo"], out["yplus_hi"] = lo * ut / nu, hi * ut / nu
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
# the budget's total from every snapshot (format 1.14), the parts from the budget snapshots
ALL = ("total_stress_all", "total_stress_expected_all", "momentum_change_all")


def print_budget(ours):
    """The split of the total stress at a few heights (docs/stats-format.md, momentum budget)."""
    names = [n for n in BUDGET if "budget:" + n in ours]
    if not names:
        return
    yp = ours["yplus"]
    tot, exp = ours["budget:total_stress"], ours["budget:total_stress_expected"]
    # the unsteady term: total + d/dt = expected in any window (absent in earlier files: 0)
    ddt = np.nan_to_num(ours.get("budget:momentum_change", np.zeros_like(tot)))
    every = all(np.any(np.isfinite(ours.get("budget:" + n, [np.nan]))) for n in ALL)
    if every:  # the closure over every snapshot; the shares of the budget snapshots' parts
        tot_c, ddt, exp = (ours["budget:" + n] for n in ("total_stress_all", "momentum_change_all",
                                                          "total_stress_expected_all"))
    else:
        tot_c = tot
    closure = tot_c + ddt - exp
    print("momentum budget (shares of total_stress; total, d/dt (momentum_change), expected and "
          "closure = total + d/dt - expected in u_tau^2%s):"
          % (", the last four over every snapshot (the *_all fields)" if every else ""))
    print("%8s %8s " % ("y+", "y/delta") + " ".join("%10s" % n.replace("_stress", "")[:10]
                                                  for n in names) +
          " %9s %9s %9s %9s" % ("total", "d/dt", "expected", "closure"))
    rows = sorted({int(np.argmin(np.abs(yp - t))) for t in (5.0, 15.0, 30.0, 100.0,
                                                             0.5 * ours["re_tau"])})
    for i in rows:
        print("%8.1f %8.3f " % (yp[i], ours["y_delta"][i]) +
              " ".join("%9.0f%%" % (100 * ours["budget:" + n][i] / tot[i]) for n in names) +
              " %9.4f %9.4f %9.4f %9.4f" % (tot_c[i], ddt[i], exp[i], closure[i]))
    worst = int(np.nanargmax(np.abs(closure)))
    print("budget closure: max |total + d/dt - expected| = %.4f u_tau^2 at y+ %.1f (over %d bins)"
          % (abs(closure[worst]), yp[worst], np.sum(np.isfinite(closure))))


def region_masks(yp, yd):
    return (yp < 5, (yp >= 5) & (yp < 30), (yp >= 30) & (yd < 0.3), (yp >= 30) & (yd >= 0.3))


def peak_range(text):
    """LO:HI with 0 <= LO < HI: the y+ range of the peak table."""
    try:
        lo, hi = (float(x) for x in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError("'%s' is not LO:HI (two numbers, e.g. 10:100)" % text)
    if not (0 <= lo < hi and math.isfinite(hi)):
        raise argparse.ArgumentTypeError("'%s': need 0 <= LO < HI" % text)
    return lo, hi


def parse(argv, prog):
    p = cli.parser(prog, __doc__, raw=True)
    p.add_argument("stats", help="stats.nc of a run (or a DNS file)")
    p.add_argument("--dns", required=True, help="one file of a DNS set")
    p.add_argument("--out", help="directory for compare.csv and the PNGs (default: beside STATS)")
    p.add_argument("--u-tau", default="wall", metavar="force|wall|VALUE",
                   help="u_tau of the wall units: wall (the averaged wall stress, default), force "
                        "(the force balance) or a value in m/s")
    p.add_argument("--binned", action="store_true",
                   help="compare with the DNS as the run's bins see it (bin averages, u_rms+ "
                        "broadened by the mean shear over the bin) instead of its values at "
                        "the bins' mean positions")
    p.add_argument("--no-plots", action="store_true")
    p.add_argument("--peak-range", default="10:150", metavar="LO:HI", type=peak_range,
                   help="the y+ range of the deviation relative to the DNS peak (default 10:150; "
                        "10:100 is the range of the same-box comparison)")
    p.add_argument("--max-error", type=cli.number(float, 0),
                   help="exit with status 1 if any L2 or Linf error exceeds this (tests)")
    return p.parse_args(argv)


def warnings_for(ours, dns):
    """Warnings on what the comparison cannot show: too few windows, another Re_tau."""
    out = []
    if ours.get("n_windows") is not None and ours["n_windows"] < 2:
        out.append("%d averaging windows: no standard errors (at least 2 needed); the "
                   "differences may be sampling noise" % ours["n_windows"])
    if "has_local" in ours and not ours["has_local"]:
        out.append("the stresses of this file are about the bin mean (written before checkpoint "
                   "format 1.12): near the wall they hold the mean velocity's spread over the "
                   "bin; --binned compares like for like")
    elif "has_local" in ours and not ours["local"].all():
        out.append("%d bins have their stresses about the bin mean (records of format 1.11 or "
                   "older in the range)" % int((~ours["local"]).sum()))
    if "short" in ours and ours["short"].any():
        out.append("%d bins have windows shorter than their correlation time: their standard "
                   "errors are widened by sqrt(n_windows / n_eff_windows)%s and marked with "
                   "open symbols in the plots" % (int(ours["short"].sum()),
                                                  "" if ours.get("widened") else " (not: no "
                                                  "n_eff_windows)"))
    if abs(ours["re_tau"] / dns["re_tau"] - 1) > 0.2:
        out.append("the run's Re_tau = %.1f differs from the DNS's %.1f by more than 20%%: the "
                   "profiles in wall units are not expected to agree" %
                   (ours["re_tau"], dns["re_tau"]))
    return out


def largest(rows):
    """The row with the largest relative L2 error, as words (or None)."""
    have = [r for r in rows if r[2] > 0 and math.isfinite(r[5])]
    if not have:
        return None
    r = max(have, key=lambda r: r[5])
    return "%s in the %s: L2 %.1f%% of the DNS (Linf %.3g)" % (r[0], r[1], 100 * r[5], r[4])


def main(argv, prog="chansph compare"):
    args = parse(argv, prog)
    dns = read_dns(args.dns)
    ours = (read_run(args.stats, args.u_tau, args.binned) if args.stats.endswith(".nc")
            else read_dns(args.stats))
    ours.setdefault("u_tau_label", "the DNS file's own wall units")
    out_dir = args.out or os.path.join(os.path.dirname(os.path.abspath(args.stats)), "compare")
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise InputError("%s: cannot create the output directory (%s)" % (out_dir, e.strerror))
    print("ours: %s, Re_tau = %.2f" % (ours["source"], ours["re_tau"]))
    print("DNS:  %s, Re_tau = %.2f" % (dns["source"], dns["re_tau"]))
    for w in warnings_for(ours, dns):
        print("warning: " + w)
    yp, yd = ours["yplus"], ours["y_delta"]
    refs = references(ours, dns, args.binned, args.stats)
    inside = (yp >= dns["yplus"][0]) & (yp <= dns["yplus"][-1])
    masks = region_masks(yp, yd)
    rows = []
    print("differences in wall units of %s:" % ours["u_tau_label"])
    print("%-8s %-17s %6s %12s %12s %12s %12s" % ("quantity", "range", "points", "L2", "Linf",
                                                   "L2 relative", "stderr"))
    for q in QUANTITIES:
        if dns.get(q) is None or ours.get(q) is None:
            print("%-8s (not in both data sets)" % q)
            continue
        ref = refs[q]
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
    peak_table(ours, dns, refs, inside, *args.peak_range)
    worst = largest(rows)
    if worst:
        print("largest error: %s (wall units of %s)" % (worst, ours["u_tau_label"]))
    with open(os.path.join(out_dir, "compare.csv"), "w") as f:
        f.write("# ours: %s\n# DNS: %s\n# wall units of %s\n"
                "quantity,range,points,L2,Linf,L2_relative,stderr\n" %
                (ours["source"], dns["source"], ours["u_tau_label"]))
        for r in rows:
            f.write("%s,%s,%d,%.6e,%.6e,%.6e,%.6e\n" % r)
    if not args.no_plots:
        plots(ours, dns, out_dir, refs if args.binned else None)
    print_budget(ours)
    nv = numvisc.report(ours, dns, out_dir, QUANTITIES)
    print("wrote %s/compare.csv%s%s" % (out_dir, ", numerical_viscosity.csv" if nv else "",
                                        "" if args.no_plots else " and one PNG per quantity"))
    budgets = read_budgets(args.stats, args.u_tau) if args.stats.endswith(".nc") else None
    if budgets is not None:  # the Reynolds-stress budgets (rsb_*) against the MKM balances
        budget_compare.report(budgets, budget_compare.read_dns(), budget_compare.DEFAULT_LEVELS,
                              out_dir, not args.no_plots)
    if args.max_error is not None:
        worst = max((max(r[3], r[4]) for r in rows if r[2] > 0), default=math.nan)
        ok = worst <= args.max_error
        print("largest error %.3e (limit %.3g): %s" % (worst, args.max_error, "PASS" if ok else "FAIL"))
        return 0 if ok else 1
    return 0


def references(ours, dns, binned, path):
    """The DNS at our bins: interpolated to their mean positions, or (binned) as the bins see
    it (dns.through_bins). Prints which."""
    if not binned:
        return {q: np.interp(ours["yplus"], dns["yplus"], dns[q]) for q in QUANTITIES
                if dns.get(q) is not None}
    if "yplus_lo" not in ours:
        raise InputError("--binned: %s has no bin bounds (y_bounds): not a chansph stats.nc"
                         % path)
    print("the DNS as the run's bins see it (--binned): bin averages, u_rms+ broadened by the "
          "mean shear over each bin%s" % ("; ours: the stresses about the bin mean (uu_bin ...)"
                                          if ours.get("has_local") else ""))
    return through_bins(dns, ours["yplus_lo"], ours["yplus_hi"], ours["yplus"])


def peak_table(ours, dns, refs, inside, lo=10.0, hi=150.0):
    """The deviation relative to the DNS peak over lo < y+ < hi (the converged run's measure): per
    quantity max |ours - DNS| / max |DNS| and our largest standard error over the range
    relative to the same peak, with the y+ of the largest deviation; for the stresses also
    both peaks and their positions (merge.peak_position: the parabola through the largest bin
    and its neighbours)."""
    sel = inside & (ours["yplus"] > lo) & (ours["yplus"] < hi)
    if not sel.any():
        return
    print("deviation relative to the DNS peak over %g < y+ < %g (%d bins): max |ours - DNS| / "
          "DNS peak, at y+; largest stderr / DNS peak" % (lo, hi, int(sel.sum())))
    for q in QUANTITIES:
        if dns.get(q) is None or ours.get(q) is None:
            continue
        peak = float(np.nanmax(np.abs(dns[q])))
        diff = np.abs(ours[q] - refs[q])[sel]
        if not np.isfinite(diff).any() or peak <= 0:
            continue
        k = int(np.nanargmax(diff))
        se = ours.get(q + "_se")
        se_max = (float(np.nanmax(se[sel])) / peak
                  if se is not None and np.isfinite(se[sel]).any() else math.nan)
        where = ""
        if q != "U+":  # the stresses' peaks and where they are (U+ peaks at the centre)
            where = "   peak %.3f at y+ %5.1f (DNS %.3f at y+ %5.1f)" % (
                float(np.nanmax(ours[q])), peak_position(ours["yplus"], ours[q]),
                float(np.nanmax(dns[q])), peak_position(dns["yplus"], dns[q]))
        print("  %-7s %6.1f%% at y+ %5.1f   stderr %s%s"
              % (q, 100 * diff[k] / peak, ours["yplus"][sel][k],
                 "%5.1f%%" % (100 * se_max) if math.isfinite(se_max) else "    -", where))


def plot_title(ours):
    """The title of every plot: the run, Re_tau, the u_tau of the wall units, the windows."""
    run = ours.get("run", ours.get("source", ""))
    wins = "" if ours.get("n_windows") is None else ", %d windows" % ours["n_windows"]
    return "%s: Re_tau = %.1f%s\nwall units of %s" % (run, ours["re_tau"], wins,
                                                     ours["u_tau_label"])


def plots(ours, dns, out_dir, binned=None):
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
        if se is not None and np.isfinite(se).any() and ours.get("n_windows", 2) >= 2:
            yerr = np.where(np.isfinite(se), 2 * se, 0.0)
        ax.errorbar(ours["yplus"], ours[q], yerr=yerr, fmt="o", ms=3, capsize=2,
                    label=ours["label"] + (" (bars: 2 standard errors)" if yerr is not None
                                           else " (no standard errors: < 2 windows)"))
        short = ours.get("short")
        if short is not None and short.any():
            ax.plot(ours["yplus"][short], ours[q][short], "o", ms=7, mfc="none", mec="r",
                    label="windows shorter than the correlation time (bars widened)")
        if binned is not None and q in binned:
            ax.semilogx(ours["yplus"], binned[q], "kx", ms=4, label="DNS through the bins")
        if q == "U+":
            y = np.logspace(-1, math.log10(max(dns["yplus"][-1], ours["yplus"][-1])), 200)
            ax.semilogx(y[y < 12], y[y < 12], "g--", lw=0.8, label="U+ = y+")
            ax.semilogx(y[y > 5], np.log(y[y > 5]) / KAPPA + B_LOG, "r--", lw=0.8,
                        label="log law (kappa 0.41, B 5.2)")
        ax.set_xlabel("y+")
        ax.set_ylabel(q)
        ax.grid(True, which="both", alpha=0.3)
        leg = ax.legend(fontsize=8)
        title = plot_title(ours)
        ax.set_title(title, fontsize=8)
        fig.tight_layout()
        name = q.replace("'", "").replace("-", "minus_").replace("+", "plus")
        legend = "; ".join(t.get_text() for t in leg.get_texts())
        fig.savefig(os.path.join(out_dir, "%s.png" % name), dpi=110,
                    metadata={"Title": title.replace("\n", " "), "Description": legend})
        plt.close(fig)
