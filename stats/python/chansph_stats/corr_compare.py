"""Two-point correlations of u, v, w in x and z of a run (group correlations) against MKM 180.

usage: chansph-stats corr_compare STATS.nc [--out DIR] [--dns DIR] [--u-tau force|wall|V]

The engine writes R_ii(l) = <u_i'(r) u_i'(r + l e)> [m^2/s^2] at the separations l = i L / n
of its periodic grid (docs/stats-format.md); the MKM files (chan180.xcorr.N, chan180.zcorr.N in
DIR, default stats/dns/mkm1999/correlations) give dx, dx+ and R_uu, R_vv, R_ww, R_pp in u_tau^2
to half their box (2 pi and 2 pi / 3 delta). Both are compared as coefficients
rho_ii = R_ii(l) / R_ii(0) against l / delta, to half our box (lx / 2, lz / 2): a periodic
correlation is symmetric about the half box, and our box (lx = 2, lz = 0.7 delta in the minimal
unit) is much smaller than MKM's.

Printed per level (nearest MKM y+; more than 10% + 1 wall unit from every file: skipped),
direction and component: R_ii(0)+ (the variance in wall units) and MKM's; the separation
where rho first drops below 0.5 (">" when it does not within half the box); the minimum of rho
over half the box and where; rho at half the box; the RMS difference of rho from MKM over
half the box; verdict "agrees" when that difference is below --tol (default 0.1), else
"differs". Engine check: R_ii(l) symmetric about the half box (R(l) = R(L - l)) to 1e-9
relative, and |rho| <= 1: PASS or FAIL (exit status 1).
With --out, corr_x.png and corr_z.png (one row per level).
"""
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .twopoint import (COMP, DNS_ROOT, dns_files, dns_table, header, nearest, out_dir, pyplot,
                       read_corr, run_y_plus, save, u_tau_arg)

DEFAULT_DNS = os.path.join(DNS_ROOT, "correlations")


def half_width(l, rho, level=0.5):
    """First separation where rho falls below level (linear interpolation), or NaN."""
    below = np.nonzero(rho < level)[0]
    if len(below) == 0 or below[0] == 0:
        return math.nan
    i = below[0]
    return l[i - 1] + (rho[i - 1] - level) / (rho[i - 1] - rho[i]) * (l[i] - l[i - 1])


def run_curve(r, lev, c, d):
    """Separations / delta and rho to half the box, R(0) in wall units, the engine check."""
    R = r["R_%s%s_%s" % (c, c, d)][lev]
    n = len(R)
    L = (r["lx"] if d == "x" else r["lz"]) / r["delta"]
    l = np.arange(n) * L / n
    ok = bool(np.all(np.isfinite(R)) and R[0] > 0)
    sym = np.max(np.abs(R[1:] - R[1:][::-1])) / R[0] if ok else math.nan
    rho = R / R[0] if ok else R * math.nan
    ok = ok and sym <= 1e-9 and np.all(np.abs(rho) <= 1 + 1e-12)
    half = n // 2 + 1
    return l[:half], rho[:half], R[0] / r["u_tau"] ** 2, ok, sym


def dns_curve(path, c):
    t = dns_table(path, 6, "an MKM chanNNN.[xz]corr.N file")
    R = t[:, 2 + COMP.index(c)]
    return t[:, 0], R / R[0], R[0]


def numbers(l, rho):
    i = int(np.argmin(rho))
    return half_width(l, rho), rho[i], l[i], rho[-1]


