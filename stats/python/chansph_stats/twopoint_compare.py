"""The group correlations of a run against MKM Re_tau = 180: two tools, one module.

`spectra_compare` (SPECTRA_DOC) checks and compares the 1-D spectra, `corr_compare`
(CORR_DOC) the two-point correlations. Both read the group with twopoint.read_corr, pick the
MKM level nearest each of the run's levels (skipping those more than 10% + 1 wall unit from
every file), print one row per level, direction and component with an engine check (PASS or
FAIL: exit status 1) and a DNS verdict, and with --out draw one figure per direction with one
row per level: the loop, the options and the figures are compare() below, each tool only its
numbers (class Spectra, class Correlations).
"""
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .twopoint import (COMP, DNS_ROOT, dns_files, dns_table, eulerian_variance, header,
                       nearest, out_dir, pyplot, read_corr, run_y_plus, save, u_tau_arg)

SPECTRA_DOC = """1-D spectra of u, v, w in x and z of a run (group correlations) against MKM Re_tau = 180.

usage: chansph-stats spectra_compare STATS.nc [--out DIR] [--dns DIR] [--u-tau force|wall|V]

Normalisation. The engine writes one-sided densities over k = 2 pi m / L with
sum_m E(k_m) dk = <u_i'^2> [m^3/s^2] (docs/stats-format.md). The MKM files (chan180.xspec.N,
chan180.zspec.N in DIR, default stats/dns/mkm1999/spectra) give k in units of 1/delta and,
per mode, the energy E_m in u_tau^2 with sum_m E_m = <u_i'^2>+ (checked: the sum over the 64
modes equals R_ii(0) of the correlation files to 4 digits): the energy of a mode of their box
(dk = 0.5 in x, Lx = 4 pi; 1.5 in z, Lz = 4 pi / 3), not a density. Both are compared as
densities in outer-wall units, E(k delta) / (u_tau^2 delta): ours E / (u_tau^2 delta), MKM
E_m / dk_MKM.

Checks printed per level (nearest MKM y+, levels more than 10% + 1 wall unit from every file
skipped), component and direction:
  engine: sum E dk = R_ii(0) (Parseval) and E = the cosine transform of R_ii(l)
          (Wiener-Khinchin), both to 1e-6 relative: PASS or FAIL (FAIL: exit status 1);
  DNS:    the energy ratio (sum E dk)/u_tau^2 / <u_i'^2>+_MKM, and the relative error
          sum |E - E_MKM| / sum E_MKM over the nonzero wavenumbers the box holds (MKM
          interpolated linearly in log E at our k, up to the last MKM k): "agrees" when the
          ratio is within --tol-energy of 1 and the error below --tol-shape, else "differs";
  the MKM wavenumbers 0 < k < 2 pi / L the box cannot hold and their share of the DNS energy.
With --out, spectra_x.png and spectra_z.png (one row per level, log-log).
"""

