#!/usr/bin/python3
"""Where the near-wall cycle sits against the particle spacing (docs/validation/scheme_ab.md, "The
near-wall cycle follows the particle spacing"): for each stats.nc of a resolution series (the
same scheme and box at several dr+), the y+ of the u_rms+, v_rms+, w_rms+ and -u'v'+ peaks (the
parabola through the largest bin and its neighbours, as `chansph compare` and ab_score find them;
for v and w the outer peak above y+ = 30; force units), with the standard error of the positions of blocks of windows of at least 0.5
delta/u_tau; the weighted straight line y+_peak = a + b dr+ through them, the same in units of
dr, and the dr+ at which the line reaches the same-box DNS's position; the peak values against the
DNS's and the dr+ at which a straight line through their deviations reaches -10% and 0. Prints
the tables, writes a CSV and a figure.

usage: cycle_vs_dr.py OUT.png OUT.csv STATS.nc DR_PLUS [STATS.nc DR_PLUS ...]
"""
import csv
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "stats",
                                "python"))
from chansph_stats.ab_score import SAMEBOX  # noqa: E402
from chansph_stats.dns import read_dns  # noqa: E402
from chansph_stats.merge import merged_profile, peak_position  # noqa: E402
from chansph_stats.ncfile import read_windows  # noqa: E402

QUANTITIES = ("u_rms+", "v_rms+", "w_rms+", "-u'v'+")
# v and w: the outer peak, above y+ = 30 (at dr+ = 9 the particle noise makes a near-wall
# maximum of v_rms+ at y+ = 10-20 in some blocks); the DNS's lie at 62 and 54
LOWEST = {"u_rms+": 0.0, "v_rms+": 30.0, "w_rms+": 30.0, "-u'v'+": 0.0}


def outer(p, q):
    """Profile q of p with the bins below LOWEST[q] masked."""
    return np.where(np.asarray(p["yplus"]) >= LOWEST[q], p[q], np.nan)
BLOCK = 0.5  # delta / u_tau: the blocks whose scatter gives the standard error


def blocks(r):
    """The completed windows of a read_windows record, in consecutive blocks of at least BLOCK."""
    out, cur, t0 = [], [], None
    for i in np.flatnonzero(r["done"]):
        if not cur:
            t0 = r["win"][i, 0]
        cur.append(int(i))
        if r["win"][i, 1] - t0 >= BLOCK - 1e-9:
            out.append(cur)
            cur = []
    return out


def positions(path):
    """{quantity: (y+ of the peak over every completed window, its standard error)} and the
    number of blocks."""
    r = read_windows(path)
    sel = [int(i) for i in np.flatnonzero(r["done"])]
    prof = merged_profile(r, sel)
    bl = blocks(r)
    each = [merged_profile(r, b) for b in bl]
    out, amp = {}, {}
    for q in QUANTITIES:
        per = np.array([peak_position(p["yplus"], outer(p, q)) for p in each])
        out[q] = (peak_position(prof["yplus"], outer(prof, q)),
                  float(np.std(per, ddof=1) / math.sqrt(len(per))))
        per = np.array([np.nanmax(outer(p, q)) for p in each])
        amp[q] = (float(np.nanmax(outer(prof, q))),
                  float(np.std(per, ddof=1) / math.sqrt(len(per))))
    return out, amp, len(bl)


def fit(x, y, se):
    """Weighted straight line y = a + b x; (a, b) and their standard errors."""
    w = 1.0 / np.asarray(se) ** 2
    A = np.vstack([np.ones_like(x), x]).T
    cov = np.linalg.inv(A.T @ (A * w[:, None]))
    a, b = cov @ (A.T @ (w * y))
    return (a, b), np.sqrt(np.diag(cov))


