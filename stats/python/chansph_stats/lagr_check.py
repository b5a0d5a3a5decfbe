"""The Lagrangian engine of a run (group lagrangian) against exact laws and the Eulerian engine.

usage: chansph-stats lagr_check STATS.nc [--ckpt CKPT.h5] [--out DIR] [--u-tau force|wall|V]
       [--sample-interval S]

Per release level (y of group lagrangian; the Eulerian values are the root profiles
interpolated to it):

1. Taylor's short-time dispersion: sigma_i^2(tau) / tau^2 -> <u_i'^2> at the release height.
   Taken at the first lag with samples. The engine samples lag k at the first statistics
   sample at or after k horizon / n_lags, so the real lag is up to one sampling interval later
   than the nominal one. Files of checkpoint format 1.9 on hold the mean real lag of the
   samples of each lag (lag_time_mean of group lagrangian), which is then the lag everywhere
   (points 1-4; the output says so). For older files (or a run resumed from a checkpoint of
   format 1.8 or older, whose lag_time_mean are fill values) the real lag lies between tau_k
   and tau_k + ds with ds the sampling interval (output.stats_every steps of dt = t_reached /
   steps, from the scene and attributes of the file; --sample-interval overrides, 0 uses the
   nominal lags): point 1 brackets it, or with --ckpt takes it from the x clock below.
   The mean drift is removed: sigma_i^2 is <dr_i^2>, not a variance. Files of this version hold
   the displacement variance about the mean displacement (disp_var_x, _y, _z of group
   lagrangian; since checkpoint format 1.7), which is used as it is. With --ckpt the
   checkpoint's sums give the clock below and <dx>^2 = (tau (<u(t0)> + <u(t0 + tau)>) / 2)^2 is
   subtracted; for older files without --ckpt (or a run resumed from a checkpoint of format
   1.6, whose disp_var_* are fill values) the Eulerian U(y0) stands in for the mean drift of x.
   lag_time_mean is the mean real lag; each release has its own (all its particles are sampled
   at one step), within one sampling interval ds of the nominal lag, so the variance about the
   mean displacement also holds D^2 var(tau_r) (D the mean drift velocity: U(y0) in x, about
   0 in y and z), which the check bounds by D^2 (m - tau_k)(tau_k + ds - m), m the mean real
   lag, and removes as a range (it matters in x only: 17^2 x 1e-6 s^2 against tau^2 = 4e-5 s^2).
   Files of checkpoint format 1.10 on hold the variance of the interval-mean velocity
   (r_i(t0 + tau) - r_i(t0)) / tau with each sample over its own real lag (rate_var_x, _y, _z):
   drift and lag spread both gone, it is compared with <u_i'^2> directly (a sharp test in x).
   Standard error: stats.nc holds only the sums over all releases, no per-release values, so it
   is modelled: a release samples N = n_tracks / releases particles on a line along z (and
   its mirror); their u_i^2 has variance (F - 1) <u_i'^2>^2 (F the Eulerian flatness) and
   correlation rho_ii,z(dz)^2 along the line (Gaussian rule; rho from group correlations at the
   nearest level), so the N particles count as N / S, S = sum over the grid's z separations of
   rho_ii,z^2; releases closer than twice the Lagrangian integral time T of the component
   (rho_L integrated to its first zero: the lifetime of the eddies that carry the particles;
   the file's Eulerian correlation_time when T is unknown) count as independent only in the
   ratio release_every / (2 T). For x the term 2 U <u'> adds 2 U u_rms / sqrt(N_eff) when the
   Eulerian U stands in for the mean drift. The Eulerian standard error of <u_i'^2> is added in
   quadrature. PASS within two standard errors.
2. Taylor's whole curve, sigma^2(tau) = 2 <u_i'^2> int_0^tau (tau - s) rho_L(s) ds (y and z; the
   ratio at 1/4, 1/2 and all of the horizon), and the long-time law
   d sigma^2 / d tau = 2 <u_i'^2> T_L over the last third of the horizon, checked only
   where the horizon exceeds 3 T_L (else "not reached"); in y the walls bound the dispersion.
3. The Lagrangian mean velocity <u(t0)> of the releases equals the Eulerian U(y0) within two
   standard errors (u_rms / sqrt(N_eff)): from u_release_mean and u_lag_mean of group
   lagrangian, or from the checkpoint's sums (--ckpt; needed for files written before
   checkpoint format 1.7, which have no Lagrangian mean). The mean displacement <dx>(tau)
   (disp_mean_x) is reported against tau times the mean of <u(t0)> and <u(t0 + tau)>.
4. T_L per level and component: the integral of rho_L to its first zero (or to the horizon,
   marked), the engine's T_L (e^-1/2 rule, Eq. 5.61) and its per-release mean and standard
   error (each release a batch), in s and wall units.
5. The dispersion PDFs P(y; x) of the stations: mean, standard deviation, tracks; with --out,
   lagr_pdf_y.png (and lagr_dispersion.png, lagr_rho.png).
Exit status 1 when a check of point 1 or 3 fails.
"""
import math
import os
import re

