#!/usr/bin/python3
"""Check the momentum budget of a run (stats.nc, method of planes; docs/stats-format.md).

usage: budget_check.py STATS.nc --tol T [--laminar] [--unsteady] [--window T0:T1 [--chansph BIN]]

Asserts, in wall units of the force balance (u_tau_force^2):
  - total_stress is the sum of its parts (reynolds, viscous, model, pair, wall) to round-off;
  - the budget closes: max over every bin |total_stress - total_stress_expected| <= T
    (with --unsteady: |total_stress + momentum_change - total_stress_expected|, for a run that
    is not yet statistically steady); where the file has them (format 1.14), the same with the
    total over every snapshot (total_stress_all, momentum_change_all, total_stress_expected_all);
  - with --laminar: the pressure pair stress and the Reynolds stress are below 0.005, and where
    no wall term acts (farther than 2h from the walls; not the end bins, where nu dU/dy is
    one-sided) the viscous pair stress equals the continuum nu dU/dy (viscous_stress) within
    0.01; the pair forces conserve momentum (|pair_momentum_source| <= 0.005) and the wall
    stress (u_tau_wall^2: wall terms, the pairs' non-conservative rest and the wall layer's
    body force; docs/theory.md "Momentum at the walls") is the driving force within 0.01.
With --window the profiles are those of the windows in T0:T1 (`chansph extract --window`,
e.g. the part of a resumed run written by a build with the present budget).
Prints the split of the stress in every bin. Exit 1 on a failed check.
"""
import csv
import io
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ncfile import attribute, attribute_or_nan, open_nc  # noqa: E402

PARTS = ("reynolds_stress", "viscous_pair_stress", "model_pair_stress", "pair_stress",
         "wall_term_stress", "advective_stress")
ALL = ("total_stress_all", "momentum_change_all", "total_stress_expected_all")


def main():
    ap = cli.parser("budget_check.py", __doc__)
    ap.add_argument("stats")
    ap.add_argument("--tol", type=cli.number(float, 0), required=True)
    ap.add_argument("--laminar", action="store_true")
    ap.add_argument("--unsteady", action="store_true")
    ap.add_argument("--window", help="T0:T1: the windows of that range (chansph extract)")
    ap.add_argument("--chansph", default="build/chansph")
    a = ap.parse_args()
    y, v = read_budget(a)
    with open_nc(a.stats) as d:  # the wall layer: within 2h of a wall, in the units of y
        scale = float(d.delta) if a.window else 1.0
        a.tau_wall = float(d.u_tau_wall) ** 2 / float(d.u_tau_force) ** 2
        a.layer = 2.0 * float(d.h) / scale
        a.width = 2.0 * float(d.delta) / scale
    return check(a, y, v)


def read_budget(a):
    """y and the budget profiles of a.stats (of the windows in a.window if given), in u_tau^2 of
    the force balance. InputError if the file has no budget or no averaging window."""
    names = PARTS + ("total_stress", "total_stress_expected", "viscous_stress",
                     "pair_momentum_source", "momentum_change") + ALL
    with open_nc(a.stats) as d:
        need = ("pair_stress", "total_stress", "total_stress_expected", "pair_momentum_source") + \
            (("momentum_change",) if a.unsteady else ()) + \
            (("wall_term_stress", "viscous_pair_stress", "viscous_stress") if a.laminar else ())
        lack = [n for n in need if n not in d.variables]
        if lack:
            raise cli.InputError(f"{a.stats}: no momentum budget (no variable '{lack[0]}')")
        if a.window:
            y, v = extract_window(a, [n for n in names if n in d.variables])
        else:
            ut2 = attribute_or_nan(d, "u_tau_force") ** 2  # absent before the first window
            v = {n: np.ma.filled(d[n][:].astype(float), np.nan) / ut2
                 for n in d.variables if n in names}
            y = np.asarray(d["y"][:])
    if not np.isfinite(v["total_stress"]).any():  # also with u_tau_force NaN
        raise cli.InputError(f"{a.stats}: the budget has no value (no averaging window "
                             f"completed yet?)")
    return y, v


