#!/usr/bin/python3
"""chansph compare: profiles of a run (stats.nc) against a DNS data set, in wall units.

usage: chansph compare STATS.nc --dns FILE [--out DIR] [--no-plots]
       (or: python3 stats/compare.py STATS.nc --dns FILE ...)

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
import argparse
import math
import os
import re
import sys

import numpy as np

QUANTITIES = ("U+", "u_rms+", "v_rms+", "w_rms+", "-u'v'+")
RANGES = (("viscous sublayer", "y+ < 5"), ("buffer layer", "5 <= y+ < 30"),
          ("log layer", "y+ >= 30, y/delta < 0.3"), ("outer layer", "y+ >= 30, y/delta >= 0.3"))
KAPPA, B_LOG = 0.41, 5.2


class InputError(Exception):
    """A file or argument chansph compare cannot use: reported as "error: ..." with exit 1."""


def numeric_rows(path, ncol, what):
    """Rows of numbers of a text file, checked: comment (#, %) lines and column-name lines
    before the first row are skipped; every row has at least ncol numbers, as many as the rows
    above, all finite; at least 2 rows. Returns the rows and their line numbers. Raises
    InputError naming the file and line (what: what the file should be, for the message)."""
    if not os.path.isfile(path):
        raise InputError("%s: cannot open %s: %s" % (path, what, "No such file" if not
                         os.path.exists(path) else "not a regular file"))
    rows, lines, width = [], [], None
    try:
        with open(path, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                if "\0" in line:
                    raise InputError("%s:%d: binary data, not a text table (%s)" % (path, n, what))
                s = line.strip()
                if not s or s[0] in "#%":
                    continue
                try:
                    row = [float(x) for x in re.split(r"[,\s]+", s) if x]
                except ValueError:
                    if rows:
                        raise InputError("%s:%d: not a row of numbers: %.60s" % (path, n, s))
                    continue  # a column-name line before the data
                if len(row) < ncol:
                    raise InputError("%s:%d: %d column(s), %s needs at least %d" %
                                     (path, n, len(row), what, ncol))
                if width is not None and len(row) != width:
                    raise InputError("%s:%d: %d columns, the rows above have %d" %
                                     (path, n, len(row), width))
                bad = [k + 1 for k, x in enumerate(row) if not math.isfinite(x)]
                if bad:
                    raise InputError("%s:%d: non-finite value (NaN or Inf) in column %d" %
                                     (path, n, bad[0]))
                width = len(row)
                rows.append(row)
                lines.append(n)
    except UnicodeDecodeError as e:
        raise InputError("%s: binary data, not a text table (%s): %s" % (path, what, e.reason))
    except OSError as e:
        raise InputError("%s: cannot read %s: %s" % (path, what, e.strerror))
    if len(rows) < 2:
        raise InputError("%s: %s holds %d data row(s) (empty or header only?); at least 2 "
                         "are needed" % (path, what, len(rows)))
    return np.array(rows), lines


def increasing(path, a, col, lines, name):
    """Column col of a (y+ or y/delta) must strictly increase, row by row."""
    for i in range(1, len(a)):
        if not a[i, col] > a[i - 1, col]:
            raise InputError("%s:%d: %s = %.6g is not larger than the previous row's %.6g (rows "
                             "must go from the wall outwards)" %
                             (path, lines[i], name, a[i, col], a[i - 1, col]))
    if not a[-1, col] > 0:
        raise InputError("%s: the last %s is %.6g, not positive" % (path, name, a[-1, col]))


def read_dns(path):
    """A DNS set as a dict: yplus, y_delta, re_tau and the QUANTITIES (None if absent)."""
    base = os.path.basename(path)
    d = os.path.dirname(path)
    out = {"name": base, "label": base}
    m = re.match(r"chan(\d+)\.(means|reystress)$", base)
    if m:  # Moser, Kim & Mansour 1999
        means = os.path.join(d, "chan%s.means" % m.group(1))
        rey = os.path.join(d, "chan%s.reystress" % m.group(1))
        a, lines = numeric_rows(means, 3, "a mean profile (y/delta, y+, U+)")
        increasing(means, a, 0, lines, "y/delta")
        increasing(means, a, 1, lines, "y+")
        out.update(yplus=a[:, 1], y_delta=a[:, 0], re_tau=a[-1, 1] / a[-1, 0])
        out["U+"] = a[:, 2]
        out["source"] = "Moser, Kim & Mansour (1999), %s" % os.path.basename(means)
        if os.path.exists(rey):
            r, _ = numeric_rows(rey, 6, "a Reynolds-stress table (y/delta, y+, uu, vv, ww, uv)")
            if r.shape[0] != a.shape[0] or not np.allclose(r[:, 1], out["yplus"]):
                raise InputError("%s and %s have different y+ points" % (means, rey))
            out["u_rms+"], out["v_rms+"], out["w_rms+"] = (np.sqrt(np.abs(r[:, k])) for k in (2, 3, 4))
            out["-u'v'+"] = -r[:, 5]
            out["source"] += " + " + os.path.basename(rey)
        return out
    m = re.match(r"LM_Channel_(\d+)_mean_prof\.dat$", base)
    derived = None
    if m:  # Lee & Moser 2015, mean profile
        a, lines = numeric_rows(path, 3, "a mean profile (y/delta, y+, U+)")
        increasing(path, a, 0, lines, "y/delta")
        increasing(path, a, 1, lines, "y+")
        out.update(yplus=a[:, 1], y_delta=a[:, 0], re_tau=a[-1, 1] / a[-1, 0], source=
                   "Lee & Moser (2015), %s" % base)
        out["U+"] = a[:, 2]
        cand = os.path.join(d, "derived", "LM_Channel_Retau%d.txt" % int(m.group(1)))
        derived = cand if os.path.exists(cand) else None
    elif re.match(r"LM_Channel_Retau(\d+)\.txt$", base):
        derived = path
    if derived:
        names = ("y+", "u_1", "uu_11", "uu_22", "uu_33", "uu_12")
        a, lines = numeric_rows(derived, len(names), "a Lee & Moser derived table")
        try:
            with open(derived, encoding="utf-8") as f:
                header = [h.strip() for h in f.readline().split(",")]
        except (OSError, UnicodeDecodeError) as e:
            raise InputError("%s: cannot read the header line: %s" % (derived, e))
        col = {h: i for i, h in enumerate(header)}
        missing = [h for h in names if h not in col or col[h] >= a.shape[1]]
        if missing:
            raise InputError("%s: the header line names no column %s" % (derived, missing[0]))
        increasing(derived, a, col["y+"], lines, "y+")
        yp = a[:, col["y+"]]
        if "yplus" not in out:
            out.update(yplus=yp, re_tau=yp[-1], y_delta=yp / yp[-1], source="Lee & Moser (2015)")
            out["U+"] = a[:, col["u_1"]]

        def on_grid(v):
            return np.interp(out["yplus"], yp, v)
        out["u_rms+"] = on_grid(np.sqrt(np.abs(a[:, col["uu_11"]])))
        out["v_rms+"] = on_grid(np.sqrt(np.abs(a[:, col["uu_22"]])))
        out["w_rms+"] = on_grid(np.sqrt(np.abs(a[:, col["uu_33"]])))
        out["-u'v'+"] = on_grid(-a[:, col["uu_12"]])
        out["source"] += " + derived/" + os.path.basename(derived)
        return out
    if m:
        return out
    if not os.path.exists(path):
        raise InputError("%s: no such file" % path)
    raise InputError("%s: not a DNS file of a known set: the name must be chanNNN.means or "
                     "chanNNN.reystress (Moser, Kim & Mansour 1999), LM_Channel_NNNN_mean_prof.dat "
                     "or LM_Channel_RetauNNN.txt (Lee & Moser 2015)" % path)


def read_run(path):
    """Our profiles in wall units (lower half, upper half mirrored), with standard errors."""
    import netCDF4
    if not os.path.isfile(path):
        raise InputError("%s: cannot open: %s" % (path, "No such file" if not os.path.exists(path)
                                                  else "not a regular file"))
    try:
        d = netCDF4.Dataset(path)
    except OSError as e:
        raise InputError("%s: cannot open as netCDF (%s)" % (path, e.strerror or e))
    with d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}

        def v(name):
            if name not in d.variables:
                raise InputError("%s: no variable '%s' (not a chansph stats.nc with profiles?)" %
                                 (path, name))
            x = d[name][:]
            return np.ma.filled(x.astype(float), np.nan)
        y, u, uu, vv, ww, uv = (v(n) for n in ("y_mean", "u_mean", "uu", "vv", "ww", "uv"))
        se = {n: v(n + "_stderr") for n in ("u_mean", "uu", "vv", "ww", "uv")}
        budget = {n: v(n) for n in BUDGET + ("total_stress", "total_stress_expected",
                                             "momentum_change")
                  if n in d.variables} if "pair_stress" in d.variables else {}
    for k in ("u_tau", "nu", "delta"):
        if k not in a:
            raise InputError("%s: no global attribute '%s' (not a chansph stats.nc?)" % (path, k))
    ut, nu, delta = float(a["u_tau"]), float(a["nu"]), float(a["delta"])
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


class Parser(argparse.ArgumentParser):
    """Usage errors exit 1 (input error), as every chansph command."""

    def error(self, message):
        self.print_usage(sys.stderr)
        sys.exit("error: %s" % message)


def main():
    try:
        compare()
    except InputError as e:
        sys.exit("error: %s" % e)


def compare():
    p = Parser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("stats", help="stats.nc of a run (or a DNS file)")
    p.add_argument("--dns", required=True, help="one file of a DNS set")
    p.add_argument("--out", help="directory for compare.csv and the PNGs (default: beside STATS)")
    p.add_argument("--no-plots", action="store_true")
    p.add_argument("--max-error", type=float,
                   help="exit with status 1 if any L2 or Linf error exceeds this (tests)")
    args = p.parse_args()
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
        sys.exit(0 if ok else 1)


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


if __name__ == "__main__":
    main()
