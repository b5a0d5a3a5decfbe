"""Reynolds-stress budgets of a run (stats.nc, rsb_*) against the MKM Re_tau = 180 balances.

usage: chansph-stats rs_budget STATS.nc [--dns-dir DIR] [--u-tau wall|force|VALUE]
                                         [--y-plus 10,15,30,50] [--out DIR] [--markdown]

The run's budgets are the root variables rsb_<c>_<t> and rsb_<c>_<t>_stderr on dimension y
(docs/stats-format.md, "Reynolds-stress budgets"): c = uu, vv, ww, uv, k (k = (uu+vv+ww)/2;
uv is the budget of <u'v'> itself), t = pressure, viscous, model (LES only: attribute les = 1),
wall, drive, transfer, production, transport, rate, closure; each the contribution of that term
to d<u_i'u_j'>/dt, gains positive, in m^2/s^3. They are put in wall units (term * nu /
u_tau^4, y+ = y_mean u_tau / nu) with the u_tau of --u-tau: wall (default, u_tau_wall; the
file's u_tau without it), force (u_tau_force) or a value in m/s. In an unfolded run (fold = 0)
the upper half is mirrored (y -> 2 delta - y; the uv terms change sign there); bins that mirror
onto each other are averaged (standard error sqrt(se1^2 + se2^2) / 2).

MKM (Moser, Kim & Mansour 1999): chan180.{uu,vv,ww,uv,k}bal of --dns-dir (default the shipped
stats/dns/mkm1999/balances), columns y, y+, dissip, produc, p-strain, p-diff, t-diff, v-diff,
bal in u_tau^4/nu, interpolated linearly in y+ to the run's bins (NaN beyond the centre).
Mapping (ours <-> MKM):
  production   <-> produc
  pressure     <-> p-strain + p-diff
  viscous+wall <-> dissip + v-diff   (viscous and wall are also printed on their own)
  transport    <-> t-diff            (transfer = production + transport <-> produc + t-diff)
  rate         <-> 0                 (MKM is statistically steady)
  closure      <-> bal
  model (LES) and drive have no MKM counterpart.
The standard error of a sum of our terms is taken as the root sum of squares of theirs.

Printed per component: at each --y-plus level the nearest bin (its own y+), each term as ours
+- 2 standard errors, MKM at that bin's y+ and the difference ('*' when it exceeds 2 standard
errors), and how well the file's closure equals sum(terms) - rate. With --out: rs_budget.csv
(component, term, y+, ours, stderr, dns for every bin) and rs_budget_<c>.png per component.
A file without rsb_ variables is an input error (exit 1).
"""
import glob
import math
import os
import re

import numpy as np

from . import cli
from .cli import InputError
from .ncfile import attribute, attribute_or_nan, need, open_nc, values
from .twopoint import DNS_ROOT

COMPONENTS = ("uu", "vv", "ww", "uv", "k")
TERMS = ("pressure", "viscous", "model", "wall", "drive", "transfer", "production", "transport",
         "rate", "closure", "pressure_noise")
SOURCES = ("pressure", "viscous", "model", "wall", "drive", "transfer")  # sum - rate = closure
DNS_COLUMNS = ("y", "y+", "dissip", "produc", "p-strain", "p-diff", "t-diff", "v-diff", "bal")
DEFAULT_DNS = os.path.normpath(os.path.join(DNS_ROOT, "balances"))
DEFAULT_LEVELS = (10.0, 15.0, 30.0, 50.0)
# (row name, our terms summed, MKM columns summed; None: no MKM counterpart; (): zero)
ROWS = (("production", ("production",), ("produc",)),
        ("pressure", ("pressure",), ("p-strain", "p-diff")),
        ("pressure_noise", ("pressure_noise",), None),
        ("pressure+wall", ("pressure", "wall"), ("p-strain", "p-diff")),
        ("viscous+wall", ("viscous", "wall"), ("dissip", "v-diff")),
        ("viscous", ("viscous",), ("dissip", "v-diff")),
        ("wall", ("wall",), None),
        ("model", ("model",), None),
        ("drive", ("drive",), None),
        ("transport", ("transport",), ("t-diff",)),
        ("transfer", ("transfer",), ("produc", "t-diff")),
        ("rate", ("rate",), ()),
        ("closure", ("closure",), ("bal",)))
