#!/usr/bin/env python3
"""The correlation engine's gap correction on one trajectory sampled on two grids
(docs/validation/statistics.md, "Empty cells"): per level and component the spanwise spectrum's
energy R(0) (and over the Eulerian variance), in the resolved band k_z delta < 30 and above it,
for the fine grid (cell dr) gap-corrected and zero-filled (R P, P its pair_fraction_z: what the
engine wrote before checkpoint format 1.15), and the coarse grid (cell 2 dr) corrected; MKM's
energy in the same bands; and a figure of the v and w spectra at four levels.

usage: gap_spectra.py FINE_STATS.nc COARSE_STATS.nc OUT.png [OUT.csv]
"""
import os
import sys

import netCDF4
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "stats",
                                "python"))
from chansph_stats import twopoint as tp  # noqa: E402
from chansph_stats.twopoint_compare import wiener_khinchin  # noqa: E402

KC = 30.0  # k_z delta: lambda_z+ = 38 at Re_tau = 180


def load(path):
    r = tp.read_corr(path, "force")
    g = netCDF4.Dataset(path)["correlations"]
    r["P"] = np.ma.filled(g["pair_fraction_z"][:], np.nan)
    return r


def main():
    fine, coarse, png = load(sys.argv[1]), load(sys.argv[2]), sys.argv[3]
    csv = open(sys.argv[4], "w") if len(sys.argv) > 4 else None
    mkm = tp.dns_files(os.path.join(tp.DNS_ROOT, "spectra"), "zspec")
    head = "y_plus,component,estimate,R0,over_eulerian,band_low,band_high,mkm_low,mkm_high"
    print("# energies in u_tau^2 (force balance); bands k_z delta < %g and >= %g" % (KC, KC))
    print(head)
    if csv:
        csv.write(head + "\n")
    curves = {}
    for lev in range(len(fine["level"])):
        yp = tp.run_y_plus(fine, lev)
        t = tp.dns_table(mkm[tp.nearest(list(mkm), yp)], 5, "an MKM chan180.zspec.N file")
        kd = t[:, 0]
        dkd = kd[1] - kd[0]
        for ci, c in enumerate("uvw"):
            Ed = t[:, 1 + ci] / dkd
            for name, r, zero in (("fine", fine, False), ("fine_zero_filled", fine, True),
                                  ("coarse", coarse, False)):
                ut, de = r["u_tau"], r["delta"]
                R = r["R_%s%s_z" % (c, c)][lev] / ut ** 2 * (r["P"][lev] if zero else 1.0)
                k = r["kz"] * de
                dk = k[1] - k[0]
                E = wiener_khinchin(R, r["lz"] / de)
                lo, hi = E[(k > 0) & (k < KC)].sum() * dk, E[k >= KC].sum() * dk
                lod = Ed[(kd >= k[1] - 1e-9) & (kd < KC)].sum() * dkd
                row = "%.1f,%s,%s,%.4f,%.3f,%.4f,%.4f,%.4f,%.4f" % (
                    yp, c, name, R[0], R[0] * ut ** 2 / tp.eulerian_variance(r, lev, c), lo, hi,
                    lod, Ed[kd >= KC].sum() * dkd)
                print(row)
                if csv:
                    csv.write(row + "\n")
                curves[(lev, c, name)] = (k, E)
            curves[(lev, c, "MKM")] = (kd, Ed)
    plt = tp.pyplot()
    levels = [i for i, y in enumerate(fine["y_plus"]) if round(float(y)) in (10, 30, 59, 98)]
    fig, axes = plt.subplots(len(levels), 2, figsize=(7, 2.1 * len(levels)), squeeze=False)
    style = {"fine_zero_filled": ("r.", "cell dr, zero-filled (before 1.15)"),
             "fine": ("bo", "cell dr, gap-corrected"),
             "coarse": ("g^", "cell 2 dr, gap-corrected"), "MKM": ("k-", "MKM 1999")}
    for row, lev in enumerate(levels):
        for col, c in enumerate("vw"):
            ax = axes[row][col]
            for name, (fmt, label) in style.items():
                k, E = curves[(lev, c, name)]
                keep = k > 0
                ax.loglog(k[keep], E[keep], fmt, ms=3, lw=1, label=label)
            ax.set_title("E_%s%s(k_z), y+ = %.0f" % (c, c, fine["y_plus"][lev]), fontsize=8)
            ax.tick_params(labelsize=7)
    axes[0][0].legend(fontsize=6)
    for ax in axes[-1]:
        ax.set_xlabel("k_z delta", fontsize=8)
    fig.tight_layout()
    tp.save(fig, png)


if __name__ == "__main__":
    main()
