"""chansph-stats lagr_table: the Lagrangian and quadrant statistics of a stats.nc with their
standard errors, as markdown tables in wall units (docs/validation/statistics.md).

Prints, for each Lagrangian level: the integral times T_L+ of u, v, w (the mean of the releases'
own T_L, `T_L_release_mean`, +- `T_L_stderr`), the autocorrelations rho_L of u, v, w at two lags
(--lags, in wall units) and the dispersion sigma_y^2, sigma_z^2 at the horizon, each +- its
standard error from the file; then how honest the release errors are: the standard error of the
mean of `T_L_release` from blocks of 2, 5 and 10 consecutive releases over the file's own one
(releases closer than about 2 T_L are not independent; the file's `releases_overlap` says
so); then the quadrants' shares of u'v' and of the time at each level with their errors, and
whether the windows are shorter than the run's correlation time (`short_windows`). Wall units
of the force balance (u_tau_force; T+ = T u_tau^2 / nu).
"""
import math

import numpy as np

from . import cli
from .ncfile import open_nc


def blocked_stderr(x, block):
    """Standard error of the mean of the finite values x from means of `block` consecutive
    ones (nan with fewer than 3 blocks)."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    nb = len(x) // block
    if nb < 3:
        return math.nan
    m = x[:nb * block].reshape(nb, block).mean(axis=1)
    return float(np.std(m, ddof=1) / math.sqrt(nb))


def pm(v, e, fmt="%.3f"):
    return (fmt + " +- " + fmt) % (v, e)


def lagrangian(d, out, lags_plus):
    L = d["lagrangian"]
    ut = float(d.u_tau_force)
    tplus = ut * ut / float(d.nu)
    yp = L["y_plus"][:]
    lag = np.asarray(L["lag"][:], dtype=float)
    comp = "uvw"
    out.append("Lagrangian: %d releases every %g over a horizon of %g (releases_overlap = %d); "
               "wall units of u_tau_force = %g" % (int(L.releases), float(L.release_every),
                                                    float(L.horizon), int(L.releases_overlap), ut))
    out.append("")
    il = [int(np.argmin(np.abs(lag * tplus - lp))) for lp in lags_plus]
    head = " | ".join("rho_L of u, v, w at tau+ = %g" % (lag[i] * tplus) for i in il)
    out.append("| y+ | T_L,u+ | T_L,v+ | T_L,w+ | %s | sigma_y^2, sigma_z^2 at tau+ = %g "
               "[delta^2] |" % (head, lag[-1] * tplus))
    out.append("|---|---|---|---|" + "---|" * len(il) + "---|")
    for k in range(len(yp)):
        cells = ["%g" % yp[k]]
        for c in range(3):
            cells.append(pm(L["T_L_release_mean"][k, c] * tplus, L["T_L_stderr"][k, c] * tplus,
                            "%.1f"))
        for i in il:
            cells.append(", ".join(pm(L["rho_L_" + comp[c]][k, i], L["rho_L_%s_stderr" % comp[c]][k, i])
                                   for c in range(3)))
        cells.append(", ".join(pm(L[v][k, -1], L[v + "_stderr"][k, -1], "%.4g")
                               for v in ("sigma2_y", "sigma2_z")))
        out.append("| " + " | ".join(cells) + " |")
    out.append("")
    out.append("Release errors against blocking of the T_L history (standard error of the mean "
               "of T_L_release from blocks of 1, 2, 5, 10 consecutive releases, wall units):")
    out.append("")
    out.append("| y+ | component | releases | 1 | 2 | 5 | 10 | file's T_L_stderr |")
    out.append("|---|---|---|---|---|---|---|---|")
    hist = np.ma.filled(L["T_L_release"][:].astype(float), np.nan)
    for k in range(len(yp)):
        for c in range(3):
            x = hist[:, k, c]
            row = ["%g" % yp[k], comp[c], "%d" % int(np.sum(np.isfinite(x)))]
            row += ["%.2f" % (blocked_stderr(x, b) * tplus) for b in (1, 2, 5, 10)]
            row.append("%.2f" % (float(L["T_L_stderr"][k, c]) * tplus))
            out.append("| " + " | ".join(row) + " |")
    out.append("")


def quadrants(d, out):
    Q = d["quadrants"]
    names = ("Q1 outward", "Q2 ejection", "Q3 inward", "Q4 sweep")
    nb = Q["n_batches"][:]
    out.append("Quadrants: windows of %g, %s complete windows per level; short_windows = %s, "
               "n_eff_windows = %.2g (file)" % (float(Q.window_length),
                                                ", ".join("%d" % n for n in nb),
                                                getattr(d, "short_windows", "?"),
                                                float(getattr(d, "n_eff_windows", math.nan))))
    out.append("")
    out.append("| y+ | " + " | ".join(names) + " |")
    out.append("|---|---|---|---|---|")
    for k, y in enumerate(Q["y_plus"][:]):
        for var, what in (("uv_fraction", "share of u'v'"), ("time_fraction", "time")):
            out.append("| %g, %s | " % (y, what) + " | ".join(
                pm(Q[var][k, q], Q[var + "_stderr"][k, q]) for q in range(4)) + " |")
    out.append("")


def main(argv, prog):
    p = cli.parser(prog, __doc__)
    p.add_argument("stats", help="a stats.nc (a run's or joined by chansph extract --nc)")
    p.add_argument("--lags", type=cli.number(float, 0, above=True), nargs=2,
                   default=[18.0, 36.0], help="two lags in wall units for rho_L (default 18 36)")
    a = p.parse_args(argv)
    d = open_nc(a.stats)
    out = ["%s: t_reached %s, source %s" % (a.stats, getattr(d, "t_reached", "?"),
                                             getattr(d, "source", "?")), ""]
    if "lagrangian" not in d.groups and "quadrants" not in d.groups:
        raise cli.InputError("%s: no lagrangian or quadrants group" % a.stats)
    if "lagrangian" in d.groups:
        lagrangian(d, out, a.lags)
    if "quadrants" in d.groups:
        quadrants(d, out)
    print("\n".join(out))
    return 0
