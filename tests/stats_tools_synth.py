#!/usr/bin/python3
"""Issue 25: the analysis tools spectra_compare, corr_compare, skewflat_compare and lagr_check
on a synthetic stats.nc whose answers are known, and on inputs they must refuse.

usage: stats_tools_synth.py ROOT WORK PART
  PART = spectra   correlations and spectra that agree by Wiener-Khinchin (a Gaussian
                   correlation; the MKM spectrum at one level): Parseval and W-K PASS, the
                   MKM level compares with error 0, the half width of the Gaussian is found;
                   a spectrum changed at one wavenumber FAILs (exit 1)
         skewflat  window moment records of known samples: the merged profiles PASS; a root
                   profile changed by 1e-6 FAILs
         lagr      an Ornstein-Uhlenbeck (Gaussian) dispersion with T_L, <v'^2>, <w'^2>: the
                   short-time law, Taylor's curve, the long-time law and T_L come out; a
                   dispersion doubled FAILs; a checkpoint's Lagrangian mean equals U; a
                   file with lag_time_mean (samples 0.4 lag intervals late) is checked at
                   those real lags, one whose lag_time_mean are fill values brackets them
         errors    missing file, not netCDF, group missing, bad arguments: "error: ...", exit 1,
                   no traceback
Prints PASS or FAIL lines; exit status 1 on any FAIL.
"""
import math
import os
import re
import subprocess
import sys

import netCDF4
import numpy as np
from passfail import check, finish  # noqa: E402

ROOT, WORK, PART = sys.argv[1], sys.argv[2], sys.argv[3]
TOOL = os.path.join(ROOT, "stats", "python", "chansph-stats")
MKM = os.path.join(ROOT, "stats", "dns", "mkm1999")
NU, DELTA, LX, LZ, DR = 1 / 180.0, 1.0, 2.0, 0.7, 0.025
NX, NZ = 80, 28


