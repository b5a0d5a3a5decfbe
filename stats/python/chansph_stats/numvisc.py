"""The numerical pair stress read as a viscosity (chansph compare's last profile table).

The momentum budget splits the total shear stress into the Reynolds stress, the viscous stress
of the pair forces and the numerical pair stress (pair_stress: what the pressure and volume
diffusion pair forces carry across a plane beyond the particles' own motion; docs/stats-format.md).
Where the latter is proportional to the mean shear it acts as an extra viscosity,

    nu_num / nu = pair_stress / (nu dU/dy) = pair+ / (dU+/dy+),

and a flow with nu + nu_num has its near-wall layer in the wall units of that viscosity:

    y*+ = integral from the wall of dy+ / (1 + nu_num / nu).

If the numerical stress is what moves the near-wall cycle away from the wall, the run's
profiles agree with the DNS better in y*+ than in y+; what still differs there (the amplitudes)
has another cause. docs/validation/scheme_ab.md, "The numerical stress is a viscosity".
"""
import math
import os

import numpy as np

from .merge import peak_position

LEVELS = (5.0, 10.0, 15.0, 20.0, 30.0, 50.0, 100.0)


def merge_mirrored(ours, keys):
    """ours with the bins at the same y+ averaged: an unfolded run's lower and upper halves,
    mirrored by compare.read_run, give every position twice (equal to rounding). Returns a dict
    of yplus and the keys present, on the distinct positions in increasing order."""
    yp = np.asarray(ours["yplus"], dtype=float)
    order = np.argsort(yp, kind="stable")
    yp = yp[order]
    new = np.concatenate([[True], np.diff(yp) > 1e-9 * max(1.0, float(yp[-1]))])
    group = np.cumsum(new) - 1
    count = np.bincount(group).astype(float)
    out = {"yplus": np.bincount(group, weights=yp) / count}
    for k in keys:
        if ours.get(k) is not None:
            out[k] = np.bincount(group, weights=np.asarray(ours[k], dtype=float)[order]) / count
    return out


def ratio(ours):
    """nu_num / nu at each bin: pair+ / (dU+/dy+), the mean gradient by central differences
    over the bins (np.gradient); NaN where the gradient is not positive or there is no pair
    stress. None for a file without the momentum budget."""
    pair = ours.get("budget:pair_stress")
    if pair is None or ours.get("U+") is None:
        return None
    grad = np.gradient(np.asarray(ours["U+"], dtype=float), np.asarray(ours["yplus"], dtype=float))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(grad > 0, pair / np.where(grad > 0, grad, 1.0), np.nan)


def effective_yplus(yplus, r):
    """y*+ at the bin positions yplus (sorted): the trapezoid rule for the integral of
    dy+ / (1 + r) from the wall, with r taken as 0 where it is not finite or negative (no
    numerical viscosity there) and the first bin's r from the wall to it."""
    yplus = np.asarray(yplus, dtype=float)
    f = 1.0 / (1.0 + np.where(np.isfinite(r) & (r > 0), r, 0.0))
    out = np.empty_like(yplus)
    out[0] = yplus[0] * f[0]
    out[1:] = out[0] + np.cumsum(np.diff(yplus) * 0.5 * (f[1:] + f[:-1]))
    return out


def deviations(yplus, ours, dns, quantities, lo, hi):
    """Per quantity: (max |ours - DNS| / DNS peak over lo < yplus < hi, the y+ of our peak),
    the DNS interpolated to yplus (linearly in y+)."""
    sel = (yplus > lo) & (yplus < hi)
    out = {}
    for q in quantities:
        if ours.get(q) is None or dns.get(q) is None:
            continue
        ref = np.interp(yplus, dns["yplus"], dns[q])
        diff = np.abs(ours[q] - ref)[sel]
        peak = float(np.nanmax(np.abs(dns[q])))
        dev = float(np.nanmax(diff)) / peak if sel.any() and np.isfinite(diff).any() else math.nan
        out[q] = (dev, math.nan if q == "U+" else peak_position(yplus, ours[q]))
    return out


def report(ours, dns, out_dir, quantities, lo=10.0, hi=60.0):
    """Print nu_num / nu at LEVELS and its means over 10-30 and 30-60, then the deviations and
    peak positions in y+ and in y*+ over lo < y < hi; write numerical_viscosity.csv. Returns
    (r, y*+) or None for a file without the momentum budget."""
    if ours.get("budget:pair_stress") is None:
        return None
    ours = merge_mirrored(ours, ("U+", "budget:pair_stress") + tuple(quantities))
    r = ratio(ours)
    yp = ours["yplus"]
    ystar = effective_yplus(yp, r)
    print("numerical viscosity: the pair stress over the mean shear's viscous stress, nu_num / nu "
          "= pair+ / (dU+/dy+):")
    print("  " + "  ".join("y+ %.1f: %.2f" % (yp[k], r[k])
                           for k in sorted({int(np.argmin(np.abs(yp - t))) for t in LEVELS})))

    def mean(a, b):
        s = (yp > a) & (yp < b) & np.isfinite(r)
        return float(np.mean(r[s])) if s.any() else math.nan
    print("  mean over 10 < y+ < 30: %s, over 30 < y+ < 60: %s"
          % tuple("%.2f" % m if math.isfinite(m) else "-" for m in (mean(10, 30), mean(30, 60))))
    write_csv(os.path.join(out_dir, "numerical_viscosity.csv"), ours.get("source", ""), yp, ystar,
              r)
    if not ((yp > lo) & (yp < hi)).any():
        print("  no bins over %g < y+ < %g: no comparison in y*+" % (lo, hi))
        return r, ystar
    nominal = deviations(yp, ours, dns, quantities, lo, hi)
    effective = deviations(ystar, ours, dns, quantities, lo, hi)
    print("  in the wall units of nu + nu_num (y*+ = integral of dy+ / (1 + nu_num / nu)), "
          "%g < y < %g: max |ours - DNS| / DNS peak, our peak's position" % (lo, hi))
    print("  %-8s %9s %9s %9s %9s %9s" % ("", "dev y+", "dev y*+", "peak y+", "peak y*+",
                                         "DNS peak"))
    for q in nominal:
        dns_peak = math.nan if q == "U+" else peak_position(dns["yplus"], dns[q])
        print("  %-8s %8.1f%% %8.1f%% %9.1f %9.1f %9.1f" % (
            q, 100 * nominal[q][0], 100 * effective[q][0], nominal[q][1], effective[q][1],
            dns_peak))
    return r, ystar


def write_csv(path, source, yp, ystar, r):
    """numerical_viscosity.csv: two comment lines, the header, one row per distinct position."""
    with open(path, "w") as f:
        f.write("# %s\n# nu_num/nu = pair+ / (dU+/dy+); y*+ = integral of dy+ / (1 + nu_num/nu)\n"
                "yplus,ystar_plus,nu_num_over_nu\n" % source)
        for a, b, c in zip(yp, ystar, r):
            f.write("%.6e,%.6e,%.6e\n" % (a, b, c))
