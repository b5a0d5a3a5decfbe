"""1-D spectra of u, v, w in x and z of a run (group correlations) against MKM Re_tau = 180.

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
import math
import os

import numpy as np

from . import cli
from .cli import InputError
from .twopoint import (COMP, DNS_ROOT, dns_files, dns_table, eulerian_variance, header,
                       nearest, out_dir, pyplot,
                       read_corr, run_y_plus, save, u_tau_arg)

DEFAULT_DNS = os.path.join(DNS_ROOT, "spectra")
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


def engine_checks(r, lev, c, d):
    """(Parseval error, Wiener-Khinchin error) of one level, component and direction."""
    E = r["E_%s%s_k%s" % (c, c, d)][lev]
    R = r["R_%s%s_%s" % (c, c, d)][lev]
    L = r["lx"] if d == "x" else r["lz"]
    k = r["k" + d]
    dk = k[1] - k[0] if len(k) > 1 else 2 * math.pi / L
    if not (np.all(np.isfinite(E)) and np.all(np.isfinite(R)) and R[0] > 0):
        return math.nan, math.nan
    pars = abs(E.sum() * dk / R[0] - 1.0)
    wk = np.max(np.abs(wiener_khinchin(R, L) - E)) / np.max(np.abs(E))
    return pars, wk


def dns_compare(r, lev, c, d, dnsfile):
    """The run's and the DNS's densities in outer-wall units and the comparison numbers."""
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
    return {"k": k, "E": E, "kd": kd, "Ed": Ed, "ratio": var / var_d, "err": err,
            "var": var, "var_d": var_d, "lost_k": kd[lost],
            "lost_share": Ed[lost].sum() * dkd / var_d, "zero_share": E[0] * dk / var,
            "zero_share_d": Ed[0] * dkd / var_d, "beyond": k[k > kd[-1]]}


def plot(path, d, curves, levels):
    plt = pyplot()
    fig, axes = plt.subplots(len(levels), 3, figsize=(9, 1.9 * len(levels) + 0.5),
                             squeeze=False)
    for (yp, near, c), cv in curves.items():
        ax = axes[levels.index((yp, near))][COMP.index(c)]
        pos = cv["k"] > 0
        ax.loglog(cv["k"][pos], cv["E"][pos], "o", ms=2.5, label="chansph")
        dpos = cv["kd"] > 0
        ax.loglog(cv["kd"][dpos], cv["Ed"][dpos], "k-", lw=1, label="MKM y+ %g" % near)
        ax.axvline(cv["k"][1], color="0.6", ls=":", lw=0.8)
        ax.set_title("E_%s%s(k_%s), y+ = %.0f" % (c, c, d, yp), fontsize=8)
        ax.tick_params(labelsize=7)
        if c == "u":
            ax.set_ylabel("E / (u_tau^2 delta)", fontsize=7)
        ax.legend(fontsize=6, loc="lower left")
    for ax in axes[-1]:
        ax.set_xlabel("k_%s delta" % d, fontsize=8)
    fig.tight_layout()
    save(fig, path)


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("stats", help="stats.nc of a run with correlations.y_plus set")
    ap.add_argument("--out", help="write spectra_x.png and spectra_z.png into this directory")
    ap.add_argument("--dns", default=DEFAULT_DNS, help="folder of the MKM chan180.[xz]spec.N files")
    ap.add_argument("--u-tau", type=u_tau_arg, default="force",
                    help="u_tau of the wall units: force (default), wall or a value [m/s]")
    ap.add_argument("--tol-energy", type=cli.number(float, 0, above=True), default=0.2,
                    help="energy ratio within this of 1 agrees (default 0.2)")
    ap.add_argument("--tol-shape", type=cli.number(float, 0, above=True), default=0.3,
                    help="relative spectrum error below this agrees (default 0.3)")
    a = ap.parse_args(argv)
    dns = {d: dns_files(a.dns, d + "spec") for d in "xz"}
    r = read_corr(a.stats, a.u_tau)
    if a.out:
        out_dir(a.out)
    header(r, a.stats)
    print("# the box holds kx delta = 0 and >= %.4g, kz delta = 0 and >= %.4g (no wavelength "
          "longer than lx = %g, lz = %g delta)" %
          (r["kx"][1] * r["delta"], r["kz"][1] * r["delta"], r["lx"] / r["delta"],
           r["lz"] / r["delta"]))
    print("# %5s %6s %3s %4s %10s %10s %9s %7s %9s %8s %8s %7s %7s %7s  %s" %
          ("y+", "MKM y+", "dir", "comp", "Parseval", "W-K", "<u'2>+", "/Eul", "MKM", "ratio",
           "err", "k0 run", "k0 MKM", "MKM>L", "verdict"))
    failed, levels, curves, lost = False, {"x": [], "z": []}, {"x": {}, "z": {}}, {}
    for lev in range(len(r["y_plus"])):
        if not r["samples"][lev] > 0:
            print("# level %d (y+ %g): no samples: skipped" % (lev, r["y_plus"][lev]))
            continue
        yp = run_y_plus(r, lev)
        print("# y+ %.1f: %.1f%% of the grid cells were empty (zero fluctuation there: the "
              "spectra miss about that share of the variance)" % (yp, 100 * r["empty"][lev]))
        for d in "xz":
            near = nearest(dns[d], yp)
            for c in COMP:
                pars, wk = engine_checks(r, lev, c, d)
                ok = pars <= EXACT and wk <= EXACT
                failed |= not ok
                if near is None:
                    print("  %5.1f %6s %3s %4s %10.2e %10.2e  (no MKM level near: not compared) "
                          "engine %s" % (yp, "-", d, c, pars, wk, "PASS" if ok else "FAIL"))
                    continue
                cv = dns_compare(r, lev, c, d, dns[d][near])
                agree = abs(cv["ratio"] - 1) <= a.tol_energy and cv["err"] <= a.tol_shape
                print("  %5.1f %6g %3s %4s %10.2e %10.2e %9.4f %7.3f %9.4f %8.3f %8.3f %7.3f %7.3f %7.3f  "
                      "engine %s, DNS %s" %
                      (yp, near, d, c, pars, wk, cv["var"],
                       cv["var"] * r["u_tau"] ** 2 / eulerian_variance(r, lev, c), cv["var_d"], cv["ratio"], cv["err"],
                       cv["zero_share"], cv["zero_share_d"], cv["lost_share"], "PASS" if ok else "FAIL",
                       "agrees" if agree else "differs"))
                curves[d][(yp, near, c)] = cv
                if (yp, near) not in levels[d]:
                    levels[d].append((yp, near))
                lost[d] = cv
    for d in "xz":
        if d in lost:
            cv = lost[d]
            print("# not held in %s: the MKM wavenumbers k_%s delta = %s (wavelengths longer than "
                  "l%s; their share of the DNS energy: column MKM>L); our k_%s delta = "
                  "%.4g .. %.4g lie beyond the MKM files (not compared)" %
                  (d, d, ", ".join("%g" % k for k in cv["lost_k"]), d, d,
                   cv["beyond"][0] if len(cv["beyond"]) else math.nan,
                   cv["beyond"][-1] if len(cv["beyond"]) else math.nan))
    print("# Parseval: |sum E dk / R(0) - 1|; W-K: max |E - FT(R)| / max E; /Eul: energy / the "
          "Eulerian <u'2> profile at the level; ratio: energy / MKM <u'2>+; err: sum|E - E_MKM| / "
          "sum E_MKM over the held k; k0: share of the energy in the k = 0 mode; MKM>L: MKM share "
          "at 0 < k < 2 pi / L (tolerances: engine %g, DNS energy %g, shape %g)" %
          (EXACT, a.tol_energy, a.tol_shape))
    if not any(levels.values()):
        raise InputError("%s: no level of group correlations is near an MKM level" % a.stats)
    if a.out:
        for d in "xz":
            if levels[d]:
                plot(os.path.join(a.out, "spectra_%s.png" % d), d, curves[d], levels[d])
    print("engine spectra consistency (Parseval, Wiener-Khinchin): %s" %
          ("FAIL" if failed else "PASS"))
    return 1 if failed else 0
