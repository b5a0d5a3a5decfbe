#!/usr/bin/python3
"""Stability on stiff and extreme cases (issue 3; docs/stability.md). Each subcommand runs
chansph, prints its numbers and exits 1 unless the case ends with a correct result or with the
specific error it must give.

  viscous      Re = 0.1 Poiseuille, dt set by the viscous limit: profile within --max-l2
  impact       a particle thrown at a wall at c0/2 (--speed): no penetration, gamma sane, run
               healthy; or (--expect-through) exit 3 naming that particle
  mach         the same channel at Ma = 0.1 and 0.3: density variation reported, no blow-up
  flux-step    a flux-driven channel whose target doubles (and halves) suddenly: converges
  les5200      coarse LES at Re_tau = 5200: 1000 steps with finite fields
  nan          a NaN injected into one particle after step 60: exit 3 at that step's health
               check, naming step, particle id and position; stats.nc written before is kept

--set KEY=VALUE (repeatable) runs a case with another scheme, e.g. the turbulent runs' (Wendland
C4 at h = 2 dr with the volume diffusion at the delta-SPH strength): every run of the case gets
it, and the viscous case's time-step limit is computed with its h.
"""
import argparse
import hashlib
import os
import re
import sys

import netCDF4
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import poiseuille_check as pc  # noqa: E402  (shared run helper and profile error)


def run(args, scene, name, sets, extra=(), expect=0):
    out, _, res = pc.run_cmd(args, scene, "stability_" + name, list(sets) + args.sets, extra,
                             expect)
    return out, res


def series(out, name):
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        return d[name][:].filled(np.nan)


def profile_error(out):
    return pc.steady_error(out)[0]


def cmd_viscous(args):
    # u_max = f (2 delta)^2 / (8 nu) = 1 m/s with nu = 10: Re = u_max 2 delta / nu = 0.1
    out, res = run(args, args.scene, "viscous",
                   ["fluid.nu=10", "drive.force=80", "time.t_end=0.1",
                    "output.t_average_start=0.08", "output.log_every=100000"])
    dt = series(out, "dt")
    err = profile_error(out)
    h_over_dr = 1.3  # the default of sph.h_over_dr; poiseuille2d.ini has dr = 0.05
    for kv in args.sets:
        if kv.startswith("sph.h_over_dr="):
            h_over_dr = float(kv.split("=", 1)[1])
    h = h_over_dr * 0.05
    print("Re = 0.1: dt = %.3e s (viscous limit 0.125 h^2/nu = %.3e s, acoustic %.3e s), "
          "%d steps, relative L2 error of u_mean %.3e (limit %.3g)"
          % (dt[-1], 0.125 * h * h / 10, 0.8 * h / 10, round(0.1 / dt[-1]), err, args.max_l2))
    return err <= args.max_l2 and abs(dt[-1] - 0.125 * h * h / 10) < 1e-12


def cmd_impact(args):
    # the files of this variant (speed, expectation, overrides) apart from the others': tests
    # of one scene run in parallel
    tag = "%g%s" % (args.speed, "_through" if args.expect_through else "")
    base, _ = run(args, args.scene, "impact_base_" + tag,
                  ["time.t_end=0.0052", "output.t_average_start=0", "output.log_every=1"])
    src = os.path.join(base, "particles.nc")
    tag += "_" + hashlib.md5(" ".join(args.sets).encode()).hexdigest()[:8]
    mod = os.path.join(args.runs, "stability_impact_start_%s.nc" % tag)
    c0 = 10.0
    with netCDF4.Dataset(src) as d, netCDF4.Dataset(mod, "w") as o:
        for k in d.ncattrs():
            o.setncattr(k, d.getncattr(k))
        for name, dim in d.dimensions.items():
            o.createDimension(name, len(dim))
        for name, var in d.variables.items():
            v = o.createVariable(name, var.dtype, var.dimensions)
            v.setncatts({k: var.getncattr(k) for k in var.ncattrs()})
            v[:] = var[:]
        y = d["y"][:]
        who = int(np.argmin(y))
        o["v"][who] = -args.speed * c0  # straight at the wall y = 0
        pid, y0 = int(d["id"][who]), float(y[who])
    what = "particle %d at y = %.4f thrown at the wall at %g c0 = %g m/s" % (
        pid, y0, args.speed, args.speed * c0)
    sets = ["init.from=" + mod, "time.t_end=0.2", "output.t_average_start=0",
            "output.log_every=1"]
    if args.expect_through:  # the scheme cannot stop it: a clear report, not a silent state
        out, res = run(args, args.scene, "impact_" + tag, sets, expect=3)
        text = res.stderr + res.stdout
        m = re.search(r"particle through a wall at step (\d+) \(t = [^)]*\): particle id (\d+) "
                      r"at \([^)]*\), velocity \([^)]*\)", text)
        print("%s: %s" % (what, m.group(0) if m else text[-500:]))
        return bool(m) and int(m.group(2)) == pid
    out, res = run(args, args.scene, "impact_" + tag, sets)
    gmin = series(out, "min_gamma")
    with netCDF4.Dataset(os.path.join(out, "particles.nc")) as d:
        ymin = float(d["y"][:].min())
    refl = re.findall(r"reached the (?:lower|upper) wall", res.stderr)
    print("%s: no health report, %d wall reflections, smallest y at the end %.4e m, min gamma "
          "over the run %.4f" % (what, len(refl), ymin, np.nanmin(gmin)))
    return ymin > 0.0 and np.nanmin(gmin) > 0.5