import numpy as np

from . import cli
from .cli import InputError
from .ncfile import attribute, need, need_group, open_nc, values
from .twopoint import out_dir, pick_u_tau, pyplot, save, u_tau_arg

COMP = ("u", "v", "w")
POS = ("x", "y", "z")
# layout of stats/lagrangian/sums (stats/lagr.h): n, then per u, v, w [S0, St, S00, Stt, S0t];
# records of 43 sums up to checkpoint format 1.6, 46 (the sums of dr added at the end) in 1.7-1.8,
# 47 (the sum of the actual lags added at the end) from 1.9
LG_N, LG_VEL, LG_LENS = 0, 1, (43, 46, 47, 53)
# Lagrangian means in group lagrangian (from checkpoint format 1.7 on)
MEANS = ["%s_release_mean" % c for c in COMP] + ["%s_lag_mean" % c for c in COMP] + \
    ["disp_mean_" + p for p in POS] + ["disp_var_" + p for p in POS]


def read_run(path, how):
    with open_nc(path) as nc:
        g = need_group(nc, "lagrangian", path)
        r = {k: values(need(g, k, path)) for k in
             ["level", "y_plus", "lag", "n_tracks", "T_L", "T_L_release_mean", "T_L_stderr"] +
             ["sigma2_" + p for p in POS] + ["rho_L_" + c for c in COMP]}
        r["releases"] = int(attribute(g, "releases", path))
        r["horizon"] = float(attribute(g, "horizon", path))
        r["release_every"] = float(attribute(g, "release_every", path))
        r["means"] = all(k in g.variables for k in MEANS)
        # the mean real lag of the samples (checkpoint format 1.9 on)
        r["lag_time"] = values(g.variables["lag_time_mean"]) \
            if "lag_time_mean" in g.variables else None
        # the variance of the interval-mean velocity dr / tau (checkpoint format 1.10 on)
        r["rate_var"] = {p: values(g.variables["rate_var_" + p]) for p in POS} \
            if all("rate_var_" + p in g.variables for p in POS) else None
        if r["means"]:
            for k in MEANS:
                r[k] = values(g.variables[k])
        r["stations"] = "station" in g.variables and "pdf_y" in g.variables
        if r["stations"]:
            for k in ("station", "pdf_bin", "pdf_y", "pdf_mu_y", "pdf_var_y", "pdf_count"):
                r[k] = values(need(g, k, path))
        e = {k: values(need(nc, k, path)) for k in
             ("y_mean", "n_samples", "u_mean", "u_mean_stderr", "uu", "vv", "ww", "uu_stderr", "vv_stderr",
              "ww_stderr", "u_flatness", "v_flatness", "w_flatness")}
        r["eul"] = e
        for k in ("nu", "delta", "lz", "dr"):
            r[k] = float(attribute(nc, k, path))
        r["u_tau"] = pick_u_tau(nc, path, how)
        r["corr_time"] = float(nc.getncattr("correlation_time")) \
            if "correlation_time" in nc.ncattrs() else math.nan
        r["ds"] = sample_interval(nc)
        r["corr"] = None
        if "correlations" in nc.groups:
            c = nc.groups["correlations"]
            r["corr"] = {k: values(c.variables[k]) for k in
                         ("y_plus", "level", "rho_uu_z", "rho_vv_z", "rho_ww_z")
                         if k in c.variables}
    if r["releases"] < 1:
        raise InputError("%s: group lagrangian has no completed release (run longer than "
                         "lagrangian.horizon = %g s)" % (path, r["horizon"]))
    return r