# the walls' part is viscous in x and z (wall shear) and mostly the normal pressure in y (the
# vertex pressure of the wall layer): vv is plotted with it in the pressure term
PLOTTED = ("production", "pressure", "viscous+wall", "transport", "rate", "closure")
PLOTTED_VV = ("production", "pressure+wall", "viscous", "transport", "rate", "closure")


def fold_halves(y, delta, fields, signs):
    """Mirror the upper half (y > delta) of profiles onto the lower one. fields: {name: (value,
    stderr)} arrays over y; signs: {name: +1 or -1}, the sign they take in the upper half.
    Bins that mirror onto each other (a layout symmetric about the centre to a quarter of a bin)
    are averaged; otherwise the mirrored bins are kept and sorted by y. Returns y and fields."""
    upper = y > delta
    ym = np.where(upper, 2 * delta - y, y)
    flipped = {k: (np.where(upper, signs[k] * v, v), s) for k, (v, s) in fields.items()}
    n, half = len(y), len(y) // 2
    j = n - 1 - np.arange(n)
    width = np.min(np.diff(np.sort(y))) if n > 1 else 0.0
    paired = (upper.any() and not upper[:half].any() and upper[n - half:].all() and
              bool(np.all(np.abs(ym - ym[j]) <= 0.25 * width)))
    if not paired:
        order = np.argsort(ym, kind="stable")
        return ym[order], {k: (v[order], s[order]) for k, (v, s) in flipped.items()}
    lo, hi = np.arange(n - half), j[:n - half]  # an odd middle bin pairs with itself
    out = {}
    for k, (v, s) in flipped.items():
        a, b, sa, sb = v[lo], v[hi], s[lo], s[hi]
        same = lo == hi
        both = np.isfinite(a) & np.isfinite(b) & ~same
        mean = np.where(both, 0.5 * (a + b), np.where(np.isfinite(a), a, b))
        se = np.where(both, 0.5 * np.sqrt(sa ** 2 + sb ** 2), np.where(np.isfinite(a), sa, sb))
        out[k] = (mean, se)
    return 0.5 * (ym[lo] + ym[hi]), out


def read_budgets(path, u_tau="wall"):
    """The Reynolds-stress budgets of a stats.nc in wall units, or None when the file has no
    rsb_ variable. Returns a dict: yplus, y_delta (lower half, upper mirrored), re_tau, u_tau,
    u_tau_label, source, les, n_windows and terms {c: {t: (value+, stderr+)}} (model only with
    les = 1). A file with some rsb_ variables but not all raises InputError naming the file and
    the missing variable."""
    from .compare import pick_u_tau  # compare imports this module: import here
    with open_nc(path) as d:
        if not any(n.startswith("rsb_") for n in d.variables):
            return None
        what = "a chansph stats.nc with Reynolds-stress budgets"
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        nu, delta = (float(attribute(d, k, path, what)) for k in ("nu", "delta"))
        if u_tau == "wall" and "u_tau_wall" not in a:  # no wall stress: the file's u_tau
            a["u_tau_wall"] = attribute_or_nan(d, "u_tau")
        les = int(a.get("les", 0)) == 1
        fold = int(a.get("fold", 0))
        y = values(need(d, "y_mean", path, what)).astype(float)
        # model only with LES; the pressure noise is absent in files of before 2026-12-03
        terms = [t for t in TERMS if (t != "model" or les) and
                 (t != "pressure_noise" or "rsb_uu_pressure_noise" in d.variables)]
        fields = {}
        for c in COMPONENTS:
            for t in terms:
                name = "rsb_%s_%s" % (c, t)
                fields[(c, t)] = (values(need(d, name, path, what)).astype(float),
                                  values(need(d, name + "_stderr", path, what)).astype(float))
    ut, ut_label = pick_u_tau(a, u_tau, path)
    signs = {k: (-1.0 if k[0] == "uv" else 1.0) for k in fields}
    if fold == 1:
        y = np.minimum(y, 2 * delta - y)  # a folded file holds only the lower half
    ym, fields = fold_halves(y, delta, fields, signs)
    scale = nu / ut ** 4
    out = {"yplus": ym * ut / nu, "y_delta": ym / delta, "re_tau": ut * delta / nu, "u_tau": ut,
           "u_tau_label": ut_label, "source": "chansph %s (%s)" % (path, ut_label), "les": les,
           "n_windows": int(a.get("n_windows", 0)), "run": path,
           "terms": {c: {} for c in COMPONENTS}}
    for (c, t), (v, s) in fields.items():
        out["terms"][c][t] = (v * scale, s * scale)
    return out