def cmd_mach(args):
    ok = True
    for c0, mach in ((10.0, 0.1), (10.0 / 3.0, 0.3)):
        out, res = run(args, args.scene, "mach%g" % mach,
                       ["fluid.c0=%.17g" % c0, "output.log_every=100000"])
        rmin, rmax = series(out, "rho_min"), series(out, "rho_max")
        err = profile_error(out)
        var = (np.nanmax(rmax) - np.nanmin(rmin)) / 1000.0
        print("Ma = %.1f (c0 = %.4g m/s): density range over the run [%.2f, %.2f] kg/m^3 "
              "(%.2f%% of rho0; Ma^2 = %.2f%%), relative L2 error of u_mean %.3e"
              % (mach, c0, np.nanmin(rmin), np.nanmax(rmax), 100 * var, 100 * mach * mach, err))
        ok &= bool(np.isfinite(var)) and err < 0.05
    return ok


def cmd_flux_step(args):
    base, _ = run(args, args.scene, "flux_base", ["output.log_every=100000"])
    src = os.path.join(base, "particles.nc")
    ok = True
    for factor in (2.0, 0.5):
        target = 0.7 * factor
        out, _ = run(args, args.scene, "flux_step%g" % factor,
                     ["init.from=" + src, "drive.u_bulk=%.17g" % target, "time.t_end=12",
                      "output.log_every=100000"])
        t, ub = series(out, "time"), series(out, "u_bulk")
        late = t >= 0.8 * t[-1]
        rel = np.max(np.abs(ub[late] - target)) / target
        t90 = t[np.argmax(np.abs(ub - target) <= 0.1 * abs(target - 0.7))]
        print("target %.2f -> %.2f m/s: within 10%% of the step after %.3f s; over the last 20%% "
              "of the run max relative error %.2e (limit %.1e)" % (0.7, target, t90, rel,
                                                                 args.max_rel))
        ok &= rel <= args.max_rel
    return ok


def cmd_les5200(args):
    out, res = run(args, args.scene, "les5200",
                   ["fluid.nu=%.17g" % (1 / 5200.0), "fluid.c0=270", "time.max_steps=1000",
                    "output.log_every=250"])
    speed, rmin, rmax = series(out, "max_speed"), series(out, "rho_min"), series(out, "rho_max")
    finite = all(np.all(np.isfinite(a)) for a in (speed, rmin, rmax))
    steps = int(re.search(r"finished: (\d+) steps", res.stdout).group(1))
    print("Re_tau = 5200 LES, dr = 0.1 delta (Delta+ = 520): %d steps, max speed %.2f m/s, "
          "density [%.1f, %.1f], all finite: %s" % (steps, np.nanmax(speed), np.nanmin(rmin),
                                                    np.nanmax(rmax), finite))
    return finite and steps == 1000


def cmd_nan(args):
    out, res = run(args, args.scene, "nan", ["output.write_every=0.05", "output.log_every=10"],
                   extra=["--inject-nan", "60:7"], expect=3)
    text = res.stderr + res.stdout
    m = re.search(r"non-finite value at step (\d+) \(t = [^)]*\): particle id (\d+) at \(", text)
    print("NaN injected into particle 7 after step 60: %s" % (m.group(0) if m else text[-500:]))
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        t_kept = float(d["time"][-1])
    print("stats.nc kept, readable, last record at t = %.4f s" % t_kept)
    return bool(m) and int(m.group(1)) == 60 and t_kept > 0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--chansph", default="build/chansph")
    p.add_argument("--runs", default="build/test-runs")
    p.add_argument("what", choices=["viscous", "impact", "mach", "flux-step", "les5200", "nan"])
    p.add_argument("scene")
    p.add_argument("--max-l2", type=float, default=0.01)
    p.add_argument("--max-rel", type=float, default=1e-3)
    p.add_argument("--speed", type=float, default=0.5,
                   help="impact: the thrown particle's speed towards the wall in units of c0")
    p.add_argument("--expect-through", action="store_true",
                   help="impact: the scheme cannot stop it; expect exit 3 naming the particle")
    p.add_argument("--set", action="append", default=[], dest="sets", metavar="KEY=VALUE",
                   help="a scene override for every run of the case (repeatable)")
    args = p.parse_args()
    os.makedirs(args.runs, exist_ok=True)
    ok = globals()["cmd_" + args.what.replace("-", "_")](args)
    print("PASS" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
