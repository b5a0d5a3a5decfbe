#!/usr/bin/python3
"""Laminar channel validation of chansph against the analytical Poiseuille solutions.

Subcommands (each runs chansph, reads its netCDF output, prints the numbers, exits 1 on failure):
  steady SCENE --max-l2 E      steady u_mean against u = f y (2 delta - y) / (2 nu)
  startup SCENE --max-l2 E     u(y, t) from rest against the Fourier series at three times
  flux SCENE --max-rel E       bulk velocity of the flux controller Eq. 3.43 (and Eq. 3.38)
  longrun SCENE --steps N      N steps: no particle lost or through a wall, density drift, gamma
  convergence SCENE            error at 2 delta/dr = 20, 40, 80 and the observed order
  study SCENE2D SCENE3D --doc DIR   error against wall-clock time for four resolutions (PNG + table)
  stats SCENE --max-stress E   statistics engine on laminar flow: Reynolds stresses below
                               E u_bulk^2, shear-stress balance and u_tau within 1%
  localmean SCENE --max-stress E  bins of two particle layers (output.n_bins = 2 delta/dr/2 - 1):
                               the stresses about the bin mean hold the spread of U over the
                               bin, (U(y2) - U(y1))^2/4 within 5%; those about the local mean
                               U(y) (the default) fall below E u_bulk^2 (the lattice level)
  profile SCENE --max-l2 E     steady laminar flow with a prescribed eddy viscosity
                               nu_r(y) = nu (-1.6 s (1 - s) + 0.8 s^3), s = y/delta
                               (les.model = profile) against
                               its semi-analytical profile tau = f (delta - y) = (nu + nu_r) u'
  restart-finer SCENE --max-l2 E  start a run at dr/2 from the steady particles.nc of a run at
                               dr (init.from, Shepard interpolation): initial profile error
  smagorinsky SCENE --max-l2 E   steady laminar flow with the Smagorinsky model on, against the
                               semi-analytical profile of tau(y) = f (delta - y) =
                               (nu + l(y)^2 |u'|) u' with l = C_S Delta_G (1 - exp(-y+/A+))
"""
import argparse
import hashlib
import math
import os
import subprocess
import sys
import time

import netCDF4
import numpy as np


def run_cmd(args, scene, name, sets, extra=(), expect=0, threads=None):
    """Run chansph on a scene into RUNS/name (a directory per set of overrides: tests of one
    scene run in parallel); exit the check unless it ends with status expect."""
    if sets:
        name += "_" + hashlib.md5(" ".join(sets).encode()).hexdigest()[:8]
    out = os.path.join(args.runs, name)
    cmd = [args.chansph, "run", scene, "--out", out, "--overwrite"] + list(extra)
    for s in sets:
        cmd += ["--set", s]
    env = dict(os.environ)
    if threads:
        env["OMP_NUM_THREADS"] = str(threads)
    t0 = time.time()
    res = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.time() - t0
    if res.returncode != expect:
        sys.stdout.write(res.stdout[-3000:] + res.stderr[-3000:])
        sys.exit("FAIL: chansph exited with %d (expected %d): %s"
                 % (res.returncode, expect, " ".join(cmd)))
    return out, wall, res


def run(args, scene, name, sets, threads=None):
    out, wall, _ = run_cmd(args, scene, name, sets, threads=threads)
    return out, wall


def attrs(path):
    with netCDF4.Dataset(path) as d:
        return {k: d.getncattr(k) for k in d.ncattrs()}


def laminar(a, y, force=None):
    f = a["body_force"] if force is None else force
    return f * y * (2 * a["delta"] - y) / (2 * a["nu"])


def steady_error(out):
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        y, u = d["y_mean"][:].filled(np.nan), d["u_mean"][:].filled(np.nan)
    ua = laminar(a, y)
    ok = np.isfinite(u)
    return math.sqrt(np.sum((u[ok] - ua[ok]) ** 2) / np.sum(ua[ok] ** 2)), a


def cmd_steady(args):
    out, wall = run(args, args.scene, "steady_" + os.path.basename(args.scene)[:-4], args.set)
    err, a = steady_error(out)
    print("steady Poiseuille %dD, 2 delta/dr = %g: relative L2 error of u_mean = %.3e "
          "(limit %.3g), %.1f s wall" % (a["dimension"], 2 * a["delta"] / a["dr"], err,
                                         args.max_l2, wall))
    return err <= args.max_l2