def extract_window(a, have):
    """y and the profiles have over the windows a.window, through chansph extract."""
    res = subprocess.run([a.chansph, "extract", a.stats, "--var", ",".join(have), "--units",
                          "outer", "--format", "csv", "--window", a.window],
                         capture_output=True, text=True)
    if res.returncode:
        raise cli.InputError("chansph extract --window %s: %s" % (a.window, res.stderr.strip()))
    out = res.stdout
    head = "".join(ln for ln in out.splitlines(True) if ln.startswith("#"))
    print(head, end="")
    m = re.search(r"force balance ([0-9.eE+-]+)", head)
    if not m:
        raise cli.InputError(f"{a.stats}: chansph extract names no force-balance u_tau")
    ut2 = float(m.group(1)) ** 2
    rows = list(csv.DictReader(io.StringIO("".join(ln for ln in out.splitlines(True)
                                                   if not ln.startswith("#")))))
    y = np.array([float(r["y"]) for r in rows])
    return y, {n: np.array([float(r[n]) for r in rows]) / ut2 for n in have}


def check(a, y, v):
    """Print the split of the stress and check it; returns the exit status."""
    parts = [n for n in PARTS if n in v]
    print("  y      " + " ".join(f"{n[:12]:>12}" for n in parts + ["total_stress",
                                                              "total_stress_expected"]))
    for i in range(len(y)):
        print(f"  {y[i]:.4f} " + " ".join(f"{v[n][i]:12.5f}" for n in parts + [
            "total_stress", "total_stress_expected"]))
    fail = 0
    s = sum(np.nan_to_num(v[n]) for n in parts)  # a NaN advective part is left out of the total
    dsum = np.nanmax(np.abs(s - v["total_stress"]))
    if not dsum <= (1e-6 if a.window else 1e-9):  # extract prints 9 significant digits
        print(f"FAIL: total_stress differs from the sum of its parts by {dsum:.3g}")
        fail = 1
    lhs = v["total_stress"] + (v["momentum_change"] if a.unsteady else 0.0)
    err = np.abs(lhs - v["total_stress_expected"])
    worst = int(np.nanargmax(err))
    print(f"closure: max |total{' + momentum_change' if a.unsteady else ''} - expected| = {err[worst]:.3g} u_tau^2 at y = {y[worst]:.4f} "
          f"(tolerance {a.tol}); momentum source {np.nanmean(v['pair_momentum_source']):.4f}")
    if not err[worst] <= a.tol:
        print("FAIL: the budget does not close")
        fail = 1
    if all(n in v and np.isfinite(v[n]).any() for n in ALL):  # format 1.14: every snapshot
        lhs = v["total_stress_all"] + (v["momentum_change_all"] if a.unsteady else 0.0)
        err = np.nanmax(np.abs(lhs - v["total_stress_expected_all"]))
        print(f"closure over every snapshot (total_stress_all): max {err:.3g} u_tau^2")
        if not err <= a.tol:
            print("FAIL: the budget over every snapshot does not close")
            fail = 1
    if a.laminar:
        for n in ("pair_stress", "reynolds_stress"):
            m = np.nanmax(np.abs(v[n]))
            if not m <= 0.005:
                print(f"FAIL: laminar flow with |{n}| up to {m:.3g} u_tau^2")
                fail = 1
        inner = (y > a.layer) & (y < a.width - a.layer)
        inner[0] = inner[-1] = False  # nu dU/dy is one-sided there
        dv = np.nanmax(np.abs(v["viscous_pair_stress"] - v["viscous_stress"])[inner])
        print(f"viscous pair stress vs nu dU/dy away from the walls: max difference {dv:.3g}")
        if not dv <= 0.01:
            print("FAIL: the viscous pair stress is not nu dU/dy")
            fail = 1
        src = np.nanmax(np.abs(v["pair_momentum_source"]))
        print(f"pair momentum source: max {src:.3g}; wall stress / driving force {a.tau_wall:.5f}")
        if not src <= 0.005:
            print("FAIL: the pair forces do not conserve momentum")
            fail = 1
        if not abs(a.tau_wall - 1.0) <= 0.01:
            print("FAIL: the wall stress is not the driving force")
            fail = 1
    return fail


if __name__ == "__main__":
    sys.exit(cli.run(main))