def read_dns(folder=DEFAULT_DNS):
    """The MKM balances chanNNN.<c>bal of folder: {c: {column: array}} for c in COMPONENTS
    (columns DNS_COLUMNS, wall units), plus re_tau (from a header line "Re = ..." or
    "Re_tau = ...") and source. InputError names the folder or the file and line."""
    from .dns import numeric_rows
    if not os.path.isdir(folder):
        raise InputError("%s: cannot open the MKM balances directory: %s" %
                         (folder, "No such directory" if not os.path.exists(folder)
                          else "not a directory"))
    out, re_tau = {}, math.nan
    for c in COMPONENTS:
        files = sorted(glob.glob(os.path.join(folder, "chan*.%sbal" % c)))
        if not files:
            raise InputError("%s: no MKM balance file chanNNN.%sbal" % (folder, c))
        rows, _ = numeric_rows(files[0], len(DNS_COLUMNS), "an MKM chanNNN.%sbal file" % c)
        rows = np.asarray(rows)
        if np.any(np.diff(rows[:, 1]) <= 0):
            raise InputError("%s: y+ (column 2) not increasing" % files[0])
        out[c] = {name: rows[:, k] for k, name in enumerate(DNS_COLUMNS)}
        with open(files[0], encoding="utf-8", errors="replace") as f:
            text = f.read()  # "# Re_tau = 178.12" (not the title's "Re_tau=590")
            m = (re.search(r"^#\s*Re_tau\s*=\s*([0-9.]+)", text, re.M) or
                 re.search(r"\bRe\s*=\s*([0-9.]+)", text))
        if m and not math.isfinite(re_tau):
            re_tau = float(m.group(1))
    out["re_tau"] = re_tau
    out["source"] = "MKM 1999 balances in %s (Re_tau = %.2f)" % (folder, re_tau)
    return out


def row_values(ours, dns, c, row):
    """(ours, stderr, dns) of one mapped row (ROWS) of component c over the run's bins, or None
    when the run lacks the row's terms (model without LES). dns is NaN without a counterpart
    and beyond the MKM range."""
    _, mine, theirs = row
    t = ours["terms"][c]
    if any(k not in t for k in mine):
        return None
    val = sum(t[k][0] for k in mine)
    se = np.sqrt(sum(t[k][1] ** 2 for k in mine))
    yp = ours["yplus"]
    if theirs is None:
        ref = np.full(len(yp), np.nan)
    elif not theirs:
        ref = np.zeros(len(yp))
    else:
        d = dns[c]
        col = sum(d[k] for k in theirs)
        ref = np.interp(yp, d["y+"], col, left=np.nan, right=np.nan)
    return val, se, ref


def levels_arg(text):
    """The y+ levels of --y-plus, "10,15,30,50"; InputError on anything else."""
    try:
        out = [float(x) for x in text.split(",")]
    except ValueError:
        out = []
    if not out or not all(math.isfinite(x) and x >= 0 for x in out):
        raise InputError("--y-plus %s: expected y+ values (>= 0) separated by commas" % text)
    return out


def closure_check(ours, c):
    """max |closure - (sum of the sources - rate)| over the bins (wall units) and its peak
    scale, the largest |term| of the component."""
    t = ours["terms"][c]
    rest = sum(t[k][0] for k in SOURCES if k in t) - t["rate"][0]
    dev = np.abs(t["closure"][0] - rest)
    peak = max(float(np.nanmax(np.abs(v))) if np.isfinite(v).any() else 0.0
               for v, _ in t.values())
    return (float(np.nanmax(dev)) if np.isfinite(dev).any() else math.nan), peak


def fmt(x, width=10, prec=4):
    return ("%*.*f" % (width, prec, x)) if math.isfinite(x) else "%*s" % (width, "-")