def fourier(a, y, t, nterms=2001):
    H, nu, f = 2 * a["delta"], a["nu"], a["body_force"]
    u = laminar(a, y)
    for n in range(1, nterms, 2):
        u -= 4 * f * H * H / (nu * math.pi ** 3 * n ** 3) * np.sin(n * math.pi * y / H) * \
            math.exp(-n * n * math.pi ** 2 * nu * t / (H * H))
    return u


def cmd_startup(args):
    ok = True
    for t in (0.2, 0.5, 2.0):
        out, _ = run(args, args.scene, "startup_t%g" % t,
                     ["time.t_end=%g" % t, "init.profile=rest", "output.t_average_start=0"] + args.set)
        with netCDF4.Dataset(os.path.join(out, "particles.nc")) as d:
            a = attrs(os.path.join(out, "stats.nc"))
            tr, y, u = d.getncattr("time"), d["y"][:], d["u"][:]
        ua = fourier(a, y, tr)
        err = math.sqrt(np.sum((u - ua) ** 2) / np.sum(ua ** 2))
        print("start-up Poiseuille at t = %.4f s: relative L2 error %.3e (limit %.3g)" %
              (tr, err, args.max_l2))
        ok &= err <= args.max_l2
    return ok


def bulk_error(out):
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        t, ub = d["time"][:], d["u_bulk"][:]
    target = a["u_bulk_target"]
    late = t >= t[-1] - 0.2 * t[-1]
    rel = np.abs(ub[late] - target) / abs(target)
    return rel.max(), rel.mean(), a


def cmd_flux(args):
    out, _ = run(args, args.scene, "flux_eq343", ["drive.controller=eq3.43"] + args.set)
    e343, m343, a = bulk_error(out)
    out, _ = run(args, args.scene, "flux_eq338", ["drive.controller=eq3.38"] + args.set)
    e338, m338, _ = bulk_error(out)
    print("flux-driven Poiseuille, target u_bulk = %g, last 20%% of the run:" % a["u_bulk_target"])
    print("  Eq. 3.43: max relative error %.3e, mean %.3e (limit %.3g)" % (e343, m343, args.max_rel))
    print("  Eq. 3.38: max relative error %.3e, mean %.3e" % (e338, m338))
    print("  ratio of mean errors (3.38 / 3.43): %.3g" % (m338 / max(m343, 1e-300)))
    return e343 <= args.max_rel


def cmd_longrun(args):
    out, wall = run(args, args.scene, "longrun",
                    ["time.max_steps=%d" % args.steps, "time.t_end=1e9", "output.log_every=2000",
                     "output.series_every=100"] + args.set)
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        mass, vol, gmin = d["mass"][:], d["volume"][:], d["min_gamma"][:]
    with netCDF4.Dataset(os.path.join(out, "particles.nc")) as d:
        y, g, n = d["y"][:], d["gamma"][:], d.dimensions["particle"].size
    rho = mass / vol
    drift = abs(rho[-1] / rho[0] - 1)
    inside = np.all((y > 0) & (y < 2 * a["delta"]))
    print("%d steps (t = %.4g s, %.1f s wall): %d of %d particles inside the walls; mean "
          "density drift %.3e (limit 1e-3); gamma in [%.4f, %.4f] over the run, final max %.6f" %
          (a["steps"], a["t_reached"], wall, int(np.sum((y > 0) & (y < 2 * a["delta"]))),
           a["n_fluid"], drift, gmin.min(), np.max(g), np.max(g)))
    drift_max = np.abs(rho / rho[0] - 1).max()
    print("largest mean-density deviation from t = 0 over the run: %.3e" % drift_max)
    return (a["steps"] == args.steps and n == a["n_fluid"] and inside and drift_max < 1e-3 and
            gmin.min() >= 0.5 and np.max(g) <= 1.0)


def resolution_sets(scene_attrs_dim, dr0, lx0, lz0, k, laminar_start):
    """Scene overrides for 2 delta/dr = 20 * 2^k: lx, lz scaled with dr (flow is x-invariant)."""
    dr = dr0 / 2 ** k
    s = ["domain.dr=%.17g" % dr, "domain.lx=%.17g" % (lx0 / 2 ** k)]
    if scene_attrs_dim == 3:
        s.append("domain.lz=%.17g" % (lz0 / 2 ** k))
    if laminar_start:
        s += ["init.profile=laminar", "time.t_end=4", "output.t_average_start=3"]
    return s


def scene_values(scene):
    import configparser
    c = configparser.ConfigParser(inline_comment_prefixes=(";",))
    c.read(scene)
    d = c["domain"]
    return int(d["dimension"]), float(d["dr"]), float(d["lx"]), float(d.get("lz", "0"))