def run(*args):
    p = subprocess.run([TOOL] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def var(g, name, dims, data, dtype="f8"):
    v = g.createVariable(name, dtype, dims)
    v[:] = data
    return v


def root(d, ys):
    """Root attributes and profiles: uniform profiles uu = 4, vv = 0.5, ww = 1 (m^2/s^2),
    U = 10 y + 5, flatness 3, skewness 0, 40 bins over the lower half."""
    for k, v in dict(nu=NU, delta=DELTA, lx=LX, lz=LZ, dr=DR, u_tau_force=1.0, u_tau_wall=1.0,
                     n_windows=2, average_start=0.0, average_end=1.0, t_reached=1.0,
                     steps=1000, correlation_time=0.01,
                     scene="[output]\nstats_every = 10\n").items():
        d.setncattr(k, v)
    d.createDimension("y", len(ys))
    n = len(ys)
    var(d, "y", ("y",), ys)
    var(d, "y_mean", ("y",), ys)
    var(d, "n_samples", ("y",), np.full(n, 1e4))
    var(d, "u_mean", ("y",), 10 * ys + 5)
    var(d, "u_mean_stderr", ("y",), np.full(n, 0.01))
    for c, v in (("uu", 4.0), ("vv", 0.5), ("ww", 1.0)):
        var(d, c, ("y",), np.full(n, v))
        var(d, c + "_stderr", ("y",), np.full(n, 0.01 * v))
    for c in "uvw":
        var(d, c + "_skewness", ("y",), np.zeros(n))
        var(d, c + "_flatness", ("y",), np.full(n, 3.0))


def wk_inverse(E, L, n):
    """R(l_i) of a one-sided density E over k = 2 pi m / L (m = 0 .. n/2)."""
    dk = 2 * math.pi / L
    c = np.full(len(E), 2.0)
    c[0] = 1.0
    c[-1] = 1.0
    phi = E * dk / c
    return np.fft.irfft(phi * n, n)


def mkm_density(path, col, k):
    t = np.loadtxt(path)
    kd, Ed = t[:, 0], t[:, col] / (t[1, 0] - t[0, 0])
    pos = Ed > 0
    return np.exp(np.interp(k, kd[pos], np.log(Ed[pos])))


def spectra_file(path, break_it=False):
    levels = np.array([30.02, 98.04]) * NU  # y+ 30.02 and 98.04 of MKM, u_tau = 1
    with netCDF4.Dataset(path, "w") as d:
        root(d, (np.arange(40) + 0.5) * DR)
        g = d.createGroup("correlations")
        for dim, n in (("level", 2), ("separation_x", NX), ("separation_z", NZ),
                       ("kx", NX // 2 + 1), ("kz", NZ // 2 + 1)):
            g.createDimension(dim, n)
        var(g, "level", ("level",), levels)
        var(g, "y_plus", ("level",), levels / NU)
        var(g, "samples", ("level",), [100.0, 100.0])
        lx = np.arange(NX) * LX / NX
        lz = np.arange(NZ) * LZ / NZ
        var(g, "separation_x", ("separation_x",), lx)
        var(g, "separation_z", ("separation_z",), lz)
        kx = 2 * math.pi / LX * np.arange(NX // 2 + 1)
        kz = 2 * math.pi / LZ * np.arange(NZ // 2 + 1)
        var(g, "kx", ("kx",), kx)
        var(g, "kz", ("kz",), kz)
        for d_, l, L, k, n in (("x", lx, LX, kx, NX), ("z", lz, LZ, kz, NZ)):
            for c, s2, L0 in (("u", 4.0, 0.3), ("v", 0.5, 0.05), ("w", 1.0, 0.08)):
                # periodic Gaussian correlation (images summed), its density by W-K
                per = np.minimum(l, L - l)
                R = s2 * np.exp(-(per / L0) ** 2)
                E = np.fft.rfft(R).real / n / (2 * math.pi / L)
                E[1:-1] *= 2
                Rs, Es = np.tile(R, (2, 1)), np.tile(E, (2, 1))
                if c == "v" and d_ == "x":  # level 0: the MKM spectrum of v at y+ 30
                    Em = mkm_density(os.path.join(MKM, "spectra", "chan180.xspec.30"), 2, k)
                    Es[0] = Em
                    Rs[0] = wk_inverse(Em, L, n)
                if break_it and c == "w" and d_ == "z":
                    Es[1, 3] *= 1.01
                var(g, "R_%s%s_%s" % (c, c, d_), ("level", "separation_" + d_), Rs)
                var(g, "E_%s%s_k%s" % (c, c, d_), ("level", "k" + d_), Es)


def spectra():
    f = os.path.join(WORK, "spectra.nc")
    spectra_file(f)
    rc, out, err = run("spectra_compare", f)
    check(rc == 0 and "consistency (Parseval, Wiener-Khinchin): PASS" in out,
          "spectra_compare: Parseval and Wiener-Khinchin hold on a consistent file (exit %d) %s"
          % (rc, err.strip()))
    row = [ln for ln in out.splitlines() if re.match(r"\s+30\.0\s+30\.02\s+x\s+v\s", ln)]
    err_col = float(row[0].split()[10]) if row else math.nan
    check(err_col < 1e-6, "spectra_compare: the MKM spectrum given at y+ 30 compares with "
          "error %.3g (< 1e-6)" % err_col)
    check("k_x delta = 0.5, 1, 1.5, 2, 2.5, 3 " in out,
          "spectra_compare names the MKM wavenumbers kx delta < pi the box cannot hold")
    b = os.path.join(WORK, "spectra_broken.nc")
    spectra_file(b, break_it=True)
    rc, out, _ = run("spectra_compare", b)
    check(rc == 1 and "Wiener-Khinchin): FAIL" in out,
          "spectra_compare: a spectrum changed by 1%% at one wavenumber FAILs (exit %d)" % rc)
    rc, out, _ = run("corr_compare", f)
    check(rc == 0 and "R(l) = R(L - l), |rho| <= 1): PASS" in out,
          "corr_compare: a symmetric correlation passes (exit %d)" % rc)
    row = [ln for ln in out.splitlines() if re.match(r"\s+98\.0\s+98\.04\s+x\s+u\s", ln)]
    hw = float(row[0].split()[6]) if row else math.nan
    # rho = exp(-(l/0.3)^2) at l = 0.025 i; the linear interpolation of the drop below 0.5
    want = 0.3 * math.sqrt(math.log(2))
    check(abs(hw - want) < 2e-3, "corr_compare: rho_uu = 0.5 at l = %.4f delta, exact %.4f" %
          (hw, want))
    with netCDF4.Dataset(b, "a") as d:
        d["correlations"]["R_uu_z"][1, 2] = 5.0
    rc, out, _ = run("corr_compare", b)
    check(rc == 1 and "FAIL" in out, "corr_compare: an asymmetric R(l) or |rho| > 1 FAILs "
          "(exit %d)" % rc)


def skewflat_file(path, delta_skew=0.0):
    rng = np.random.default_rng(7)
    nw, ny = 3, 40
    ys = (np.arange(ny) + 0.5) * DR
    labels = ["count", "mean_u", "mean_v", "mean_w", "mean_p", "mean_rho", "mean_y", "mean_nu_t",
              "mean_k_r", "C2_uu", "C2_vv", "C2_ww", "C2_uv", "C2_uw", "C2_vw", "M3_u", "M3_v",
              "M3_w", "M4_u", "M4_v", "M4_w"]
    mom = np.zeros((nw, ny, len(labels)))
    pooled = {c: [[] for _ in range(ny)] for c in "uvw"}
    for w in range(nw):
        for j in range(ny):
            n = 200 + 50 * w
            mom[w, j, 0] = n
            for c, x in (("u", rng.gamma(2.0, 1.0, n)), ("v", rng.normal(0, 1, n)),
                         ("w", rng.exponential(1.0, n))):
                m = x.mean()
                mom[w, j, labels.index("mean_" + c)] = m
                mom[w, j, labels.index("C2_" + c + c)] = ((x - m) ** 2).sum()
                mom[w, j, labels.index("M3_" + c)] = ((x - m) ** 3).sum()
                mom[w, j, labels.index("M4_" + c)] = ((x - m) ** 4).sum()
                pooled[c][j].extend(x)
    with netCDF4.Dataset(path, "w") as d:
        root(d, ys)
        for c in "uvw":
            s = [np.mean((np.array(p) - np.mean(p)) ** 3) / np.var(p) ** 1.5 for p in pooled[c]]
            f = [np.mean((np.array(p) - np.mean(p)) ** 4) / np.var(p) ** 2 for p in pooled[c]]
            d[c + "_skewness"][:] = np.array(s) + (delta_skew if c == "w" else 0.0)
            d[c + "_flatness"][:] = f
        g = d.createGroup("eulerian")
        g.createDimension("window", nw)
        g.createDimension("y", ny)
        g.createDimension("moment", len(labels))
        mv = g.createVariable("moment", str, ("moment",))
        for i, s in enumerate(labels):
            mv[i] = s
        var(g, "moments", ("window", "y", "moment"), mom)
        var(g, "window_complete", ("window",), [1, 1, 0], "i4")


def skewflat():
    f = os.path.join(WORK, "skewflat.nc")
    skewflat_file(f)
    rc, out, err = run("skewflat_compare", f)
    check(rc == 0 and out.count(": PASS") == 7, "skewflat_compare: the profiles are the merge of "
          "the window records of known samples (exit %d) %s" % (rc, err.strip()))
    row = [ln for ln in out.splitlines() if re.match(r"\s+30\s+u\s", ln)]
    check(bool(row) and "+-" in row[0] and "-)" not in row[0],
          "skewflat_compare: batch standard errors from the 2 complete windows: %s" %
          (row[0].strip() if row else "no row"))
    b = os.path.join(WORK, "skewflat_broken.nc")
    skewflat_file(b, delta_skew=1e-6)
    rc, out, _ = run("skewflat_compare", b)
    check(rc == 1 and "w_skewness = merge" in out and "FAIL" in out,
          "skewflat_compare: a profile 1e-6 off the window records FAILs (exit %d)" % rc)


def lagr_file(path, scale_y=1.0, with_corr=True, means=None, lag_shift=None, rate=None):
    """Ornstein-Uhlenbeck velocities: rho_L = exp(-tau/T), sigma^2 = 2 s2 T^2 (t/T - 1 + e^-t/T)
    (Taylor 1921), releases of N tracks at y+ 30 and 100; PDFs Gaussian. means = du: the
    Lagrangian means of checkpoint format 1.7 (u_release_mean ... disp_var_z), the mean u
    U + du; None: a file without them. lag_shift = s: the samples of every lag k > 0 were taken
    at the real lag k dtau + s, written as lag_time_mean (checkpoint format 1.9), and the
    functions are those of the real lags; NaN: lag_time_mean all fill values (a run resumed
    from format 1.8); None: no lag_time_mean. rate = (fx, fy, fz): rate_var_x, _y, _z of
    checkpoint format 1.10, the OU variance of dr / tau at the real lags times f."""
    T, nlag, H = 0.02, 120, 0.12  # horizon 6 T; lag interval 0.001
    nominal = np.arange(nlag + 1) * H / nlag
    t = nominal + (np.where(nominal > 0, lag_shift, 0.0) if lag_shift == lag_shift and
                   lag_shift is not None else 0.0)
    levels = np.array([30.0, 100.0]) * NU
    nrel, N = 400, 56
    with netCDF4.Dataset(path, "w") as d:
        root(d, (np.arange(40) + 0.5) * DR)
        # dt = 1e-6, stats_every 10: the samples lie within 1e-5 of the nominal lags
        d.setncattr("t_reached", 0.1)
        d.setncattr("steps", 100000)
        if with_corr:
            g = d.createGroup("correlations")
            g.createDimension("level", 2)
            g.createDimension("separation_z", NZ)
            var(g, "level", ("level",), levels)
            var(g, "y_plus", ("level",), levels / NU)
            lz = np.arange(NZ) * LZ / NZ
            rho = np.exp(-(np.minimum(lz, LZ - lz) / 0.03) ** 2)
            for c in "uvw":
                var(g, "rho_%s%s_z" % (c, c), ("level", "separation_z"), np.tile(rho, (2, 1)))
        g = d.createGroup("lagrangian")
        for k, v in dict(releases=nrel, horizon=H, release_every=0.05, x0=0.0).items():
            g.setncattr(k, v)
        g.createDimension("level", 2)
        g.createDimension("lag", nlag + 1)
        g.createDimension("component", 3)
        g.createDimension("station", 3)
        g.createDimension("pdf_bin", 50)
        var(g, "level", ("level",), levels)
        var(g, "y_plus", ("level",), levels / NU)
        var(g, "lag", ("lag",), nominal)
        if lag_shift is not None:
            v = var(g, "lag_time_mean", ("level", "lag"), np.tile(t, (2, 1)))
            if lag_shift != lag_shift:
                v[:] = np.ma.masked_all((2, nlag + 1))
        disp = lambda s2: 2 * s2 * T ** 2 * (t / T - 1 + np.exp(-t / T))
        U = 10 * levels + 5
        var(g, "sigma2_x", ("level", "lag"), np.array([disp(4.0) + (u * t) ** 2 for u in U]))
        var(g, "sigma2_y", ("level", "lag"), np.tile(scale_y * disp(0.5), (2, 1)))
        var(g, "sigma2_z", ("level", "lag"), np.tile(disp(1.0), (2, 1)))
        if means is not None:
            um = np.array([np.full(nlag + 1, u + means) for u in U])
            zero = np.zeros((2, nlag + 1))
            for kind in ("release", "lag"):
                var(g, "u_%s_mean" % kind, ("level", "lag"), um)
                var(g, "v_%s_mean" % kind, ("level", "lag"), zero)
                var(g, "w_%s_mean" % kind, ("level", "lag"), zero)
            var(g, "disp_mean_x", ("level", "lag"), um * t)
            var(g, "disp_mean_y", ("level", "lag"), zero)
            var(g, "disp_mean_z", ("level", "lag"), zero)
            var(g, "disp_var_x", ("level", "lag"), np.tile(disp(4.0), (2, 1)))
            var(g, "disp_var_y", ("level", "lag"), np.tile(scale_y * disp(0.5), (2, 1)))
            var(g, "disp_var_z", ("level", "lag"), np.tile(disp(1.0), (2, 1)))
        if rate is not None:
            for p, s2, f in zip("xyz", (4.0, 0.5, 1.0), rate):
                rv = np.where(t > 0, f * disp(s2) / np.where(t > 0, t, 1.0) ** 2, 0.0)
                var(g, "rate_var_" + p, ("level", "lag"), np.tile(rv, (2, 1)))
        for c in "uvw":
            var(g, "rho_L_" + c, ("level", "lag"), np.tile(np.exp(-t / T), (2, 1)))
        var(g, "n_tracks", ("level", "lag"), np.full((2, nlag + 1), float(nrel * N)))
        var(g, "T_L", ("level", "component"), np.full((2, 3), T))
        var(g, "T_L_release_mean", ("level", "component"), np.full((2, 3), T))
        var(g, "T_L_stderr", ("level", "component"), np.full((2, 3), 0.05 * T))
        var(g, "station", ("station",), [0.5, 1.0, 2.0])
        yb = (np.arange(50) + 0.5) * DELTA / 50
        var(g, "pdf_bin", ("pdf_bin",), yb)
        pdf = np.zeros((2, 3, 50))
        for l in range(2):
            for s, sd in enumerate((0.05, 0.08, 0.12)):
                pdf[l, s] = np.exp(-0.5 * ((yb - levels[l]) / sd) ** 2) / (sd * math.sqrt(2 * math.pi))
        var(g, "pdf_y", ("level", "station", "pdf_bin"), pdf)
        var(g, "pdf_mu_y", ("level", "station"), np.tile(levels[:, None], (1, 3)))
        var(g, "pdf_var_y", ("level", "station"), np.tile(np.array([0.05, 0.08, 0.12]) ** 2, (2, 1)))
        var(g, "pdf_count", ("level", "station"), np.full((2, 3), 1000.0))
    return U, nrel * N, nlag


def lagr():
    f = os.path.join(WORK, "lagr.nc")
    U, n, nlag = lagr_file(f)
    rc, out, err = run("lagr_check", f)
    short = re.findall(r"short-time (.): sigma_.\^2/tau\^2 = ([0-9.e+-]+) \.\. ([0-9.e+-]+) .*: "
                       r"(PASS|FAIL)", out)
    check(rc == 0 and len(short) == 6 and all(s[3] == "PASS" for s in short),
          "lagr_check: the short-time law holds for an OU dispersion (x without its drift; the "
          "real lag bracketed by one sampling interval): %s (exit %d) %s" % (short, rc, err.strip()))
    sy = [float(s[2]) for s in short if s[0] == "y"]
    # sigma^2/tau^2 at the nominal first lag tau = T/20 is <v'^2> (1 - tau/(3T) + ...)
    check(sy and abs(sy[0] / 0.5 - (2 * 20 ** 2 * (1 / 20 - 1 + math.exp(-1 / 20)))) < 1e-4,
          "lagr_check: sigma_y^2/tau^2 at the nominal first lag = the OU value (%s)" % sy)
    tc = re.findall(r"Taylor curve y: .* at .*?: ([0-9.]+), .*?: ([0-9.]+), .*?: ([0-9.]+)", out)
    check(tc and all(abs(float(x) - 1) < 2e-3 for x in tc[0]),
          "lagr_check: Taylor's curve from rho_L reproduces sigma_y^2 (%s)" % (tc,))
    lt = re.findall(r"long-time z: .*\(ratio ([0-9.]+)\)", out)
    check(lt and abs(float(lt[0]) - 1) < 0.03,
          "lagr_check: long-time growth 2 <w'^2> T_L tau (ratio %s)" % lt)
    tl = re.findall(r"T_L,v: int rho_L to the horizon \(no zero crossing\) = ([0-9.e+-]+) s", out)
    check(tl and abs(float(tl[0]) / (0.02 * (1 - math.exp(-6))) - 1) < 1e-3,
          "lagr_check: T_L = int rho_L over the horizon for exp(-tau/T) (%s)" % tl)
    check("mean y 0.1667 m, sd 0.05 m, 1000 tracks" in out,
          "lagr_check: the dispersion PDF's mean and sd are reported")
    check("Lagrangian mean velocity: not in stats.nc" in out and
          "drift = Eulerian U(y0)" in out,
          "lagr_check: a file without the Lagrangian means (before checkpoint format 1.7): the "
          "Eulerian U stands in for the drift, the mean velocity is not checked")
    # checkpoint format 1.7 on: the Lagrangian means in stats.nc, no --ckpt needed
    m = os.path.join(WORK, "lagr_means.nc")
    lagr_file(m, means=0.0)
    rc, out, err = run("lagr_check", m)
    short = re.findall(r"short-time (.): sigma_.\^2/tau\^2 = .*drift removed \(disp_var_.*: "
                       r"(PASS|FAIL)", out)
    mean = re.findall(r"Lagrangian mean u at release .* \(stats.nc\).*: (PASS|FAIL)", out)
    ratio = re.findall(r"mean displacement <dx>.*\(ratio ([0-9.]+)\)", out)
    check(rc == 0 and len(short) == 6 and all(x[1] == "PASS" for x in short) and
          mean == ["PASS", "PASS"] and len(ratio) == 2 and
          all(abs(float(x) - 1) < 1e-3 for x in ratio),
          "lagr_check without --ckpt on a file with the Lagrangian means: the drift removed by "
          "disp_var_*, the short-time law holds (%s), the mean velocity equals U (%s), "
          "<dx> = U tau (%s) (exit %d) %s" % (short, mean, ratio, rc, err.strip()))
    lagr_file(m, means=1.0)
    rc, out, _ = run("lagr_check", m)
    mean = re.findall(r"Lagrangian mean u at release .* \(stats.nc\).*: (PASS|FAIL)", out)
    check(rc == 1 and mean == ["FAIL", "FAIL"],
          "lagr_check: a Lagrangian mean velocity 1 m/s off U FAILs (%s, exit %d)" % (mean, rc))
    b = os.path.join(WORK, "lagr_broken.nc")
    lagr_file(b, scale_y=2.0, with_corr=False)
    rc, out, _ = run("lagr_check", b)
    check(rc == 1 and re.search(r"short-time y: .*FAIL", out) is not None,
          "lagr_check: a doubled y dispersion FAILs the short-time law (exit %d)" % rc)
    # checkpoint format 1.9 on: the real lags in lag_time_mean. The samples 0.4 lag intervals
    # late: bracketing [tau, tau + ds] (ds = 1e-5) would FAIL, the real lag gives the OU value
    s = os.path.join(WORK, "lagr_lagtime.nc")
    lagr_file(s, lag_shift=0.0004)
    rc, out, err = run("lagr_check", s)
    short = re.findall(r"short-time (.): sigma_.\^2/tau\^2 = ([0-9.e+-]+) \.\. ([0-9.e+-]+) at "
                       r"the real lag ([0-9.e+-]+) s \(lag 1, nominal 0.001 s: lag_time_mean of "
                       r"the file\).*: (PASS|FAIL)", out)
    sy = [float(x[1]) for x in short if x[0] == "y"]
    tau = 0.0014 / 0.02
    check(rc == 0 and len(short) == 6 and all(x[4] == "PASS" and float(x[3]) == 0.0014
                                              for x in short) and
          out.count("lags: lag_time_mean of the file") == 2 and sy and
          abs(sy[0] / 0.5 - 2 * (tau - 1 + math.exp(-tau)) / tau ** 2) < 1e-4,
          "lagr_check: a file with lag_time_mean takes the real lags from it (0.0014 s for the "
          "nominal 0.001): sigma_y^2/tau^2 is the OU value at the real lag, the short-time law "
          "holds (%s, exit %d) %s" % (short, rc, err.strip()))
    # checkpoint format 1.10 on: var(dr / tau) with each sample over its own real lag
    s3 = os.path.join(WORK, "lagr_rate.nc")
    lagr_file(s3, means=0.0, lag_shift=0.0004, rate=(1.0, 1.0, 1.0))
    rc, out, err = run("lagr_check", s3)
    rows = re.findall(r"short-time (.): var\(\(.\(t0 \+ tau\) - .\(t0\)\) / tau\) = "
                      r"([0-9.e+-]+) at the real lag 0.0014 s .*: (PASS|FAIL)", out)
    rx = [float(x[1]) for x in rows if x[0] == "x"]
    check(rc == 0 and len(rows) == 6 and all(x[2] == "PASS" for x in rows) and rx and
          abs(rx[0] / 4.0 - 2 * (tau - 1 + math.exp(-tau)) / tau ** 2) < 1e-4,
          "lagr_check: a file with rate_var_* compares var(dr / tau) with <u_i'^2> directly, "
          "x included (the OU value at the real lag; %s, exit %d) %s" % (rows, rc, err.strip()))
    lagr_file(s3, means=0.0, lag_shift=0.0004, rate=(2.0, 1.0, 1.0))
    rc, out, _ = run("lagr_check", s3)
    check(rc == 1 and re.search(r"short-time x: var.*FAIL", out) is not None and
          re.search(r"short-time y: var.*PASS", out) is not None,
          "lagr_check: a doubled rate_var_x FAILs the short-time law in x (exit %d)" % rc)
    s2 = os.path.join(WORK, "lagr_lagtime_fill.nc")
    lagr_file(s2, lag_shift=math.nan)
    rc, out, _ = run("lagr_check", s2)
    check(rc == 0 and out.count("lags: no lag_time_mean in the file (or fill values") == 2 and
          out.count("for the real lag between 0.001 and 0.00101 s") == 6,
          "lagr_check: lag_time_mean all fill values (resumed from format 1.8): the real lag "
          "bracketed as for older files (exit %d)" % rc)
    # a checkpoint with the Lagrangian sums: mean velocity = U at every lag
    try:
        import h5py
    except ImportError:
        print("SKIP: no h5py for the checkpoint part")
        return
    ck = os.path.join(WORK, "lagr_ckpt.h5")
    # sums of the OU velocities: means U, 0, 0; variances 4, 0.5, 1; correlation exp(-t/T)
    t = np.arange(nlag + 1) * 0.12 / nlag
    rho = np.exp(-t / 0.02)
    sums = np.zeros((2, nlag + 1, 43))
    for l in range(2):
        sums[l, :, 0] = n
        for i, (m, v) in enumerate(((U[l], 4.0), (0.0, 0.5), (0.0, 1.0))):
            sums[l, :, 1 + 5 * i] = sums[l, :, 2 + 5 * i] = n * m
            sums[l, :, 3 + 5 * i] = sums[l, :, 4 + 5 * i] = n * (m * m + v)
            sums[l, :, 5 + 5 * i] = n * (m * m + v * rho)
    with h5py.File(ck, "w") as h:
        h.attrs.update(format=b"chansph-checkpoint", format_version_major=1,
                       format_version_minor=0, complete=1)
        h["stats/lagrangian/sums"] = sums
        h["stats/lagrangian/releases"] = np.array([400.0])
    rc, out, err = run("lagr_check", f, "--ckpt", ck)
    ck17 = os.path.join(WORK, "lagr_ckpt17.h5")
    with h5py.File(ck17, "w") as h:  # format 1.7: the sums of dr appended
        h.attrs.update(format=b"chansph-checkpoint", format_version_major=1,
                       format_version_minor=7, complete=1)
        h["stats/lagrangian/sums"] = np.concatenate([sums, np.zeros((2, nlag + 1, 3))], axis=2)
        h["stats/lagrangian/releases"] = np.array([400.0])
    rc17, out17, err17 = run("lagr_check", f, "--ckpt", ck17)
    check(rc17 == 0 and out17.count("(checkpoint)") == 2,
          "lagr_check --ckpt reads a checkpoint of format 1.7 (exit %d) %s" % (rc17, err17.strip()))
    ck19 = os.path.join(WORK, "lagr_ckpt19.h5")
    with h5py.File(ck19, "w") as h:  # format 1.9: the sums of dr and of the actual lags appended
        h.attrs.update(format=b"chansph-checkpoint", format_version_major=1,
                       format_version_minor=9, complete=1)
        h["stats/lagrangian/sums"] = np.concatenate([sums, np.zeros((2, nlag + 1, 4))], axis=2)
        h["stats/lagrangian/releases"] = np.array([400.0])
    rc19, out19, err19 = run("lagr_check", s, "--ckpt", ck19)
    x19 = re.findall(r"short-time x: lag 1 \(nominal 0.001 s\) is at tau = 0.0014 s .* by "
                     r"lag_time_mean of the file .*: lag_time_mean used as the lag", out19)
    kin19 = re.findall(r"short-time [yz]: .*kinematics, within 3%: (PASS|FAIL).*: (PASS|FAIL)",
                       out19)
    check(rc19 == 0 and len(x19) == 2 and kin19 == [("PASS", "PASS")] * 4,
          "lagr_check --ckpt of format 1.9 on a file with lag_time_mean: the real lag from the "
          "file, not the x clock; the kinematics and the short-time law hold in y and z (%s, "
          "exit %d) %s" % (kin19, rc19, err19.strip()))
    mean = re.findall(r"Lagrangian mean u at release .*: (PASS|FAIL)", out)
    kin = re.findall(r"short-time [yz]: .*kinematics, within 3%: (PASS|FAIL).*: (PASS|FAIL)", out)
    clock = re.findall(r"is at tau = ([0-9.e+-]+) s .* by the x clock", out)
    check(len(kin) == 4 and all(k == ("PASS", "PASS") for k in kin) and clock and
          all(abs(float(c) / 0.001 - 1) < 1e-3 for c in clock),
          "lagr_check --ckpt: the x clock finds the first lag (%s s, nominal 0.001), the "
          "kinematics and the short-time law hold in y and z (%s)" % (clock, kin))
    check(rc == 0 and mean == ["PASS", "PASS"],
          "lagr_check --ckpt: the Lagrangian mean velocity equals U (%s, exit %d) %s" %
          (mean, rc, err.strip()))
    with h5py.File(ck, "a") as h:
        h["stats/lagrangian/releases"][0] = 399.0
    rc, out, err = run("lagr_check", f, "--ckpt", ck)
    check(rc == 1 and "399 completed releases, the stats.nc 400" in err,
          "lagr_check --ckpt refuses a checkpoint of another state: %s" % err.strip())


def errors():
    missing = os.path.join(WORK, "missing.nc")
    text = os.path.join(WORK, "text.nc")
    with open(text, "w") as f:
        f.write("not netCDF\n")
    bare = os.path.join(WORK, "bare.nc")
    with netCDF4.Dataset(bare, "w") as d:
        root(d, (np.arange(40) + 0.5) * DR)
    cases = [
        (["spectra_compare", missing], "missing.nc: cannot open: No such file"),
        (["spectra_compare", text], "text.nc: cannot open as netCDF"),
        (["spectra_compare", bare], "bare.nc: no group 'correlations'"),
        (["spectra_compare", bare, "--dns", WORK], "no MKM files chanNNN.xspec.N"),
        (["spectra_compare", bare, "--u-tau", "-1"], "argument --u-tau"),
        (["corr_compare", missing], "missing.nc: cannot open: No such file"),
        (["corr_compare", bare], "bare.nc: no group 'correlations'"),
        (["corr_compare", bare, "--tol", "x"], "argument --tol"),
        (["skewflat_compare", text], "text.nc: cannot open as netCDF"),
        (["skewflat_compare", bare], "bare.nc: no group 'eulerian'"),
        (["skewflat_compare", bare, "--dns", text], "text.nc: the flatness file"),
        (["skewflat_compare", bare, "--at", "5,x"], "--at 5,x: expected y"),
        (["lagr_check", missing], "missing.nc: cannot open: No such file"),
        (["lagr_check", bare], "bare.nc: no group 'lagrangian'"),
        (["lagr_check", bare, "--sample-interval", "-1"], "argument --sample-interval"),
    ]
    for args, want in cases:
        rc, out, err = run(*args)
        first = err.splitlines()[0] if err else ""
        ok = (rc == 1 and first.startswith("error: ") and want in first and
              "Traceback" not in out + err)
        check(ok, "%s: exit %d, %r" % (" ".join(os.path.basename(a) for a in args), rc, first))
    f = os.path.join(WORK, "lagr.nc")
    lagr_file(f)
    rc, out, err = run("lagr_check", f, "--ckpt", text)
    check(rc == 1 and "cannot open as HDF5" in err and "Traceback" not in err,
          "lagr_check --ckpt text: %s" % err.strip())


os.makedirs(WORK, exist_ok=True)
{"spectra": spectra, "skewflat": skewflat, "lagr": lagr, "errors": errors}[PART]()
finish(PART)