def plot(path, d, curves, levels):
    plt = pyplot()
    fig, axes = plt.subplots(len(levels), 3, figsize=(9, 1.8 * len(levels) + 0.5),
                             squeeze=False, sharex=True)
    for (yp, near, c), (l, rho, ld, rd) in curves.items():
        ax = axes[levels.index((yp, near))][COMP.index(c)]
        ax.plot(l, rho, "o-", ms=2.5, lw=0.8, label="chansph")
        keep = ld <= l[-1] * 1.5
        ax.plot(ld[keep], rd[keep], "k-", lw=1, label="MKM y+ %g" % near)
        ax.axhline(0, color="0.7", lw=0.5)
        ax.set_title("rho_%s%s(%s), y+ = %.0f" % (c, c, d, yp), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6)
    for ax in axes[-1]:
        ax.set_xlabel("%s separation / delta" % d, fontsize=8)
    fig.tight_layout()
    save(fig, path)


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("stats", help="stats.nc of a run with correlations.y_plus set")
    ap.add_argument("--out", help="write corr_x.png and corr_z.png into this directory")
    ap.add_argument("--dns", default=DEFAULT_DNS,
                    help="folder of the MKM chan180.[xz]corr.N files")
    ap.add_argument("--u-tau", type=u_tau_arg, default="force",
                    help="u_tau of the wall units: force (default), wall or a value [m/s]")
    ap.add_argument("--tol", type=cli.number(float, 0, above=True), default=0.1,
                    help="RMS difference of rho below this agrees (default 0.1)")
    a = ap.parse_args(argv)
    dns = {d: dns_files(a.dns, d + "corr") for d in "xz"}
    r = read_corr(a.stats, a.u_tau)
    if a.out:
        out_dir(a.out)
    header(r, a.stats)
    print("# %5s %6s %3s %4s %8s %8s %12s %12s %16s %16s %7s %7s %6s  %s" %
          ("y+", "MKM y+", "dir", "comp", "R(0)+", "MKM", "l(rho=0.5)", "MKM", "min rho at l",
           "MKM", "rho L/2", "MKM", "rms d", "verdict"))
    failed, levels, curves = False, {"x": [], "z": []}, {"x": {}, "z": {}}
    for lev in range(len(r["y_plus"])):
        if not r["samples"][lev] > 0:
            print("# level %d (y+ %g): no samples: skipped" % (lev, r["y_plus"][lev]))
            continue
        yp = run_y_plus(r, lev)
        for d in "xz":
            near = nearest(dns[d], yp)
            for c in COMP:
                l, rho, r0, ok, sym = run_curve(r, lev, c, d)
                failed |= not ok
                if near is None:
                    print("  %5.1f      - %3s %4s (no MKM level near: not compared) engine %s" %
                          (yp, d, c, "PASS" if ok else "FAIL (symmetry %.2e)" % sym))
                    continue
                ld, rd, r0d = dns_curve(dns[d][near], c)
                inside = ld <= l[-1] + 1e-9
                rdi = np.interp(l, ld, rd)
                diff = math.sqrt(np.mean((rho - rdi) ** 2))
                hw, mn, lmn, end = numbers(l, rho)
                hwd, mnd, lmnd, _ = numbers(ld[inside], rd[inside])
                endd = float(np.interp(l[-1], ld, rd))
                print("  %5.1f %6g %3s %4s %8.4f %8.4f %12s %12s %7.3f at %5.3f %7.3f at %5.3f "
                      "%7.3f %7.3f %6.3f  engine %s, DNS %s" %
                      (yp, near, d, c, r0, r0d, "%.3f" % hw if hw == hw else "> %.3g" % l[-1],
                       "%.3f" % hwd if hwd == hwd else "> %.3g" % l[-1], mn, lmn, mnd, lmnd,
                       end, endd, diff, "PASS" if ok else "FAIL (symmetry %.2e)" % sym,
                       "agrees" if diff <= a.tol else "differs"))
                curves[d][(yp, near, c)] = (l, rho, ld, rd)
                if (yp, near) not in levels[d]:
                    levels[d].append((yp, near))
    print("# separations in delta; l(rho=0.5): first drop below 0.5; rho L/2: at half our box "
          "(MKM interpolated there); rms d: RMS of rho - rho_MKM over half our box")
    if not any(levels.values()):
        raise InputError("%s: no level of group correlations is near an MKM level" % a.stats)
    if a.out:
        for d in "xz":
            if levels[d]:
                plot(os.path.join(a.out, "corr_%s.png" % d), d, curves[d], levels[d])
    print("engine correlation consistency (R(l) = R(L - l), |rho| <= 1): %s" %
          ("FAIL" if failed else "PASS"))
    return 1 if failed else 0