def print_tables(ours, dns, levels=DEFAULT_LEVELS):
    """The budget table of every component at the bins nearest to levels (y+)."""
    yp = ours["yplus"]
    ok = np.isfinite(yp)
    print("Reynolds-stress budgets (d<u_i'u_j'>/dt, gains positive) in wall units u_tau^4/nu of "
          "%s; ours +- 2 standard errors against %s; '*': |ours - DNS| > 2 stderr" %
          (ours["u_tau_label"], dns["source"]))
    if ours["n_windows"] < 2:
        print("warning: %d averaging windows: no standard errors (at least 2 needed)" %
              ours["n_windows"])
    if abs(ours["re_tau"] / dns["re_tau"] - 1) > 0.2:
        print("warning: the run's Re_tau = %.1f differs from the DNS's %.1f by more than 20%%: "
              "the budgets in wall units are not expected to agree" %
              (ours["re_tau"], dns["re_tau"]))
    bins = [int(np.flatnonzero(ok)[np.argmin(np.abs(yp[ok] - lev))]) for lev in levels]
    for c in COMPONENTS:
        print("rs budget %s:" % c)
        print("  %6s %8s  %-13s %10s %10s %10s %10s  %s" %
              ("y+", "bin y+", "term", "ours", "+-2se", "DNS", "ours-DNS", "DNS terms"))
        for lev, i in zip(levels, bins):
            for row in ROWS:
                got = row_values(ours, dns, c, row)
                if got is None:
                    continue
                v, s, r = (float(x[i]) for x in got)
                diff = v - r
                mark = "*" if math.isfinite(diff) and math.isfinite(s) and \
                    abs(diff) > 2 * s else " "
                names = "-" if row[2] is None else ("0 (steady)" if not row[2]
                                                    else "+".join(row[2]))
                print("  %6g %8.2f  %-13s %s %s %s %s %s %s" %
                      (lev, yp[i], row[0], fmt(v), fmt(2 * s), fmt(r), fmt(diff), mark, names))
        dev, peak = closure_check(ours, c)
        print("  closure = sum(pressure .. transfer) - rate: max difference %.3g u_tau^4/nu "
              "(%.2g of the largest term)" % (dev, dev / peak if peak > 0 else math.nan))


def print_markdown(ours, dns, levels=DEFAULT_LEVELS):
    """One Markdown table per component: each mapped row at the levels as ours +- 2 standard
    errors (DNS in brackets), for a document."""
    yp = ours["yplus"]
    ok = np.isfinite(yp)
    bins = [int(np.flatnonzero(ok)[np.argmin(np.abs(yp[ok] - lev))]) for lev in levels]
    print("Wall units u_tau^4/nu of %s; ours +- 2 standard errors [MKM 180]." %
          ours["u_tau_label"])
    for c in COMPONENTS:
        print("\n%s | " % c + " | ".join("y+ %.1f" % yp[i] for i in bins) + " |")
        print("|---|" + "---|" * len(bins))
        for row in ROWS:
            got = row_values(ours, dns, c, row)
            if got is None:
                continue
            cells = []
            for i in bins:
                v, s, r = (float(x[i]) for x in got)
                cell = "%.4f" % v + (" +- %.4f" % (2 * s) if math.isfinite(s) else "")
                cells.append(cell + (" [%.4f]" % r if math.isfinite(r) else ""))
            print("| %s | %s |" % (row[0], " | ".join(cells)))


def write_csv(ours, dns, path):
    """rs_budget.csv: component, term, y+, ours, stderr, dns for every bin and mapped row."""
    with open(path, "w") as f:
        f.write("# ours: %s\n# DNS: %s\n# wall units u_tau^4/nu; dns nan: no counterpart or "
                "beyond the DNS range\ncomponent,term,y+,ours,stderr,dns\n" %
                (ours["source"], dns["source"]))
        for c in COMPONENTS:
            for row in ROWS:
                got = row_values(ours, dns, c, row)
                if got is None:
                    continue
                for i, yp in enumerate(ours["yplus"]):
                    f.write("%s,%s,%.9g,%.9e,%.9e,%.9e\n" %
                            (c, row[0], yp, got[0][i], got[1][i], got[2][i]))


