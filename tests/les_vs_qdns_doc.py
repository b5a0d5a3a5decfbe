#!/usr/bin/python3
"""LES against quasi-DNS on les395_small.ini (docs/validation/les_vs_qdns.md).

Usage: tests/les_vs_qdns_doc.py LES_DIR QDNS_DIR DNS_MEANS DOCDIR
Reads the mean velocity of both runs (root variables y_mean, u_mean of stats.nc; the two halves
of the channel folded), u_tau from the force balance (u_tau^2 = f delta), and prints, for each:
the largest relative deviation of U+ from the log law 2.44 ln y+ + 5.2 over y+ in [50, 300], and
the relative L2 and Linf deviations from the DNS U+ (Moser, Kim & Mansour 1999, chan395.means)
over the sample points with y+ <= Re_tau. Writes DOCDIR/les_vs_qdns.png.
"""
import math
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import netCDF4
import numpy as np


def profile(run):
    with netCDF4.Dataset(run + "/stats.nc") as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        y, u = d["y_mean"][:].filled(np.nan), d["u_mean"][:].filled(np.nan)
    delta, nu, f = a["delta"], a["nu"], a["body_force"]
    utau = math.sqrt(f * delta)
    yw = np.minimum(y, 2 * delta - y)
    order = np.argsort(yw)
    yw, u = yw[order], u[order]
    # fold: average the two bins at the same wall distance
    keys = np.round(yw / np.max(np.diff(yw)))  # the bins of the two halves pair up
    yf, uf = [], []
    for k in np.unique(keys):
        m = keys == k
        yf.append(yw[m].mean()), uf.append(u[m].mean())
    yf, uf = np.array(yf), np.array(uf)
    return yf * utau / nu, uf / utau, a


def dns(path):
    t = np.loadtxt(path, comments="#")
    return t[:, 1], t[:, 2]


def main():
    les, qdns, dnsfile, doc = sys.argv[1:5]
    yd, ud = dns(dnsfile)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.semilogx(yd[1:], ud[1:], "k-", lw=1.5, label="DNS Re_tau = 392 (Moser, Kim & Mansour 1999)")
    yl = np.logspace(np.log10(20), np.log10(400), 50)
    ax.semilogx(yl, 2.44 * np.log(yl) + 5.2, "k--", lw=1, label="log law 2.44 ln y+ + 5.2")
    for run, label, st in ((les, "LES (Smagorinsky)", "o-"), (qdns, "no model", "s-")):
        yp, up, a = profile(run)
        log = (yp >= 50) & (yp <= 300)
        dev = np.abs(up[log] - (2.44 * np.log(yp[log]) + 5.2)) / (2.44 * np.log(yp[log]) + 5.2)
        inside = yp <= yd.max()
        ui = np.interp(yp[inside], yd, ud)
        l2 = math.sqrt(np.sum((up[inside] - ui) ** 2) / np.sum(ui ** 2))
        linf = np.max(np.abs(up[inside] - ui)) / np.max(ui)
        print("%s: %d points in y+ [50, 300]; largest deviation from the log law %.1f%% "
              "(at y+ = %.0f); against the DNS: relative L2 %.3f, Linf %.3f; U+ at the "
              "centre %.2f (DNS %.2f)" % (label, log.sum(), 100 * dev.max(),
                                          yp[log][np.argmax(dev)], l2, linf, up[-1], ud[-1]))
        for y, u in zip(yp, up):
            print("  y+ %7.1f  U+ %6.2f  log %6.2f  DNS %6.2f" % (y, u, 2.44 * math.log(y) + 5.2,
                                                               np.interp(y, yd, ud)))
        ax.semilogx(yp, up, st, ms=4, label=label)
    ax.axvspan(50, 300, color="gray", alpha=0.1)
    ax.set_xlabel("y+")
    ax.set_ylabel("U+")
    ax.set_xlim(1, 500)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("les395_small: pi x 2 x pi/2, dr = delta/16 (Delta+ = 24.7)")
    fig.tight_layout()
    fig.savefig(doc + "/les_vs_qdns.png", dpi=110)


if __name__ == "__main__":
    main()
