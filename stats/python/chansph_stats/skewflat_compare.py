"""Skewness and flatness profiles of u, v, w of a run against MKM Re_tau = 180.

usage: chansph-stats skewflat_compare STATS.nc [--plot FILE.png] [--dns FILE] [--u-tau ...]

The run's profiles are the root variables u_skewness ... w_flatness (M3 / M2^1.5, M4 / M2^2 of
the bins) against y_mean in wall units of --u-tau (force: u_tau_force, default; wall:
u_tau_wall; or a value); their standard errors are batch means over the complete windows of
group eulerian (each window's own skewness and flatness from its moment record; standard
deviation / sqrt(windows)). MKM: chan180.skew and chan180.flat (columns y, y+, S or F of u, v,
w, p; default stats/dns/mkm1999/profiles/chan180.skew, the flatness file found beside it),
interpolated linearly in y+ (clamped at the centre, y+ 178.12).

Printed: the run's value +- standard error and MKM's at y+ = 5, 10, 30, 100 (--at), each with
a verdict "agrees" when within two standard errors or --tol (0.1 for skewness, 3 times that
for flatness) of MKM, else "differs" with the difference; the RMS differences over
y+ < 30 and y+ >= 30. Engine check: the root profiles equal the merge of the window moment
records (Chan-Golub-LeVeque / Pebay pairwise formulas) to 1e-8 relative: PASS or FAIL
(exit status 1). The run's bins are those of the file (folded: the lower half).
"""
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .ncfile import attribute, need, need_group, open_nc, values
from .twopoint import DNS_ROOT, dns_table, pyplot, save, u_tau_arg, pick_u_tau

COMP = ("u", "v", "w")
DEFAULT_DNS = os.path.join(DNS_ROOT, "profiles", "chan180.skew")


def read_run(path, how):
    with open_nc(path) as nc:
        r = {name: values(need(nc, name, path)) for name in
             ["y_mean", "n_samples"] + ["%s_%s" % (c, q) for c in COMP
                                        for q in ("skewness", "flatness")]}
        g = need_group(nc, "eulerian", path)
        labels = [str(x) for x in values(need(g, "moment", path))]
        mom = values(need(g, "moments", path))
        done = values(need(g, "window_complete", path))
        r["nu"] = float(attribute(nc, "nu", path))
        r["u_tau"] = pick_u_tau(nc, path, how)
    want = ["count"] + ["mean_" + c for c in COMP] + ["C2_" + c + c for c in COMP] + \
        ["M3_" + c for c in COMP] + ["M4_" + c for c in COMP]
    for w in want:
        if w not in labels:
            raise InputError("%s: group eulerian: no moment '%s' in variable moments" % (path, w))
    r["mom"] = {w: mom[:, :, labels.index(w)] for w in want}
    r["complete"] = np.asarray(done) == 1
    if mom.shape[0] == 0 or not np.any(r["n_samples"] > 0):
        raise InputError("%s: no averaging window with samples" % path)
    r["y+"] = r["y_mean"] * r["u_tau"] / r["nu"]
    return r


def merge(a, b):
    """Pairwise merge of moment records (n, mean, M2, M3, M4), arrays over bins."""
    na, ma, m2a, m3a, m4a = a
    nb, mb, m2b, m3b, m4b = b
    n = na + nb
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.where(n > 0, mb - ma, 0.0)
        f = np.where(n > 0, 1.0 / np.where(n > 0, n, 1), 0.0)
        mean = ma + d * nb * f
        m2 = m2a + m2b + d ** 2 * na * nb * f
        m3 = m3a + m3b + d ** 3 * na * nb * (na - nb) * f ** 2 + 3 * d * (na * m2b - nb * m2a) * f
        m4 = (m4a + m4b + d ** 4 * na * nb * (na ** 2 - na * nb + nb ** 2) * f ** 3 +
              6 * d ** 2 * (na ** 2 * m2b + nb ** 2 * m2a) * f ** 2 +
              4 * d * (na * m3b - nb * m3a) * f)
    return n, mean, m2, m3, m4


def record(r, w, c):
    m = r["mom"]
    return (m["count"][w], m["mean_" + c][w], m["C2_" + c + c][w], m["M3_" + c][w],
            m["M4_" + c][w])


def shape(rec):
    n, _, m2, m3, m4 = rec
    with np.errstate(invalid="ignore", divide="ignore"):
        return (m3 / n) / (m2 / n) ** 1.5, (m4 / n) / (m2 / n) ** 2


def batches(r):
    """Per component: merged skewness and flatness of all windows, and the batch standard
    errors over the complete windows."""
    out = {}
    nw = r["mom"]["count"].shape[0]
    for c in COMP:
        tot = record(r, 0, c)
        for w in range(1, nw):
            tot = merge(tot, record(r, w, c))
        per = [shape(record(r, w, c)) for w in range(nw) if r["complete"][w]]
        k = len(per)
        se = [np.std([p[q] for p in per], axis=0, ddof=1) / math.sqrt(k) if k >= 2
              else np.full(len(r["y_mean"]), math.nan) for q in range(2)]
        out[c] = (shape(tot), se, k)
    return out