def cmd_convergence(args):
    dim, dr0, lx0, lz0 = scene_values(args.scene)
    errs = []
    for k in range(3):
        out, wall = run(args, args.scene, "conv%dd_%d" % (dim, k),
                        resolution_sets(dim, dr0, lx0, lz0, k, True) + args.set)
        e, a = steady_error(out)
        errs.append(e)
        print("%dD 2 delta/dr = %4d: relative L2 error %.3e  (%.1f s wall)" %
              (dim, round(2 * a["delta"] / a["dr"]), e, wall))
    orders = [math.log(errs[i] / errs[i + 1], 2) for i in range(2)]
    print("observed order: %.2f (20 -> 40), %.2f (40 -> 80), %.2f overall" %
          (orders[0], orders[1], 0.5 * (orders[0] + orders[1])))
    monotone = errs[1] < errs[0] and errs[2] < errs[1]
    print("error falls at each halving: %s" % ("yes" if monotone else "NO"))
    if args.require == "monotone":
        return monotone
    return errs[2] < errs[0]


def cmd_study(args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = []
    for scene in (args.scene, args.scene3d):
        dim, dr0, lx0, lz0 = scene_values(scene)
        for k in (range(4) if dim == 2 else range(-1, 3)):  # 3-D: 2 delta/dr = 10 .. 80
            sets = resolution_sets(dim, dr0, lx0, lz0, k, False)
            out, wall = run(args, scene, "study%dd_%d" % (dim, k), sets + args.set)
            e, a = steady_error(out)
            rows.append((dim, round(2 * a["delta"] / a["dr"]), int(a["n_fluid"]), int(a["steps"]),
                         wall, e))
            print("%dD 2delta/dr=%d particles=%d steps=%d wall=%.1f s L2=%.3e" % rows[-1])
    os.makedirs(args.doc, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for dim, mk in ((2, "o-"), (3, "s-")):
        r = [x for x in rows if x[0] == dim]
        ax.loglog([x[4] for x in r], [x[5] for x in r], mk, label="%d-D" % dim)
        for x in r:
            ax.annotate("%d" % x[1], (x[4], x[5]), textcoords="offset points", xytext=(4, 4),
                        fontsize=8)
    ax.set_xlabel("wall-clock time on 2 cores [s]")
    ax.set_ylabel("relative L2 error of u_mean")
    ax.set_title("Poiseuille, Re = 10, from rest to t = 12 (labels: 2 delta / dr)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.doc, "poiseuille_error_vs_time.png"), dpi=120)
    with open(os.path.join(args.doc, "poiseuille_study.md"), "w") as f:
        f.write("| dim | 2 delta/dr | fluid particles | steps | wall [s] | rel. L2 error |\n")
        f.write("|---|---|---|---|---|---|\n")
        for x in rows:
            f.write("| %d | %d | %d | %d | %.1f | %.3e |\n" % x)
    return True


def cmd_stats(args):
    out, wall = run(args, args.scene, "stats_" + os.path.basename(args.scene)[:-4], args.set)
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        ub = float(d["u_bulk"][-1])
        stress = {n: np.ma.filled(d[n][:].astype(float), np.nan) for n in
                  ("uu", "vv", "ww", "uv", "uw", "vw")}
    worst = max(np.nanmax(np.abs(v)) for v in stress.values()) / ub ** 2
    which = max(stress, key=lambda n: np.nanmax(np.abs(stress[n])))
    bal = float(a["stress_balance_error"])
    dut = abs(a["u_tau_wall"] - a["u_tau_force"]) / a["u_tau_force"]
    print("laminar statistics %dD, %d windows of %.3g s: max |Reynolds stress| = %.3e u_bulk^2 "
          "(%s; limit %.3g): the method's velocity noise" %
          (a["dimension"], a["n_windows"], a["window_length"], worst, which, args.max_stress))
    print("shear-stress balance: max |nu dU/dy - <u'v'> - tau_w/rho (1 - y/delta)| = %.3e "
          "tau_w/rho (limit 0.01)" % bal)
    print("u_tau from the wall shear %.6g, from the force balance %.6g: %.3e relative "
          "(limit 0.01); correlation time %.3g s" % (a["u_tau_wall"], a["u_tau_force"], dut,
                                                     a.get("correlation_time", np.nan)))
    return worst < args.max_stress and bal < 0.01 and dut < 0.01


def cmd_localmean(args):
    """Bins that each hold two particle layers (the middle one three): the spread of the mean
    over a bin is known exactly, and the stresses about the local mean must not hold it."""
    out0, _ = run(args, args.scene, "stats_" + os.path.basename(args.scene)[:-4], args.set)
    a0 = attrs(os.path.join(out0, "stats.nc"))
    layers = int(round(2 * a0["delta"] / a0["dr"])) - 1  # walls at 0, 2 delta; layers j dr
    nb = (layers - 1) // 2
    out, _ = run(args, args.scene, "localmean_" + os.path.basename(args.scene)[:-4],
                 args.set + ["output.n_bins=%d" % nb])
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        ub = float(d["u_bulk"][-1])
        v = {n: np.ma.filled(d[n][:].astype(float), np.nan) for n in
             ("uu", "uu_bin", "uv", "uv_bin", "local_mean", "y_bounds")}
    yl = a["dr"] * np.arange(1, layers + 1)
    ok = int(a["local_mean"]) == 1 and np.all(v["local_mean"] == 1)
    print("%d bins over %d layers; local_mean = %d" % (nb, layers, a["local_mean"]))
    for b in range(nb):
        lo, hi = v["y_bounds"][b]
        inside = yl[(yl > lo) & (yl < hi)]
        if len(inside) != 2:
            print("  bin %d: %d layers (not checked)" % (b, len(inside)))
            continue
        ua = laminar(a, inside)
        spread = (ua[1] - ua[0]) ** 2 / 4
        rel = v["uu_bin"][b] / spread - 1
        good = abs(rel) < 0.05 and abs(v["uu"][b]) < args.max_stress * ub ** 2
        print("  bin %d (layers %.3g, %.3g): uu about the bin mean %.4e u_bulk^2 (exact spread "
              "%.4e, %+.1f%%), about U(y) %.3e u_bulk^2 (limit %.3g), uv %.2e (bin mean %.2e): %s"
              % (b, inside[0], inside[1], v["uu_bin"][b] / ub ** 2, spread / ub ** 2, 100 * rel,
                 v["uu"][b] / ub ** 2, args.max_stress, v["uv"][b] / ub ** 2,
                 v["uv_bin"][b] / ub ** 2, "ok" if good else "FAIL"))
        ok &= good
    return bool(ok)


def scene_attr(out, section, key):
    """A value of the resolved scene stored in stats.nc."""
    text = attrs(os.path.join(out, "stats.nc"))["scene"]
    part = text.split("[%s]" % section, 1)[1].split("\n[", 1)[0]
    for line in part.splitlines():
        if "=" in line and line.split("=")[0].strip() == key:
            return line.split("=", 1)[1].strip()
    raise KeyError(key)


def smagorinsky_profile(a, out, y):
    """u(y) of the steady channel with nu + nu_r, nu_r = l^2 |u'| (thesis Eq. 5.46-5.47, 5.50)."""
    f, delta, nu = a["body_force"], a["delta"], a["nu"]
    h = float(scene_attr(out, "sph", "h_over_dr")) * float(scene_attr(out, "domain", "dr"))
    cs = float(scene_attr(out, "les", "cs"))
    dg = float(scene_attr(out, "les", "filter_width")) * h
    damp = int(scene_attr(out, "les", "van_driest"))
    aplus = float(scene_attr(out, "les", "a_plus"))
    utau = math.sqrt(f * delta)
    yy = np.linspace(0.0, delta, 200001)
    tau = f * (delta - yy)
    l = cs * dg * ((1.0 - np.exp(-yy * utau / nu / aplus)) if damp else np.ones_like(yy))
    du = 2.0 * tau / (nu + np.sqrt(nu * nu + 4.0 * l * l * tau))
    u = np.concatenate(([0.0], np.cumsum(0.5 * (du[1:] + du[:-1]) * np.diff(yy))))
    return np.interp(np.minimum(y, 2 * delta - y), yy, u)


def cmd_restart_finer(args):
    coarse, _ = run(args, args.scene, "coarse_" + os.path.basename(args.scene)[:-4], args.set)
    dr = float(scene_attr(coarse, "domain", "dr"))
    fine, _ = run(args, args.scene, "finer_" + os.path.basename(args.scene)[:-4],
                  args.set + ["domain.dr=%.17g" % (dr / 2), "time.max_steps=1",
                              "init.from=" + os.path.join(coarse, "particles.nc")])
    a = attrs(os.path.join(coarse, "stats.nc"))
    with netCDF4.Dataset(os.path.join(fine, "particles.nc")) as d:
        y, u = d["y"][:], d["u"][:]
    ua = laminar(a, y)
    err = math.sqrt(np.sum((u - ua) ** 2) / np.sum(ua ** 2))
    print("finer run (dr %.4g -> %.4g, %d particles) started from the coarse particles.nc: "
          "relative L2 error of u against the steady profile %.3e (limit %.3g)"
          % (dr, dr / 2, len(y), err, args.max_l2))
    return err <= args.max_l2


def model_channel(args, name, sets, exact, what):
    """Run the steady channel with the extra keys sets and compare u_mean with exact(a, out, y)
    (a: the stats.nc attributes); pass if the relative L2 error is within --max-l2 and the
    model moves the profile from the laminar one by more than 5 times the error."""
    out, wall = run(args, args.scene, name + "_" + os.path.basename(args.scene)[:-4], sets)
    with netCDF4.Dataset(os.path.join(out, "stats.nc")) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
        y, u = d["y_mean"][:].filled(np.nan), d["u_mean"][:].filled(np.nan)
    ua = exact(a, out, y)
    ok = np.isfinite(u)
    err = math.sqrt(np.sum((u[ok] - ua[ok]) ** 2) / np.sum(ua[ok] ** 2))
    ul = laminar(a, y)
    shift = math.sqrt(np.sum((ul[ok] - ua[ok]) ** 2) / np.sum(ua[ok] ** 2))
    print("%s %dD (%s): relative L2 error of u_mean = %.3e (limit %.3g); the model moves the "
          "profile by %.3e from the laminar one; %.1f s wall"
          % (what, a["dimension"], " ".join(args.set), err, args.max_l2, shift, wall))
    return err <= args.max_l2 and shift > 5 * err


def cmd_smagorinsky(args):
    return model_channel(args, "smagorinsky", ["les.model=smagorinsky", "sph.viscous=violeau"]
                         + args.set, smagorinsky_profile, "Smagorinsky channel")


def cmd_profile(args):
    """les.model = profile: a prescribed nu_r / nu = g(s), s = y / delta (here -1.6 s (1 - s) +
    0.8 s^3 at 21 points, linear between them: 0 at the walls, -0.33 at s = 0.39, 0.8 at the
    centre); the steady profile is u' = f (delta - y) / (nu (1 + g)), integrated on a fine grid
    with the same linear table."""
    os.makedirs(args.runs, exist_ok=True)
    table = os.path.join(os.path.abspath(args.runs), "nu_profile_cubic.txt")
    yt = np.linspace(0.0, 1.0, 21)
    gt = -1.6 * yt * (1.0 - yt) + 0.8 * yt ** 3
    with open(table, "w") as f:
        f.write("# nu_r / nu = -1.6 s (1 - s) + 0.8 s^3, s = y / delta (poiseuille_check.py)\n"
                "y_over_delta, nu_r_over_nu\n")
        f.writelines("%.17g, %.17g\n" % (a, b) for a, b in zip(yt, gt))

    def exact(a, out, y):
        f, delta, nu = a["body_force"], a["delta"], a["nu"]
        yy = np.linspace(0.0, delta, 200001)
        du = f * (delta - yy) / (nu * (1.0 + np.interp(yy / delta, yt, gt)))
        uu = np.concatenate(([0.0], np.cumsum(0.5 * (du[1:] + du[:-1]) * np.diff(yy))))
        return np.interp(np.minimum(y, 2 * delta - y), yy, uu)

    sets = ["les.model=profile", "les.profile=" + table, "sph.viscous=violeau"] + args.set
    return model_channel(args, "profile", sets, exact,
                         "channel with the prescribed nu_r(y) of " + table + ",")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--chansph", default="build/chansph")
    p.add_argument("--runs", default="build/test-runs")
    p.add_argument("what", choices=["steady", "startup", "flux", "longrun", "convergence", "study",
                                    "stats", "localmean", "smagorinsky", "profile",
                                    "restart-finer"])
    p.add_argument("scene")
    p.add_argument("scene3d", nargs="?")
    p.add_argument("--max-l2", type=float, default=0.01)
    p.add_argument("--max-rel", type=float, default=1e-5)
    p.add_argument("--max-stress", type=float, default=1e-4)
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--doc", default="docs/validation")
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--require", choices=["monotone", "overall"], default="monotone",
                   help="convergence: error falls at each halving, or from dr to dr/4")
    args = p.parse_args()
    os.makedirs(args.runs, exist_ok=True)
    ok = globals()["cmd_" + args.what.replace("-", "_")](args)
    print("PASS" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