def sample_interval(nc):
    """output.stats_every x dt, dt = t_reached / steps, from the file; NaN if unknown."""
    try:
        m = re.search(r"^stats_every\s*=\s*([0-9]+)", nc.getncattr("scene"), re.M)
        return int(m.group(1)) * float(nc.getncattr("t_reached")) / int(nc.getncattr("steps"))
    except (AttributeError, KeyError, ValueError, ZeroDivisionError, TypeError):
        return math.nan


def read_ckpt(path, r):
    """The Lagrangian sums of a checkpoint; its completed releases must be the file's."""
    from .ckpt import open_h5
    with open_h5(path) as f:
        for k in ("stats/lagrangian/sums", "stats/lagrangian/releases"):
            if k not in f:
                raise InputError("%s: no dataset '%s' (not a checkpoint of a run with the "
                                 "Lagrangian engine?)" % (path, k))
        sums = np.asarray(f["stats/lagrangian/sums"][()])
        rel = int(np.asarray(f["stats/lagrangian/releases"][()]).ravel()[0])
    want = [(len(r["level"]), len(r["lag"]), n) for n in LG_LENS]
    if sums.shape not in want:
        raise InputError("%s: stats/lagrangian/sums has shape %s, the stats.nc needs %s" %
                         (path, sums.shape, " or ".join(str(w) for w in want)))
    if rel != r["releases"]:
        raise InputError("%s: %d completed releases, the stats.nc %d: not the same state (use "
                         "the checkpoint written with it, e.g. the final one)" %
                         (path, rel, r["releases"]))
    return sums


def real_lags(r, ds):
    """The lags the samples were taken at, on average: lag k > 0 is the first statistics sample
    at or after tau_k, so tau_k + ds / 2 (ds: the mean sampling interval; dt varies in a run)."""
    tau = np.array(r["lag"], dtype=float)
    if ds > 0:
        tau[1:] += ds / 2
    return tau


def level_lags(r, l, t):
    """The lags of level l: lag_time_mean of the file (the mean real lag of the samples) at the
    lags with samples, t elsewhere; and how they were found (None: not in the file, or fill
    values at a lag with samples: a run resumed from a checkpoint of format 1.8 or older)."""
    if r["lag_time"] is None:
        return t, None
    m, has = r["lag_time"][l], r["n_tracks"][l] > 0
    if not has.any() or not np.all(np.isfinite(m[has])):
        return t, None
    return np.where(has, m, t), "lag_time_mean"


def eulerian_at(r, y):
    e = r["eul"]
    ok = e["n_samples"] > 0
    return {k: float(np.interp(y, e["y_mean"][ok], v[ok])) for k, v in e.items()}


def line_factor(r, y, c):
    """S = sum over the z separations of rho_cc,z^2 at the correlation level nearest to y (the
    particles of a release line count as N / S); the number of z grid points (a fully
    correlated line) when there is no correlation level within 10% + 1 wall unit."""
    nz = max(1, int(round(r["lz"] / r["dr"])))
    cr = r["corr"]
    if not cr or "rho_%s%s_z" % (c, c) not in cr:
        return float(nz), "no correlations: line fully correlated"
    yp = y * r["u_tau"] / r["nu"]
    ylev = cr["level"] * r["u_tau"] / r["nu"]
    i = int(np.argmin(np.abs(ylev - yp)))
    if abs(ylev[i] - yp) > 0.1 * yp + 1.0:
        return float(nz), "no correlation level near: line fully correlated"
    rho = cr["rho_%s%s_z" % (c, c)][i]
    if not np.all(np.isfinite(rho)):
        return float(nz), "correlation level without samples: line fully correlated"
    return float(np.sum(rho ** 2)), "rho_%s%s_z at y+ %.0f" % (c, c, ylev[i])


