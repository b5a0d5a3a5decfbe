"""The resolution a turbulent channel series extrapolates to, for the resolution series' targets.

usage: chansph-stats resolution_extrapolate --dns FILE [--window T0:T1] [--units wall|force]
           --developed RUN_DIR[+...] --developed-dr DR [--developed-window T0:T1]
           DR=RUN_DIR[+RUN_DIR...] DR=... ...

Two steps, both printed:

1. The rate. Every run of the series starts from the same synthetic-eddy state, so the same
   window after the start (default 0.5-2.0 delta/u_tau) compares like with like across the
   resolutions, even where the coarse runs decay. For each quantity its deviation from the DNS
   is measured over that window (the measures below), and a power law |e| = C dr+^p is fitted
   to the resolutions by least squares in log-log: p is how fast refining helps.
2. The extrapolation. The developed run's deviations over its own window are carried down with
   that rate: the resolution needed is dr+_dev (target / |e_dev|)^(1/p). Where a quantity's own
   rate is missing (p <= 0.05), the slower of the two peaks' rates is printed beside it.

Measures (the targets the resolution series was set): for -u'v'+ and u_rms+, the relative deviation of
the peak from the DNS peak (target 15%); for v_rms+ and w_rms+, the largest relative deviation
from the DNS over 20 < y+ < 150 (target 20%). Wall units: u_tau from the mean wall shear stress
of the windows taken (default; the same numbers as `chansph extract --units wall`), or from the
force balance (--units force, error_vs_time's).

The extrapolation assumes the developed error falls at the rate of the common transient window;
it is an estimate of the order of the resolution needed, not a prediction of its statistics.
"""
import math

import numpy as np

from . import cli
from .cli import InputError
from .dns import Y_HI, Y_LO, deviation, read_dns
from .merge import window_profile

MEASURES = (("-u'v'+", "peak", 0.15), ("u_rms+", "peak", 0.15),
            ("v_rms+", "range", 0.20), ("w_rms+", "range", 0.20))


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("series", nargs="+", help="DR=RUN_DIR[+RUN_DIR...] (dr in wall units)")
    ap.add_argument("--dns", required=True)
    ap.add_argument("--window", type=cli.window, default=(0.5, 2.0))
    ap.add_argument("--developed", required=True, help="run directory of the developed run")
    ap.add_argument("--developed-dr", type=cli.number(float, 0, above=True), required=True)
    ap.add_argument("--developed-window", type=cli.window, default=(0.5, math.inf))
    ap.add_argument("--units", choices=("wall", "force"), default="wall",
                    help="u_tau from the wall shear stress of the windows taken, or the force balance")
    a = ap.parse_args(argv)
    dns = read_dns(a.dns)
    series = []
    for spec in a.series:
        dr, _, dirs = spec.partition("=")
        try:
            dr = float(dr)
        except ValueError:
            raise InputError(f"{spec}: expected DR=RUN_DIR[+RUN_DIR...]")
        if not dirs or not dr > 0:
            raise InputError(f"{spec}: expected DR=RUN_DIR[+RUN_DIR...] with DR > 0")
        prof, span = window_profile(dirs, *a.window, a.units)
        series.append((dr, span, {q: deviation(prof, dns, q, k) for q, k, _ in MEASURES}))
    if len(series) < 2:
        raise InputError("at least two resolutions are needed for a rate")
    dev, dev_span = window_profile(a.developed, *a.developed_window, a.units)
    dev = {q: deviation(dev, dns, q, k) for q, k, _ in MEASURES}
    print(f"# 1. deviations from {dns['name']} over the common window "
          f"{a.window[0]}-{a.window[1]} delta/u_tau ({a.units} units)")
    print(f"# {'dr+':>5} {'window':>11} " + " ".join(f"{q:>8}" for q, _, _ in MEASURES))
    for dr, span, e in sorted(series, reverse=True):
        print(f"  {dr:5.2f} {span[0]:5.2f}-{span[1]:5.2f} " +
              " ".join(f"{100 * e[q]:+7.0f}%" for q, _, _ in MEASURES))
    lx = np.log([s[0] for s in series])
    rate = {}
    for q, _, _ in MEASURES:
        ly = np.log([max(abs(s[2][q]), 1e-6) for s in series])
        rate[q] = np.polyfit(lx, ly, 1)[0]
    # the rate of the quantities that converge, for those whose own rate the series lacks
    borrowed = min(rate[q] for q, kind, _ in MEASURES if kind == "peak")
    print(f"# 2. rate p of |e| = C dr+^p, the developed run (dr+ {a.developed_dr:g}, "
          f"{dev_span[0]:.2f}-{dev_span[1]:.2f}) and the dr+ needed at "
          f"its own rate and at p = {borrowed:.2f} (the slower of the peaks' rates)")
    print(f"# {'quantity':<8} {'measure':<22} {'p':>5} {'developed':>9} {'target':>6} "
          f"{'dr+ needed':>10} {'at p=' + format(borrowed, '.2f'):>10}")

    def need(e, target, p):
        if abs(e) <= target:
            return "met"
        if p <= 0.05:
            return "no rate"
        return f"{a.developed_dr * (target / abs(e)) ** (1.0 / p):.1f}"

    for q, kind, target in MEASURES:
        e = dev[q]
        what = "peak" if kind == "peak" else f"largest, {Y_LO:g}<y+<{Y_HI:g}"
        print(f"  {q:<8} {what:<22} {rate[q]:5.2f} {100 * e:+8.0f}% {100 * target:5.0f}% "
              f"{need(e, target, rate[q]):>10} {need(e, target, borrowed):>10}")