def dns(path):
    flat = os.path.join(os.path.dirname(path), os.path.basename(path).replace(".skew", ".flat"))
    if flat == path or not os.path.isfile(flat):
        raise InputError("%s: the flatness file %s beside it is missing" % (path, flat))
    s = dns_table(path, 6, "an MKM chanNNN.skew file")
    f = dns_table(flat, 6, "an MKM chanNNN.flat file")
    return s[:, 1], s[:, 2:5], f[:, 1], f[:, 2:5]


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("stats", help="stats.nc of a run")
    ap.add_argument("--dns", default=DEFAULT_DNS, help="the MKM chanNNN.skew file (the .flat beside it)")
    ap.add_argument("--plot", help="write the profiles against MKM to this PNG")
    ap.add_argument("--u-tau", type=u_tau_arg, default="force",
                    help="u_tau of the wall units: force (default), wall or a value [m/s]")
    ap.add_argument("--at", default="5,10,30,100", help="y+ of the table (default 5,10,30,100)")
    ap.add_argument("--tol", type=cli.number(float, 0, above=True), default=0.1,
                    help="skewness tolerance (flatness: 3 times it), default 0.1")
    a = ap.parse_args(argv)
    try:
        at = [float(x) for x in a.at.split(",")]
    except ValueError:
        raise InputError("--at %s: expected y+ values separated by commas" % a.at)
    ys, S, yf, F = dns(a.dns)
    r = read_run(a.stats, a.u_tau)
    b = batches(r)
    yp, ok = r["y+"], np.isfinite(r["y+"]) & (r["n_samples"] > 0)
    if ok.any():
        lo, hi = float(yp[ok].min()), float(yp[ok].max())
        out = [y for y in at if not 0 < y <= hi]
        if out:
            raise InputError("--at %s: y+ %s outside the channel of the run (0 < y+ <= %.4g, "
                             "its bins' centres y+ %.3g .. %.3g in %s): give y+ within it"
                             % (a.at, ", ".join("%g" % y for y in out), hi, lo, hi, a.stats))
    failed = False
    print("# %s: %d complete windows (batches of the standard errors); wall units of u_tau = "
          "%.5g m/s; run value +- standard error (MKM)" % (a.stats, b["u"][2], r["u_tau"]))
    for c in COMP:
        for q, name in enumerate(("skewness", "flatness")):
            mine = r["%s_%s" % (c, name)]
            dev = np.nanmax(np.abs(b[c][0][q] - mine)[ok] / np.maximum(np.abs(mine[ok]), 1e-300))
            good = dev <= 1e-8
            failed |= not good
            print("engine %s_%s = merge of the window records: max relative difference %.2e: %s"
                  % (c, name, dev, "PASS" if good else "FAIL"))
    print("# %6s %4s %22s %22s" % ("y+", "comp", "skewness", "flatness"))
    rows = []
    for y in at:
        for ci, c in enumerate(COMP):
            cells, verdicts = [], []
            for q, name in enumerate(("skewness", "flatness")):
                v = float(np.interp(y, yp[ok], r["%s_%s" % (c, name)][ok]))
                e = float(np.interp(y, yp[ok], b[c][1][q][ok]))
                ref = float(np.interp(y, ys, S[:, ci]) if q == 0 else np.interp(y, yf, F[:, ci]))
                tol = max(2 * e if e == e else 0.0, a.tol * (3 if q else 1))
                cells.append("%6.3f+-%5s (%6.3f)" % (v, "%.3f" % e if e == e else "-", ref))
                verdicts.append("%s %s" % (name, "agrees" if abs(v - ref) <= tol else
                                           "differs by %+.2f" % (v - ref)))
            rows.append((y, c))
            print("  %6g %4s %s  %s" % (y, c, " ".join(cells), ", ".join(verdicts)))
    for lo, hi, label in ((0, 30, "y+ < 30"), (30, 1e9, "y+ >= 30")):
        sel = ok & (yp >= lo) & (yp < hi)
        if not sel.any():
            continue
        parts = []
        for ci, c in enumerate(COMP):
            ds = r[c + "_skewness"][sel] - np.interp(yp[sel], ys, S[:, ci])
            df = r[c + "_flatness"][sel] - np.interp(yp[sel], yf, F[:, ci])
            parts.append("%s: S %.3f F %.3f" % (c, math.sqrt(np.mean(ds ** 2)),
                                                 math.sqrt(np.mean(df ** 2))))
        print("# RMS difference from MKM over %s (%d bins): %s" % (label, sel.sum(), "; ".join(parts)))
    if a.plot:
        plt = pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
        for ci, c in enumerate(COMP):
            col = "C%d" % ci
            for q, (ax, name, yd, D) in enumerate(((axes[0], "skewness", ys, S),
                                                   (axes[1], "flatness", yf, F))):
                ax.errorbar(yp[ok], r["%s_%s" % (c, name)][ok], yerr=np.nan_to_num(2 * b[c][1][q][ok]), fmt="o",
                            ms=2.5, lw=0.7, color=col, label="%s chansph" % c)
                ax.plot(yd, D[:, ci], "-", color=col, lw=1, label="%s MKM" % c)
        axes[0].set_ylabel("skewness")
        axes[1].set_ylabel("flatness")
        axes[1].set_yscale("log")
        for ax in axes:
            ax.set_xscale("log")
            ax.set_xlabel("y+")
            ax.set_xlim(1, 200)
            ax.legend(fontsize=6, ncol=2)
        fig.tight_layout()
        save(fig, a.plot)
    print("engine skewness/flatness consistency: %s" % ("FAIL" if failed else "PASS"))
    return 1 if failed else 0