def first_zero_integral(t, rho):
    """int rho dt to its first zero (linear interpolation), or to the last lag; and whether it
    reached the zero."""
    ok = np.isfinite(rho)
    t, rho = t[ok], rho[ok]
    neg = np.nonzero(rho <= 0)[0]
    if len(neg) and neg[0] > 0:
        i = neg[0]
        tz = t[i - 1] + rho[i - 1] / (rho[i - 1] - rho[i]) * (t[i] - t[i - 1])
        tt = np.append(t[:i], tz)
        rr = np.append(rho[:i], 0.0)
        return float(np.trapz(rr, tt)), True
    return float(np.trapz(rho, t)), False


def taylor_curve(t, rho, var):
    """2 var int_0^tau (tau - s) rho(s) ds at every t (trapezoidal)."""
    out = np.zeros(len(t))
    for k in range(1, len(t)):
        out[k] = 2 * var * np.trapz((t[k] - t[:k + 1]) * rho[:k + 1], t[:k + 1])
    return out


def release_se(r, l, nper, c, E):
    """Modelled standard error of a release-ensemble mean of u_i^2 (module docstring)."""
    S, how = line_factor(r, r["level"][l], c)
    T = r["tl_now"].get(c, math.nan)
    g = max(1.0, 2 * T / r["release_every"]) if T == T else r["g"]
    neff = nper / max(S, 1.0) / g
    F = E[c + "_flatness"]
    return E[c + c] * math.sqrt(max(F - 1.0, 0.0) / neff), neff, how + ", releases / %.2g" % g


def release_test(r, l, nper, c, E, value):
    """The modelled standard error of value (a release-ensemble <u_i'^2>) with the Eulerian one
    in quadrature, and whether value is within two of them of the Eulerian <u_i'^2>."""
    se, neff, how = release_se(r, l, nper, c, E)
    se = math.hypot(se, np.nan_to_num(E[c + c + "_stderr"]))
    return se, neff, how, abs(value - E[c + c]) <= 2 * se


def lag_jitter(r, l, k, p, real):
    """The most that the spread of the real lags can add to the displacement variance of axis p
    at lag k of level l. All particles of a release are sampled at one step, so each release
    has its own real lag tau_r in [tau_k, tau_k + ds); the displacement about the ensemble mean
    then holds D^2 var(tau_r), D the mean drift velocity, and a variable on that interval with
    mean m = lag_time_mean has var <= (m - tau_k)(tau_k + ds - m) (Bhatia-Davis). ds: the
    larger of the file's mean sampling interval and the largest real - nominal lag seen; 0
    without lag_time_mean."""
    if real != real:
        return 0.0
    has = r["n_tracks"][l] > 0
    ds = max(np.nan_to_num(r["ds"]), float(np.max((r["t_level"] - r["lag"])[has])))
    a = r["lag"][k]
    drift = r["disp_mean_" + p][l][k] / real
    return drift ** 2 * max(0.0, (real - a) * (a + ds - real))