CORR_DOC = """Two-point correlations of u, v, w in x and z of a run (group correlations) against MKM 180.

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

EXACT = 1e-6


def wiener_khinchin(R, L):
    """One-sided density over k = 2 pi m / L (m = 0 .. n/2) of a periodic correlation R(l_i),
    l_i = i L / n: E_m = c_m (1/n) sum_i R_i cos(k_m l_i) / dk, c = 1 at m = 0 and n/2, else 2."""
    n = len(R)
    phi = np.fft.rfft(R).real / n
    c = np.full(len(phi), 2.0)
    c[0] = 1.0
    if n % 2 == 0:
        c[-1] = 1.0
    return c * phi / (2 * math.pi / L)


def half_width(l, rho, level=0.5):
    """First separation where rho falls below level (linear interpolation), or NaN."""
    below = np.nonzero(rho < level)[0]
    if len(below) == 0 or below[0] == 0:
        return math.nan
    i = below[0]
    return l[i - 1] + (rho[i - 1] - level) / (rho[i - 1] - rho[i]) * (l[i] - l[i - 1])


class Spectra:
    """spectra_compare: Parseval and Wiener-Khinchin, energy ratio and shape against MKM."""
    doc, dns_kind, png = SPECTRA_DOC, "spec", "spectra"
    dns_default = os.path.join(DNS_ROOT, "spectra")
    figure_height, sharex = 1.9, False

    def __init__(self, a):
        self.a, self.lost = a, {}

    @staticmethod
    def options(ap):
        ap.add_argument("--tol-energy", type=cli.number(float, 0, above=True), default=0.2,
                        help="energy ratio within this of 1 agrees (default 0.2)")
        ap.add_argument("--tol-shape", type=cli.number(float, 0, above=True), default=0.3,
                        help="relative spectrum error below this agrees (default 0.3)")

    def head(self, r):
        print("# the box holds kx delta = 0 and >= %.4g, kz delta = 0 and >= %.4g (no wavelength "
              "longer than lx = %g, lz = %g delta)" %
              (r["kx"][1] * r["delta"], r["kz"][1] * r["delta"], r["lx"] / r["delta"],
               r["lz"] / r["delta"]))
        print("# %5s %6s %3s %4s %10s %10s %9s %7s %9s %8s %8s %7s %7s %7s %8s  %s" %
              ("y+", "MKM y+", "dir", "comp", "Parseval", "W-K", "<u'2>+", "/Eul", "MKM",
               "ratio", "err", "k0 run", "k0 MKM", "MKM>L", "+-", "verdict"))

    @staticmethod
    def level_note(r, lev, yp):
        share = ("%.1f%%" % (100 * r["empty"][lev]) if np.isfinite(r["empty"][lev])
                 else "an unknown share (no empty_cells: a file of extract)")
        print("# y+ %.1f: %s of the grid cells were empty; %s" %
              (yp, share, "gap-corrected: R over the filled cell pairs, E its transform"
               if r["gap"][lev] else "not gap-corrected (a file before checkpoint format "
               "1.15, or no empty cell): zero-filled cells lower R(l) by the filled share "
               "squared and add a white floor to E"))

    @staticmethod
    def engine(r, lev, c, d):
        """PASS and the engine numbers (Parseval error, Wiener-Khinchin error)."""
        E = r["E_%s%s_k%s" % (c, c, d)][lev]
        R = r["R_%s%s_%s" % (c, c, d)][lev]
        L = r["lx"] if d == "x" else r["lz"]
        k = r["k" + d]
        dk = k[1] - k[0] if len(k) > 1 else 2 * math.pi / L
        if not (np.all(np.isfinite(E)) and np.all(np.isfinite(R)) and R[0] > 0):
            return False, (math.nan, math.nan)
        pars = abs(E.sum() * dk / R[0] - 1.0)
        wk = np.max(np.abs(wiener_khinchin(R, L) - E)) / np.max(np.abs(E))
        return pars <= EXACT and wk <= EXACT, (pars, wk)

    @staticmethod
    def no_dns_row(yp, d, c, ok, num):
        return ("  %5.1f %6s %3s %4s %10.2e %10.2e  (no MKM level near: not compared) engine %s"
                % (yp, "-", d, c, num[0], num[1], "PASS" if ok else "FAIL"))

    def dns_row(self, r, lev, yp, near, c, d, dnsfile, ok, num):
        """The run's and the DNS's densities in outer-wall units, the row and the curve."""
        ut, delta = r["u_tau"], r["delta"]
        k = r["k" + d] * delta
        E = r["E_%s%s_k%s" % (c, c, d)][lev] / (ut ** 2 * delta)
        dk = k[1] - k[0]
        t = dns_table(dnsfile, 5, "an MKM chanNNN.%sspec.N file" % d)
        kd = t[:, 0]
        dkd = kd[1] - kd[0]
        Ed = t[:, 1 + COMP.index(c)] / dkd
        var_d = Ed.sum() * dkd
        var = E.sum() * dk
        held = (k > 0) & (k <= kd[-1])
        pos = Ed > 0
        Ei = np.exp(np.interp(k[held], kd[pos], np.log(Ed[pos])))
        err = np.abs(E[held] - Ei).sum() / Ei.sum() if held.any() else math.nan
        lost = (kd > 0) & (kd < k[1] - 1e-9)
        cv = {"k": k, "E": E, "kd": kd, "Ed": Ed, "lost_k": kd[lost], "beyond": k[k > kd[-1]]}
        self.lost[d] = cv
        ratio, lost_share = var / var_d, Ed[lost].sum() * dkd / var_d
        agree = abs(ratio - 1) <= self.a.tol_energy and err <= self.a.tol_shape
        se = r.get("R_%s%s_%s_stderr" % (c, c, d))
        se = se[lev][0] / ut ** 2 if se is not None else math.nan
        row = ("  %5.1f %6g %3s %4s %10.2e %10.2e %9.4f %7.3f %9.4f %8.3f %8.3f %7.3f %7.3f "
               "%7.3f %8s  engine %s, DNS %s" %
               (yp, near, d, c, num[0], num[1], var, var * ut ** 2 / eulerian_variance(r, lev, c),
                var_d, ratio, err, E[0] * dk / var, Ed[0] * dkd / var_d, lost_share,
                "%.4f" % se if math.isfinite(se) else "-",
                "PASS" if ok else "FAIL", "agrees" if agree else "differs"))
        return row, cv

    def foot(self, r):
        for d in "xz":
            if d in self.lost:
                cv = self.lost[d]
                print("# not held in %s: the MKM wavenumbers k_%s delta = %s (wavelengths longer "
                      "than l%s; their share of the DNS energy: column MKM>L); our k_%s delta = "
                      "%.4g .. %.4g lie beyond the MKM files (not compared)" %
                      (d, d, ", ".join("%g" % k for k in cv["lost_k"]), d, d,
                       cv["beyond"][0] if len(cv["beyond"]) else math.nan,
                       cv["beyond"][-1] if len(cv["beyond"]) else math.nan))
        print("# Parseval: |sum E dk / R(0) - 1|; W-K: max |E - FT(R)| / max E; /Eul: energy / "
              "the Eulerian <u'2> profile at the level; ratio: energy / MKM <u'2>+; err: sum|E - "
              "E_MKM| / sum E_MKM over the held k; k0: share of the energy in the k = 0 mode; "
              "MKM>L: MKM share at 0 < k < 2 pi / L; +-: the standard error of <u'2>+ (batch "
              "means over the complete windows, R_ii_stderr at l = 0; - without) (tolerances: "
              "engine %g, DNS energy %g, shape %g)" % (EXACT, self.a.tol_energy, self.a.tol_shape))

    @staticmethod
    def draw(ax, cv, c, d, yp, near):
        pos = cv["k"] > 0
        ax.loglog(cv["k"][pos], cv["E"][pos], "o", ms=2.5, label="chansph")
        dpos = cv["kd"] > 0
        ax.loglog(cv["kd"][dpos], cv["Ed"][dpos], "k-", lw=1, label="MKM y+ %g" % near)
        ax.axvline(cv["k"][1], color="0.6", ls=":", lw=0.8)
        ax.set_title("E_%s%s(k_%s), y+ = %.0f" % (c, c, d, yp), fontsize=8)
        if c == "u":
            ax.set_ylabel("E / (u_tau^2 delta)", fontsize=7)
        ax.legend(fontsize=6, loc="lower left")

    @staticmethod
    def xlabel(d):
        return "k_%s delta" % d

    verdict = "engine spectra consistency (Parseval, Wiener-Khinchin): %s"


class Correlations:
    """corr_compare: R(l) = R(L - l) and |rho| <= 1, rho against MKM over half the box."""
    doc, dns_kind, png = CORR_DOC, "corr", "corr"
    dns_default = os.path.join(DNS_ROOT, "correlations")
    figure_height, sharex = 1.8, True

    def __init__(self, a):
        self.a = a

    @staticmethod
    def options(ap):
        ap.add_argument("--tol", type=cli.number(float, 0, above=True), default=0.1,
                        help="RMS difference of rho below this agrees (default 0.1)")

    @staticmethod
    def head(r):
        print("# %5s %6s %3s %4s %8s %8s %12s %12s %16s %16s %7s %7s %6s %6s  %s" %
              ("y+", "MKM y+", "dir", "comp", "R(0)+", "MKM", "l(rho=0.5)", "MKM",
               "min rho at l", "MKM", "rho L/2", "MKM", "rms d", "se", "verdict"))

    @staticmethod
    def level_note(r, lev, yp):
        pass

    @staticmethod
    def engine(r, lev, c, d):
        """PASS and the engine numbers: separations / delta and rho to half the box, R(0) in
        wall units, the symmetry error."""
        R = r["R_%s%s_%s" % (c, c, d)][lev]
        n = len(R)
        L = (r["lx"] if d == "x" else r["lz"]) / r["delta"]
        l = np.arange(n) * L / n
        ok = bool(np.all(np.isfinite(R)) and R[0] > 0)
        sym = np.max(np.abs(R[1:] - R[1:][::-1])) / R[0] if ok else math.nan
        rho = R / R[0] if ok else R * math.nan
        ok = bool(ok and sym <= 1e-9 and np.all(np.abs(rho) <= 1 + 1e-12))
        half = n // 2 + 1
        return ok, (l[:half], rho[:half], R[0] / r["u_tau"] ** 2, sym)

    @staticmethod
    def engine_text(ok, sym):
        return "PASS" if ok else "FAIL (symmetry %.2e)" % sym

    def no_dns_row(self, yp, d, c, ok, num):
        return ("  %5.1f      - %3s %4s (no MKM level near: not compared) engine %s" %
                (yp, d, c, self.engine_text(ok, num[3])))

    def dns_row(self, r, lev, yp, near, c, d, dnsfile, ok, num):
        l, rho, r0, sym = num
        t = dns_table(dnsfile, 6, "an MKM chanNNN.[xz]corr.N file")
        R = t[:, 2 + COMP.index(c)]
        ld, rd, r0d = t[:, 0], R / R[0], R[0]
        inside = ld <= l[-1] + 1e-9
        diff = math.sqrt(np.mean((rho - np.interp(l, ld, rd)) ** 2))

        def numbers(x, y):
            i = int(np.argmin(y))
            return half_width(x, y), y[i], x[i]

        hw, mn, lmn = numbers(l, rho)
        hwd, mnd, lmnd = numbers(ld[inside], rd[inside])
        endd = float(np.interp(l[-1], ld, rd))
        se = r.get("rho_%s%s_%s_stderr" % (c, c, d))  # RMS over half the box, as rms d
        se = math.sqrt(np.mean(se[lev][: len(l)] ** 2)) if se is not None else math.nan
        row = ("  %5.1f %6g %3s %4s %8.4f %8.4f %12s %12s %7.3f at %5.3f %7.3f at %5.3f "
               "%7.3f %7.3f %6.3f %6s  engine %s, DNS %s" %
               (yp, near, d, c, r0, r0d, "%.3f" % hw if hw == hw else "> %.3g" % l[-1],
                "%.3f" % hwd if hwd == hwd else "> %.3g" % l[-1], mn, lmn, mnd, lmnd,
                rho[-1], endd, diff, "%.3f" % se if math.isfinite(se) else "-",
                self.engine_text(ok, sym), "agrees" if diff <= self.a.tol else "differs"))
        return row, (l, rho, ld, rd)

    @staticmethod
    def foot(r):
        print("# separations in delta; l(rho=0.5): first drop below 0.5; rho L/2: at half our "
              "box (MKM interpolated there); rms d: RMS of rho - rho_MKM over half our box; se: "
              "RMS of rho's standard error there (batch means; - without)")

    @staticmethod
    def draw(ax, cv, c, d, yp, near):
        l, rho, ld, rd = cv
        ax.plot(l, rho, "o-", ms=2.5, lw=0.8, label="chansph")
        keep = ld <= l[-1] * 1.5
        ax.plot(ld[keep], rd[keep], "k-", lw=1, label="MKM y+ %g" % near)
        ax.axhline(0, color="0.7", lw=0.5)
        ax.set_title("rho_%s%s(%s), y+ = %.0f" % (c, c, d, yp), fontsize=8)
        ax.legend(fontsize=6)

    @staticmethod
    def xlabel(d):
        return "%s separation / delta" % d

    verdict = "engine correlation consistency (R(l) = R(L - l), |rho| <= 1): %s"


def plot(tool, path, d, curves, levels):
    """One row per level, one column per component."""
    plt = pyplot()
    fig, axes = plt.subplots(len(levels), 3, figsize=(9, tool.figure_height * len(levels) + 0.5),
                             squeeze=False, sharex=tool.sharex)
    for (yp, near, c), cv in curves.items():
        ax = axes[levels.index((yp, near))][COMP.index(c)]
        tool.draw(ax, cv, c, d, yp, near)
        ax.tick_params(labelsize=7)
    for ax in axes[-1]:
        ax.set_xlabel(tool.xlabel(d), fontsize=8)
    fig.tight_layout()
    save(fig, path)


def compare(kind, argv, prog):
    """The tool kind (Spectra or Correlations) on the command line argv."""
    ap = cli.parser(prog, kind.doc)
    ap.add_argument("stats", help="stats.nc of a run with correlations.y_plus set")
    ap.add_argument("--out", help="write %s_x.png and %s_z.png into this directory" %
                    (kind.png, kind.png))
    ap.add_argument("--dns", default=kind.dns_default,
                    help="folder of the MKM chan180.[xz]%s.N files" % kind.dns_kind)
    ap.add_argument("--u-tau", type=u_tau_arg, default="force",
                    help="u_tau of the wall units: force (default), wall or a value [m/s]")
    kind.options(ap)
    a = ap.parse_args(argv)
    tool = kind(a)
    dns = {d: dns_files(a.dns, d + kind.dns_kind) for d in "xz"}
    r = read_corr(a.stats, a.u_tau)
    if a.out:
        out_dir(a.out)
    header(r, a.stats)
    tool.head(r)
    failed, levels, curves = False, {"x": [], "z": []}, {"x": {}, "z": {}}
    for lev in range(len(r["y_plus"])):
        if not r["samples"][lev] > 0:
            print("# level %d (y+ %g): no samples: skipped" % (lev, r["y_plus"][lev]))
            continue
        yp = run_y_plus(r, lev)
        tool.level_note(r, lev, yp)
        for d in "xz":
            near = nearest(dns[d], yp)
            for c in COMP:
                ok, num = tool.engine(r, lev, c, d)
                failed |= not ok
                if near is None:
                    print(tool.no_dns_row(yp, d, c, ok, num))
                    continue
                row, cv = tool.dns_row(r, lev, yp, near, c, d, dns[d][near], ok, num)
                print(row)
                curves[d][(yp, near, c)] = cv
                if (yp, near) not in levels[d]:
                    levels[d].append((yp, near))
    tool.foot(r)
    if not any(levels.values()):
        raise InputError("%s: no level of group correlations is near an MKM level" % a.stats)
    if a.out:
        for d in "xz":
            if levels[d]:
                plot(tool, os.path.join(a.out, "%s_%s.png" % (kind.png, d)), d, curves[d],
                     levels[d])
    print(kind.verdict % ("FAIL" if failed else "PASS"))
    return 1 if failed else 0


def spectra_main(argv, prog):
    """The tool spectra_compare."""
    return compare(Spectra, argv, prog)


def corr_main(argv, prog):
    """The tool corr_compare."""
    return compare(Correlations, argv, prog)