def plots(ours, dns, out_dir):
    """rs_budget_<c>.png: ours (lines, 2-stderr bands) and MKM (dashed) for y+ 0..100."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    yp = ours["yplus"]
    xmax = min(100.0, float(np.nanmax(yp)))
    names = []
    for c in COMPONENTS:
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for k, row in enumerate(r for r in ROWS if r[0] in (PLOTTED_VV if c == "vv" else PLOTTED)):
            got = row_values(ours, dns, c, row)
            if got is None:
                continue
            v, s, r = got
            col = "C%d" % k
            ax.plot(yp, v, "-", color=col, lw=1.3, label=row[0])
            if np.isfinite(s).any():
                ax.fill_between(yp, v - 2 * s, v + 2 * s, color=col, alpha=0.25, lw=0)
            if row[2]:
                d = dns[c]
                ax.plot(d["y+"], sum(d[n] for n in row[2]), "--", color=col, lw=1.0,
                        label="MKM " + "+".join(row[2]))
        for name, style in (("viscous", ":"), ("wall", "-.")):
            v = ours["terms"][c][name][0]
            ax.plot(yp, v, style, color="0.4", lw=0.9, label="%s (ours)" % name)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_xlim(0, xmax)
        ax.set_xlabel("y+")
        ax.set_ylabel("budget of <%s> [u_tau^4/nu]" % ("u_i'u_i'/2" if c == "k" else
                                                      "%s'%s'" % tuple(c)))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6.5, ncol=2)
        title = "%s: Re_tau = %.1f, %d windows; bands: 2 stderr\nwall units of %s" % (
            ours["run"], ours["re_tau"], ours["n_windows"], ours["u_tau_label"])
        ax.set_title(title, fontsize=7)
        fig.tight_layout()
        name = os.path.join(out_dir, "rs_budget_%s.png" % c)
        fig.savefig(name, dpi=110, metadata={"Title": title.replace("\n", " ")})
        plt.close(fig)
        names.append(name)
    return names


def report(ours, dns, levels, out_dir=None, with_plots=True):
    """print_tables, and with out_dir rs_budget.csv and (with_plots) the PNGs; the shared part
    of `rs_budget` and `chansph compare`."""
    print_tables(ours, dns, levels)
    if out_dir:
        write_csv(ours, dns, os.path.join(out_dir, "rs_budget.csv"))
        if with_plots:
            plots(ours, dns, out_dir)
        print("wrote %s/rs_budget.csv%s" % (out_dir, " and rs_budget_{%s}.png" %
                                            ",".join(COMPONENTS) if with_plots else ""))


def main(argv, prog="chansph-stats rs_budget"):
    ap = cli.parser(prog, __doc__, raw=True)
    ap.add_argument("stats", help="stats.nc of a run with Reynolds-stress budgets (rsb_*)")
    ap.add_argument("--dns-dir", default=DEFAULT_DNS,
                    help="directory of the MKM chanNNN.<c>bal files (default: the shipped "
                         "stats/dns/mkm1999/balances)")
    ap.add_argument("--u-tau", default="wall", metavar="wall|force|VALUE",
                    help="u_tau of the wall units: wall (default), force or a value [m/s]")
    ap.add_argument("--y-plus", default="10,15,30,50",
                    help="y+ levels of the table (default 10,15,30,50; the nearest bin)")
    ap.add_argument("--out", help="write rs_budget.csv and rs_budget_<c>.png to this directory")
    ap.add_argument("--markdown", action="store_true",
                    help="print the tables as Markdown (ours +- 2 stderr [DNS]) instead")
    a = ap.parse_args(argv)
    levels = levels_arg(a.y_plus)
    dns = read_dns(a.dns_dir)
    ours = read_budgets(a.stats, a.u_tau)
    if ours is None:
        raise InputError("%s: no Reynolds-stress budget variables (rsb_uu_pressure, ...): a "
                         "stats.nc of a chansph version without the budgets?" % a.stats)
    if a.out:
        try:
            os.makedirs(a.out, exist_ok=True)
        except OSError as e:
            raise InputError("%s: cannot create the output directory (%s)" % (a.out, e.strerror))
    print("ours: %s, Re_tau = %.2f" % (ours["source"], ours["re_tau"]))
    print("DNS:  %s" % dns["source"])
    if a.markdown:
        print_markdown(ours, dns, levels)
        return 0
    report(ours, dns, levels, a.out)
    return 0