def short_time(r, l, sums, E, ds):
    """Rows of point 1 for level l: (axis, text, verdict)."""
    n = r["n_tracks"][l]
    ks = [k for k in range(1, len(r["lag"])) if n[k] > 0]
    if not ks:
        return []
    k, tau = ks[0], r["lag"][ks[0]]
    real = r["t_level"][k] if r["lags_from"] else math.nan  # lag_time_mean (format 1.9)
    rows = []
    if sums is not None:
        R = sums[l, k]
        mom = [R[LG_VEL + 5 * i:LG_VEL + 5 * i + 5] / R[LG_N] for i in range(3)]
        # mean square of the interval-mean velocity (u(t0) + u(t0 + tau)) / 2
        q = [(m[2] + 2 * m[4] + m[3]) / 4 for m in mom]
        mean = [(m[0] + m[1]) / 2 for m in mom]
        xclock = math.sqrt(r["sigma2_x"][l][k] / q[0])
        clock = real if real == real else xclock
        how = ("by lag_time_mean of the file (the x clock <dx^2> = tau^2 <((u(t0) + u(t0 + tau)) "
               "/ 2)^2> gives %.4g s)" % xclock if real == real else "by the x clock <dx^2> = "
               "tau^2 <((u(t0) + u(t0 + tau)) / 2)^2>")
        rows.append(("x", "lag %d (nominal %.4g s) is at tau = %.4g s (tau+ %.3g) %s; ensemble "
                     "<u'^2> = %.5g, Eulerian %.5g (%+.1f%%)" %
                     (k, tau, clock, clock * r["u_tau"] ** 2 / r["nu"], how, q[0] - mean[0] ** 2,
                      E["uu"], 100 * ((q[0] - mean[0] ** 2) / E["uu"] - 1)),
                     "lag_time_mean used as the lag" if real == real else "used as the clock"))
        for i, (p, c) in ((1, ("y", "v")), (2, ("z", "w"))):
            s2 = r["sigma2_" + p][l][k] / clock ** 2
            kin = s2 / q[i]
            ok_kin = abs(kin - 1) <= 0.03
            val = s2 - mean[i] ** 2
            se, neff, how, ok = release_test(r, l, n[k], c, E, val)
            rows.append((p, "sigma_%s^2/tau^2 = %.5g = %.4f x <((%s(t0) + %s(t0 + tau)) / 2)^2> "
                         "(kinematics, within 3%%: %s); minus the mean drift %.5g, Eulerian "
                         "<%s'^2> %.5g, difference %+.4g (%+.1f%%), 2 se %.3g (N_eff %.0f; %s)" %
                         (p, s2, kin, c, c, "PASS" if ok_kin else "FAIL", val, c, E[c + c],
                          val - E[c + c], 100 * (val / E[c + c] - 1), 2 * se, neff, how),
                         "PASS" if ok and ok_kin else "FAIL"))
        return rows
    lo, hi = (real, real) if real == real else (tau, tau + (ds if ds > 0 else 0.0))
    lag = ("at the real lag %.4g s (lag %d, nominal %.4g s: lag_time_mean of the file)" %
           (real, k, tau) if real == real else "for the real lag between %.4g and %.4g s (lag %d; "
           "no --ckpt for the clock)" % (lo, hi, k))
    for p, c in zip(POS, COMP):
        rate = r["rate_var"][p][l][k] if r["rate_var"] else math.nan
        if rate == rate:  # format 1.10 on: var(dr / tau), each sample over its own real lag
            se, neff, how, ok = release_test(r, l, n[k], c, E, rate)
            rows.append((p, "var((%s(t0 + tau) - %s(t0)) / tau) = %.5g at the real lag %.4g s "
                         "(lag %d, each sample over its own lag: rate_var_%s), Eulerian <%s'^2> "
                         "%.5g, difference %+.1f%%, 2 se %.3g (N_eff %.0f; %s)" %
                         (p, p, rate, real, k, p, c, E[c + c], 100 * (rate / E[c + c] - 1),
                          2 * se, neff, how), "PASS" if ok else "FAIL"))
            continue
        s2 = r["sigma2_" + p][l][k]
        dvar = r["disp_var_" + p][l][k] if r["means"] else math.nan
        if dvar == dvar:  # the variance about the mean displacement (format 1.7 on)
            s2 = dvar
        jitter = lag_jitter(r, l, k, p, real) if dvar == dvar else 0.0
        v_hi, v_lo = s2 / lo ** 2, (s2 - jitter) / hi ** 2
        se, neff, how = release_se(r, l, n[k], c, E)
        if jitter > 0:
            how += ("; lag jitter: the releases' real lags differ within a sampling interval, "
                    "which the mean drift turns into up to %.3g of sigma^2/tau^2 (the range)"
                    % (jitter / hi ** 2))
        if dvar == dvar:
            how += "; drift removed (disp_var_%s, mean displacement %.4g m)" % (
                p, r["disp_mean_" + p][l][k])
        elif p == "x":
            drift = E["u_mean"]
            v_hi, v_lo = v_hi - drift ** 2, v_lo - drift ** 2
            se = math.hypot(se, 2 * abs(drift) * math.sqrt(E["uu"] / neff))
            how += "; drift = Eulerian U(y0) %.4g m/s (no --ckpt, no disp_var_x)" % drift
        se = math.hypot(se, np.nan_to_num(E[c + c + "_stderr"]))
        ok = v_lo - 2 * se <= E[c + c] <= v_hi + 2 * se
        rows.append((p, "sigma_%s^2/tau^2 = %.5g .. %.5g %s, Eulerian <%s'^2> %.5g, 2 se %.3g "
                     "(N_eff %.0f; %s)" % (p, v_lo, v_hi, lag, c, E[c + c], 2 * se, neff, how),
                     "PASS" if ok else "FAIL"))
    return rows


