#!/usr/bin/python3
"""Check the Reynolds-stress budgets of a run (stats.nc variables rsb_<component>_<term>;
docs/stats-format.md, "Reynolds-stress budgets").

usage: rs_budget_check.py STATS.nc [--identity T] [--closure T] [--laminar T]

Always: the budgets exist; k is half the sum of uu, vv, ww and transport is transfer less
production (to round-off).
  --identity T  sampled at every step the budget is an identity of the scheme: in each
                component max |closure| <= T times the largest term (pressure .. transfer, rate)
  --closure T   max |closure| <= T in wall units u_tau^4 / nu (u_tau of the force balance)
  --laminar T   every term of every component <= T u_tau^4 / nu (no turbulence)
Prints the largest value of each term per component. Exit 1 on a failed check.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ncfile import open_nc  # noqa: E402

COMPONENTS = ("uu", "vv", "ww", "uv", "k")
TERMS = ("pressure", "viscous", "model", "wall", "drive", "transfer", "production", "transport",
         "rate", "closure", "pressure_noise")


def main():
    ap = cli.parser("rs_budget_check.py", __doc__)
    ap.add_argument("stats")
    ap.add_argument("--identity", type=cli.number(float, 0))
    ap.add_argument("--closure", type=cli.number(float, 0))
    ap.add_argument("--laminar", type=cli.number(float, 0))
    a = ap.parse_args()
    with open_nc(a.stats) as d:
        if "rsb_uu_pressure" not in d.variables:
            raise cli.InputError(f"{a.stats}: no Reynolds-stress budget (no variable "
                                 f"'rsb_uu_pressure')")
        wall = float(d.u_tau_force) ** 4 / float(d.nu)  # u_tau^4 / nu
        n = d.dimensions["y"].size
        b = {(c, t): (np.ma.filled(d[f"rsb_{c}_{t}"][:].astype(float), np.nan)
                      if f"rsb_{c}_{t}" in d.variables else np.zeros(n))
             for c in COMPONENTS for t in TERMS}
    fail = 0
    print("largest |term| in u_tau^4/nu (u_tau of the force balance):")
    print("%4s " % "" + " ".join("%11s" % t for t in TERMS))
    for c in COMPONENTS:
        print("%4s " % c + " ".join("%11.3e" % (np.nanmax(np.abs(b[c, t])) / wall) for t in TERMS))
    for t in TERMS:
        dk = np.nanmax(np.abs(b["k", t] - 0.5 * (b["uu", t] + b["vv", t] + b["ww", t])))
        if not dk <= 1e-12 * wall + 1e-9 * np.nanmax(np.abs(b["k", t])):
            print(f"FAIL: rsb_k_{t} is not half the sum of uu, vv, ww ({dk:.3g})")
            fail = 1
    for c in COMPONENTS:
        dt = np.nanmax(np.abs(b[c, "transport"] - (b[c, "transfer"] - b[c, "production"])))
        if not dt <= 1e-9 * max(np.nanmax(np.abs(b[c, "transfer"])), 1e-300) + 1e-12 * wall:
            print(f"FAIL: rsb_{c}_transport is not transfer - production ({dt:.3g})")
            fail = 1
        cl = np.nanmax(np.abs(b[c, "closure"]))
        if not np.isfinite(cl):
            print(f"FAIL: rsb_{c}_closure has no value")
            fail = 1
            continue
        if a.identity is not None:
            big = max(np.nanmax(np.abs(b[c, t])) for t in TERMS[:6] + ("rate",))
            print(f"{c}: closure {cl:.3g} = {cl / big:.3g} of the largest term {big:.3g} "
                  f"(tolerance {a.identity})")
            if not cl <= a.identity * big:
                print(f"FAIL: the {c} budget is not an identity")
                fail = 1
        if a.closure is not None:
            print(f"{c}: closure {cl / wall:.3g} u_tau^4/nu (tolerance {a.closure})")
            if not cl <= a.closure * wall:
                print(f"FAIL: the {c} budget does not close")
                fail = 1
        if a.laminar is not None:
            worst = max(np.nanmax(np.abs(b[c, t])) for t in TERMS) / wall
            print(f"{c}: laminar, largest term {worst:.3g} u_tau^4/nu (tolerance {a.laminar})")
            if not worst <= a.laminar:
                print(f"FAIL: laminar flow with a {c} budget term of {worst:.3g} u_tau^4/nu")
                fail = 1
    return fail


if __name__ == "__main__":
    sys.exit(cli.run(main))