def main(argv):
    if len(argv) < 5 or len(argv) % 2 == 0:
        sys.exit(__doc__)
    png, out_csv = argv[1], argv[2]
    runs = [(argv[i], float(argv[i + 1])) for i in range(3, len(argv), 2)]
    dns = read_dns(SAMEBOX)
    ref = {q: peak_position(dns["yplus"], outer(dns, q)) for q in QUANTITIES}
    rows = []
    peak = {q: float(np.nanmax(outer(dns, q))) for q in QUANTITIES}
    amps = []
    for path, drp in runs:
        pos, amp, nb = positions(path)
        rows.append((path, drp, nb, pos))
        amps.append(amp)
    dr = np.array([r[1] for r in rows])
    print("peak positions in y+ (force units; +- the standard error of blocks of >= %.1f "
          "delta/u_tau), and in units of dr; same-box DNS: %s" % (
              BLOCK, ", ".join(f"{q} {ref[q]:.1f}" for q in QUANTITIES)))
    print("| stats.nc | dr+ | blocks | " + " | ".join(f"{q} y+ (/dr)" for q in QUANTITIES) + " |")
    print("|---|---|---|" + "---|" * len(QUANTITIES))
    for path, drp, nb, pos in rows:
        print(f"| {os.path.basename(path)} | {drp:.2f} | {nb} | " + " | ".join(
            f"{pos[q][0]:.1f} +- {pos[q][1]:.1f} ({pos[q][0] / drp:.2f})" for q in QUANTITIES)
            + " |")
    lines = {}
    print("\nweighted straight line y+_peak = a + b dr+; the dr+ where it meets the DNS's position")
    for q in QUANTITIES:
        y = np.array([r[3][q][0] for r in rows])
        se = np.array([max(r[3][q][1], 0.5) for r in rows])  # at least half a wall unit
        (a, b), (sa, sb) = fit(dr, y, se)
        chi2 = float(np.sum(((y - a - b * dr) / se) ** 2))
        reach = (ref[q] - a) / b if b > 0 else math.nan
        lines[q] = (a, b, sa, sb, chi2, reach)
        print(f"  {q:7s} a = {a:6.1f} +- {sa:4.1f}, b = {b:5.2f} +- {sb:4.2f}, chi2 = {chi2:5.2f} "
              f"({len(dr) - 2} dof); DNS {ref[q]:.1f} at dr+ = {reach:.2f}")
    print("\npeak values against the same-box DNS's (force units; +- the blocks' standard error)")
    print("| stats.nc | dr+ | " + " | ".join(f"{q} peak (dev)" for q in QUANTITIES) + " |")
    print("|---|---|" + "---|" * len(QUANTITIES))
    for (path, drp, nb, pos), amp in zip(rows, amps):
        print(f"| {os.path.basename(path)} | {drp:.2f} | " + " | ".join(
            f"{amp[q][0]:.3f} +- {amp[q][1]:.3f} ({100 * (amp[q][0] / peak[q] - 1):+.0f}%)"
            for q in QUANTITIES) + " |")
    print("weighted straight line dev = c + d dr+; the dr+ where it reaches -10% and 0")
    devfit = {}
    for q in QUANTITIES:
        y = np.array([a[q][0] / peak[q] - 1.0 for a in amps])
        se = np.array([max(a[q][1] / peak[q], 0.005) for a in amps])
        (c, d), (sc, sd) = fit(dr, y, se)
        chi2 = float(np.sum(((y - c - d * dr) / se) ** 2))
        at = [(v - c) / d if d < 0 else math.nan for v in (-0.10, 0.0)]
        devfit[q] = (c, d)
        print(f"  {q:7s} c = {100 * c:+5.1f}% +- {100 * sc:3.1f}, d = {100 * d:+5.2f}% +- "
              f"{100 * sd:4.2f} per wall unit, chi2 = {chi2:5.2f} ({len(dr) - 2} dof); -10% at "
              f"dr+ = {at[0]:.2f}, 0 at {at[1]:.2f}")
    with open(out_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["stats", "dr_plus", "blocks"]
                   + [x for q in QUANTITIES for x in (q + " y+", q + " y+ se")]
                   + [x for q in QUANTITIES for x in (q + " peak", q + " peak se")])
        for (path, drp, nb, pos), amp in zip(rows, amps):
            w.writerow([os.path.basename(path), drp, nb] + [f"{v:.4g}" for q in QUANTITIES
                                                            for v in pos[q]]
                       + [f"{v:.4g}" for q in QUANTITIES for v in amp[q]])
        for q in QUANTITIES:
            a, b, sa, sb, chi2, reach = lines[q]
            w.writerow([f"fit {q}", "a=%.4g" % a, "b=%.4g" % b, "se_a=%.3g" % sa,
                        "se_b=%.3g" % sb, "chi2=%.3g" % chi2, "dns_at_dr_plus=%.3g" % reach])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.4))
    xs = np.linspace(0.0, dr.max() * 1.1, 50)
    for q, c in zip(QUANTITIES, ("C0", "C1", "C2", "C3")):
        y = [r[3][q][0] for r in rows]
        e = [r[3][q][1] for r in rows]
        ax.errorbar(dr, y, yerr=e, fmt="o", color=c, label=q, capsize=3)
        a, b = lines[q][:2]
        ax.plot(xs, a + b * xs, "-", color=c, lw=0.8)
        ax.axhline(ref[q], color=c, ls=":", lw=0.8)
        y = [100 * (a_[q][0] / peak[q] - 1.0) for a_ in amps]
        e = [100 * a_[q][1] / peak[q] for a_ in amps]
        bx.errorbar(dr, y, yerr=e, fmt="o", color=c, label=q, capsize=3)
        cc, dd = devfit[q]
        bx.plot(xs, 100 * (cc + dd * xs), "-", color=c, lw=0.8)
    bx.axhspan(-10, 10, color="0.9", zorder=0)
    bx.axhline(0, color="k", lw=0.6)
    bx.set_xlabel("dr+ (particle spacing in wall units)")
    bx.set_ylabel("peak against the same-box DNS's peak [%]")
    bx.set_xlim(0, xs[-1])
    bx.set_title("Peak values (grey: within 10%)", fontsize=10)
    bx.legend(fontsize=8)
    ax.set_xlabel("dr+ (particle spacing in wall units)")
    ax.set_ylabel("y+ of the peak")
    ax.set_xlim(0, xs[-1])
    ax.set_ylim(0, None)
    ax.set_title("Peak positions against dr+ (dotted: same-box DNS)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"wrote {png} and {out_csv}")


if __name__ == "__main__":
    main(sys.argv)