def report_level(r, l, t, sums, status):
    y, ut, nu = r["level"][l], r["u_tau"], r["nu"]
    E = eulerian_at(r, y)
    print("\n## level y+ %g (y = %.4g m; %d completed releases, %d tracks at lag 0)" %
          (r["y_plus"][l], y, r["releases"], r["n_tracks"][l][0]))
    t, r["lags_from"] = level_lags(r, l, t)
    r["t_level"] = t
    print("lags: %s" % ("lag_time_mean of the file, the mean real lag of the samples (checkpoint "
                        "format 1.9 on), largest real - nominal %.3g s" %
                        np.max((t - r["lag"])[r["n_tracks"][l] > 0]) if r["lags_from"] else
                        "no lag_time_mean in the file (or fill values: a run resumed from a "
                        "checkpoint of format 1.8 or older): the nominal lags%s" %
                        (" + half the sampling interval" if r["ds"] > 0 else "")))
    r["tl_now"] = {c: first_zero_integral(t, r["rho_L_" + c][l])[0] for c in COMP}
    rows = short_time(r, l, sums, E, r["ds"])
    if not rows:
        print("short-time dispersion: no lag with samples: not checked")
    for p, text, verdict in rows:
        print("short-time %s: %s: %s" % (p, text, verdict))
        status["fail"] |= verdict == "FAIL"
    # T_L
    tl = {}
    for i, c in enumerate(COMP):
        rho = r["rho_L_" + c][l]
        T0, reached = first_zero_integral(t, rho)
        tl[c] = T0
        eng, mean, se = (r["T_L"][l][i], r["T_L_release_mean"][l][i], r["T_L_stderr"][l][i])
        se0 = se * T0 / mean if mean == mean and mean > 0 and se == se else math.nan
        print("T_L,%s: int rho_L to %s = %.4g s (%.3g+) +- %.2g; engine T_L %.4g s, per-release "
              "mean %.4g +- %.2g s (T_L+ %.3g +- %.2g)" %
              (c, "its first zero" if reached else "the horizon (no zero crossing)", T0,
               T0 * ut ** 2 / nu, se0, eng, mean, se, mean * ut ** 2 / nu, se * ut ** 2 / nu))
    # Taylor curve and long-time law, y and z
    for p, c in (("y", "v"), ("z", "w")):
        var = E[c + c]
        rho = r["rho_L_" + c][l]
        ok = np.isfinite(rho) & np.isfinite(r["sigma2_" + p][l])
        if ok.sum() < 3:
            continue
        tt, rr, ss = t[ok], rho[ok], r["sigma2_" + p][l][ok]
        pred = taylor_curve(tt, rr, var)
        parts = []
        for f in (0.25, 0.5, 1.0):
            j = int(np.argmin(np.abs(tt - f * tt[-1])))
            parts.append("%.3g s: %.3f" % (tt[j], ss[j] / pred[j] if pred[j] > 0 else math.nan))
        print("Taylor curve %s: sigma^2 / (2 <%s'^2> int (tau - s) rho_L ds) at %s" %
              (p, c, ", ".join(parts)))
        T = tl[c]
        if T == T and tt[-1] >= 3 * T:
            last = tt >= tt[-1] * 2 / 3
            slope = np.polyfit(tt[last], ss[last], 1)[0]
            want = 2 * var * T
            print("long-time %s: d sigma^2/d tau over the last third %.4g m^2/s, 2 <%s'^2> T_L = "
                  "%.4g (ratio %.3f)%s" % (p, slope, c, want, slope / want,
                                           "; the walls bound y" if p == "y" else ""))
        else:
            print("long-time %s: not reached (horizon %.3g s < 3 T_L = %.3g s)" %
                  (p, tt[-1], 3 * T))
    mean_velocity(r, l, t, sums, E, status)
    if r["stations"]:
        for s, x in enumerate(r["station"]):
            print("P(y; x - x0 = %g): mean y %.4g m, sd %.4g m, %d tracks" %
                  (x, r["pdf_mu_y"][l][s], math.sqrt(max(r["pdf_var_y"][l][s], 0.0))
                   if r["pdf_var_y"][l][s] == r["pdf_var_y"][l][s] else math.nan,
                   r["pdf_count"][l][s] if r["pdf_count"][l][s] == r["pdf_count"][l][s] else 0))


