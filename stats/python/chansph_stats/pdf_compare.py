"""One-point PDFs of u', v', w' of a run (group pdfs of stats.nc) against the MKM Re_tau = 180 PDFs.

usage: chansph-stats pdf_compare STATS.nc [--dns DIR] [--plot FILE.png]

For each level of the group pdfs (scene key pdfs.y_plus) the MKM file of the nearest y+
(chan180.pdf.N in DIR, default stats/dns/mkm1999/pdfs; levels more than 10% + 1 wall unit from
every file are skipped) is read: its columns are the fluctuation in wall units and the
probability of each of its 201 bins (the columns sum to 1: the density is p / bin width). The
DNS PDF is taken to units of its own rms about its own mean and averaged over the run's bins.
Printed per level and component: rms+ (the run's rms / u_tau_ref), skewness and flatness with
their standard errors against the DNS values computed from the DNS PDF, the L1 distance
sum |p - p_DNS| dx of the two PDFs (0: equal, 2: disjoint) and the share of bins within two
standard errors of the DNS. With --plot, one panel per level and component (log scale).
The run's values are those of the whole run as written; `chansph extract --pdfs --window
T0:T1` re-averages a range of windows.
"""
import glob
import math
import os
import re

import numpy as np

from . import cli
from .cli import InputError
from .dns import numeric_rows
from .ncfile import attribute, need, need_group, open_nc, values

COMP = ("u", "v", "w")
DEFAULT_DNS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "dns",
                           "mkm1999", "pdfs")


def read_run(path):
    """The group pdfs of a stats.nc: levels, bin edges, PDFs and moments in wall units."""
    with open_nc(path) as nc:
        g = need_group(nc, "pdfs", path)
        ut = float(attribute(g, "u_tau_ref", path))
        r = {name: values(need(g, name, path)) for name in
             ("y_plus", "pdf_bin_bounds", "pdf", "pdf_stderr", "rms", "rms_stderr", "skewness",
              "skewness_stderr", "flatness", "flatness_stderr", "samples")}
        r["n_windows"] = int(g.getncattr("n_windows")) if "n_windows" in g.ncattrs() else 0
    r["rms+"], r["rms+_stderr"] = r["rms"] / ut, r["rms_stderr"] / ut
    return r


def dns_levels(folder):
    """{y+: file} of the MKM PDF files chan180.pdf.N of folder (y+ from each file's header)."""
    out = {}
    for f in sorted(glob.glob(os.path.join(folder, "chan*.pdf.*"))):
        with open(f, encoding="utf-8") as h:
            m = re.search(r"y\+ =\s*([0-9.]+)", h.read())
        if m:
            out[float(m.group(1))] = f
    if not out:
        raise InputError("%s: no MKM PDF files chanNNN.pdf.N with a 'y+ =' header line" % folder)
    return out


def dns_pdf(path, comp, edges):
    """The DNS PDF of component comp (0..2) of one MKM file in units of its rms, averaged over
    the bins edges (in rms units), and its rms, skewness and flatness."""
    rows, _ = numeric_rows(path, 8, "an MKM chanNNN.pdf.N file")
    d = np.asarray(rows)
    x, q = d[:, 2 * comp], d[:, 2 * comp + 1]
    dx = x[1] - x[0]
    q = q / q.sum()  # probabilities of the bins (they sum to 1 up to rounding)
    m = (x * q).sum()
    sd = math.sqrt(((x - m) ** 2 * q).sum())
    mom = (sd, ((x - m) ** 3 * q).sum() / sd ** 3, ((x - m) ** 4 * q).sum() / sd ** 4)
    cdf_x = np.concatenate(([x[0] - dx / 2], x + dx / 2))
    cdf = np.concatenate(([0.0], np.cumsum(q)))
    at = np.interp(edges * sd + m, cdf_x, cdf)
    return np.diff(at) / np.diff(edges), mom


def compare(run, dns):
    """Rows (y+, y+ of the DNS, component, numbers) and the curves for the plot."""
    edges = np.concatenate((run["pdf_bin_bounds"][:, 0], run["pdf_bin_bounds"][-1:, 1]))
    rows, curves = [], []
    for lev, yp in enumerate(run["y_plus"]):
        near = min(dns, key=lambda k: abs(k - yp))
        if abs(near - yp) > 0.1 * yp + 1.0:
            print("# y+ %g: no MKM level near it (nearest %g): skipped" % (yp, near))
            continue
        for c in range(3):
            pd, mom = dns_pdf(dns[near], c, edges)
            p, pe = run["pdf"][lev, c], run["pdf_stderr"][lev, c]
            l1 = float(np.nansum(np.abs(p - pd) * np.diff(edges)))
            ok = np.isfinite(pe) & (pe > 0)
            within = float(np.mean(np.abs(p - pd)[ok] <= 2 * pe[ok])) if ok.any() else math.nan
            rows.append((yp, near, COMP[c],
                         [(run[q][lev, c], run[q + "_stderr"][lev, c], mom[k])
                          for k, q in enumerate(("rms+", "skewness", "flatness"))], l1, within))
            curves.append((yp, near, c, edges, p, pe, pd))
    return rows, curves


def plot(path, curves):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    levels = sorted({c[0] for c in curves})
    fig, axes = plt.subplots(len(levels), 3, figsize=(10, 2.2 * len(levels) + 0.6),
                             squeeze=False, sharex=True)
    for yp, near, c, edges, p, pe, pd in curves:
        ax = axes[levels.index(yp)][c]
        mid = 0.5 * (edges[1:] + edges[:-1])
        ax.errorbar(mid, p, yerr=2 * pe, fmt="o", ms=2.5, lw=0.8, label="chansph (2 s.e.)")
        ax.plot(mid, pd, "k-", lw=1, label="MKM y+ = %g" % near)
        ax.set_yscale("log")
        ax.set_ylim(1e-4, 1.0)
        ax.set_title("%s', y+ = %g" % (COMP[c], yp), fontsize=9)
        if c == 0:
            ax.set_ylabel("pdf")
        ax.legend(fontsize=6, loc="lower center")
    for ax in axes[-1]:
        ax.set_xlabel("fluctuation / local rms")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("stats", help="stats.nc of a run with pdfs.y_plus set")
    ap.add_argument("--dns", default=DEFAULT_DNS, help="folder of the MKM chan180.pdf.N files")
    ap.add_argument("--plot", help="write the PDFs against the DNS to this PNG")
    a = ap.parse_args(argv)
    dns = dns_levels(a.dns)
    run = read_run(a.stats)
    rows, curves = compare(run, dns)
    if not rows:
        raise InputError("%s: no level of group pdfs is near an MKM level" % a.stats)
    print("# %s: %d complete windows; run value +- standard error (MKM value)" %
          (a.stats, run["n_windows"]))
    print("# %6s %6s %4s %22s %22s %22s %6s %7s" % ("y+", "MKM y+", "comp", "rms+", "skewness",
                                                     "flatness", "L1", "in 2se"))
    for yp, near, comp, nums, l1, within in rows:
        cells = ["%6.3f+-%5.3f (%6.3f)" % n for n in nums]
        print("  %6g %6g %4s %s %6.3f %7.2f" % (yp, near, comp, " ".join(cells), l1, within))
    if a.plot:
        plot(a.plot, curves)