def mean_velocity(r, l, t, sums, E, status):
    """Point 3: the Lagrangian mean velocity against U(y0), and the mean displacement."""
    ok = r["n_tracks"][l] > 0
    n0 = r["n_tracks"][l][0]
    if sums is not None:
        ul, src = sums[l, 0, LG_VEL] / sums[l, 0, LG_N], "checkpoint"
        ult = sums[l, ok, LG_VEL + 1] / sums[l, ok, LG_N]
    elif r["means"] and n0 > 0:
        ul, src = r["u_release_mean"][l][0], "stats.nc"
        ult = r["u_lag_mean"][l][ok]
    else:
        print("Lagrangian mean velocity: not in stats.nc (a file written before checkpoint "
              "format 1.7; the sums are in the checkpoint: give --ckpt): not checked")
        return
    r["mean_checked"] = True
    _, neff, _ = release_se(r, l, n0, "u", E)
    se = math.hypot(math.sqrt(E["uu"] / neff), np.nan_to_num(E["u_mean_stderr"]))
    verdict = "PASS" if abs(ul - E["u_mean"]) <= 2 * se else "FAIL"
    status["fail"] |= verdict == "FAIL"
    print("Lagrangian mean u at release %.5g m/s (%s), Eulerian U(y0) %.5g, difference %+.3g "
          "(2 se %.3g): %s; <u(t0 + tau)> over the horizon %.4g .. %.4g m/s" %
          (ul, src, E["u_mean"], ul - E["u_mean"], 2 * se, verdict, ult.min(), ult.max()))
    if not r["means"]:
        return
    dm = r["disp_mean_x"][l]
    good = ok & np.isfinite(dm) & (t > 0)
    if not good.any():
        print("mean displacement <dx>: fill values (a run resumed from a checkpoint of format "
              "1.6 does not know it)")
        return
    k = np.nonzero(good)[0][-1]
    drift = t[k] * (r["u_release_mean"][l][k] + r["u_lag_mean"][l][k]) / 2
    print("mean displacement <dx>(%.4g s) = %.5g m, tau (<u(t0)> + <u(t0 + tau)>) / 2 = %.5g m "
          "(ratio %.4f)" % (t[k], dm[k], drift, dm[k] / drift if drift else math.nan))


def plots(r, t, d):
    plt = pyplot()
    nl = len(r["level"])
    if r["stations"]:
        fig, axes = plt.subplots(1, nl, figsize=(3.2 * nl, 3), squeeze=False)
        for l in range(nl):
            ax = axes[0][l]
            for s, x in enumerate(r["station"]):
                ax.plot(r["pdf_bin"] / r["delta"], r["pdf_y"][l][s] * r["delta"], "-",
                        drawstyle="steps-mid", label="x - x0 = %g" % x)
            ax.axvline(r["level"][l] / r["delta"], color="0.6", ls=":")
            ax.set_title("release y+ = %g" % r["y_plus"][l], fontsize=9)
            ax.set_xlabel("y / delta")
            ax.legend(fontsize=7)
        axes[0][0].set_ylabel("P(y; x) delta")
        fig.tight_layout()
        save(fig, os.path.join(d, "lagr_pdf_y.png"))
    fig, axes = plt.subplots(1, 3, figsize=(10, 3))
    for l in range(nl):
        E = eulerian_at(r, r["level"][l])
        tl = level_lags(r, l, t)[0]
        for i, (p, c) in enumerate(zip(POS, COMP)):
            ok = (tl > 0) & np.isfinite(r["sigma2_" + p][l])
            col = "C%d" % l
            axes[i].loglog(tl[ok], r["sigma2_" + p][l][ok], "-", color=col,
                           label="y+ %g" % r["y_plus"][l])
            if p != "x":
                axes[i].loglog(tl[ok], E[c + c] * tl[ok] ** 2, ":", color=col, lw=0.8)
    for i, p in enumerate(POS):
        axes[i].set_xlabel("tau [s]")
        axes[i].set_title("sigma_%s^2 (dotted: <%s'^2> tau^2)" % (p, COMP[i]) if p != "x" else
                          "<dx^2> (mean drift included)", fontsize=9)
        axes[i].legend(fontsize=7)
    fig.tight_layout()
    save(fig, os.path.join(d, "lagr_dispersion.png"))
    fig, axes = plt.subplots(1, 3, figsize=(10, 3))
    for l in range(nl):
        for i, c in enumerate(COMP):
            axes[i].plot(level_lags(r, l, t)[0], r["rho_L_" + c][l], "-",
                         label="y+ %g" % r["y_plus"][l])
    for i, c in enumerate(COMP):
        axes[i].axhline(0, color="0.7", lw=0.5)
        axes[i].set_xlabel("tau [s]")
        axes[i].set_title("rho_L of %s" % c, fontsize=9)
        axes[i].legend(fontsize=7)
    fig.tight_layout()
    save(fig, os.path.join(d, "lagr_rho.png"))


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("stats", help="stats.nc of a run with lagrangian.y_plus set")
    ap.add_argument("--ckpt", help="the checkpoint written with it: the Lagrangian sums for the "
                    "x clock (files without lag_time_mean, written before checkpoint format "
                    "1.9), and the mean velocity of files written before checkpoint format 1.7 "
                    "(newer files hold it)")
    ap.add_argument("--out", help="write lagr_pdf_y.png, lagr_dispersion.png, lagr_rho.png here")
    ap.add_argument("--u-tau", type=u_tau_arg, default="force",
                    help="u_tau of the wall units: force (default), wall or a value [m/s]")
    ap.add_argument("--sample-interval", type=cli.number(float, 0),
                    help="statistics sampling interval [s] (default: from the file; 0: nominal "
                    "lags)")
    a = ap.parse_args(argv)
    r = read_run(a.stats, a.u_tau)
    sums = read_ckpt(a.ckpt, r) if a.ckpt else None
    ds = r["ds"] if a.sample_interval is None else a.sample_interval
    r["ds"] = ds
    t = real_lags(r, ds)
    # releases closer than two correlation times are not independent: their number counts
    # as releases x release_every / (2 tau) (the statistical inefficiency of batch means)
    tau = r["corr_time"]
    r["g"] = max(1.0, 2 * tau / r["release_every"]) if tau == tau else 1.0
    if a.out:
        out_dir(a.out)
    print("# %s: %d completed releases every %g s, horizon %g s, %d lags; wall units of u_tau = "
          "%.5g m/s; sampling interval %s; Eulerian correlation time %s s" %
          (a.stats, r["releases"], r["release_every"], r["horizon"], len(t) - 1, r["u_tau"],
           "%.4g s (mean; without lag_time_mean the lags are taken as nominal + half of it)" % ds if ds > 0 else
           "unknown (nominal lags)",
           "%.3g" % r["corr_time"]))
    status = {"fail": False}
    for l in range(len(r["level"])):
        report_level(r, l, t, sums, status)
    if a.out:
        plots(r, t, a.out)
    print("\nLagrangian checks (short-time dispersion%s): %s" %
          (", mean velocity" if r.get("mean_checked") else "", "FAIL" if status["fail"] else
           "PASS"))
    return 1 if status["fail"] else 0
