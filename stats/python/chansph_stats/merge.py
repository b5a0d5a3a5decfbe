"""Window records of stats.nc merged into profiles in wall units (the Python side of
`chansph extract --window`; tests/window_profile_check.py holds the two together).

The raw records of group eulerian (docs/stats-format.md): per window and bin, `moments` holds
the sample count (MOM_N), the means (MEAN: u v w p rho y ...) and the co-moments (C2: uu vv ww
uv ...); `planes` the momentum-budget sums (PL). Wall units: u_tau of the force balance
(u_tau^2 = delta f, read_windows' "ut") or of the mean wall shear stress of the windows taken.
With fold = 0 the upper half is mirrored onto the lower one (-u'v' and the stresses change sign).
"""
import math
import os

import numpy as np

from .cli import InputError
from .ncfile import read_windows

MOM_N, MEAN = 0, 1
C2 = MEAN + 8
PL = {"n": 0, "pair": 1, "visc": 2, "model": 3, "wall": 4, "drive": 5, "source": 6}


def window_values(mom, pln, delta, fold, ut, nu):
    """Per-window indicators (arrays over the windows given)."""
    out = []
    for m, p in zip(mom, pln):
        n = m[:, MOM_N]
        ok = n > 0
        y = m[:, MEAN + 5]
        uu, vv, uv = (np.where(ok, m[:, C2 + k] / np.maximum(n, 1), np.nan) for k in (0, 1, 3))
        u = m[:, MEAN]
        if not fold:
            up = y > delta
            y = np.where(up, 2 * delta - y, y)
            uv = np.where(up, -uv, uv)
        yp = y * ut / nu
        muv = -uv / ut**2
        k = int(np.nanargmax(muv))
        band = ok & (yp >= 30) & (yp <= 100)
        r = dict(uv_peak=muv[k], y_peak=yp[k], urms=np.nanmax(np.sqrt(uu)) / ut,
                 vrms=np.nanmax(np.sqrt(vv)) / ut,
                 ruv=np.nanmean(-uv[band] / np.sqrt(uu[band] * vv[band])) if band.any() else math.nan,
                 ub=np.sum(u[ok] * n[ok]) / np.sum(n[ok]) / ut)
        if p is not None and p[:, 0].max() > 0:
            pn = np.maximum(p[:, 0], 1)
            parts = {key: p[:, i] / pn for key, i in PL.items() if key != "n"}
            if not fold:  # mirrored like -u'v' above: the stresses of the upper half change sign
                for key in parts:
                    parts[key] = np.where(up, -parts[key], parts[key])
            rey = -uv  # -u'v' towards the centre (upper half mirrored above)
            total = rey + parts["pair"] + parts["visc"] + parts["model"] + parts["wall"]
            for name, target in (("12", 12.0), ("30", 30.0), ("half", 0.5 * delta * ut / nu)):
                i = int(np.nanargmin(np.abs(yp - target) + np.where(ok, 0, np.inf)))
                r["res_" + name] = rey[i] / total[i]
                r["pair_" + name] = parts["pair"][i] / total[i]
                r["model_" + name] = parts["model"][i] / total[i]
            r["closure"] = np.nanmax(np.abs(total - parts["drive"])) / ut**2
            r["source"] = np.nanmean(parts["source"]) / ut**2
        out.append(r)
    return out


CY = C2 + 6 + 6  # the co-moments of u, v, w with y, then of y with y (format 1.12 records)
CYY = CY + 3


def deriv(x, f, ok, i):
    """euler_deriv (stats/euler_rs.c): 3-point central derivative of f at i between the nearest
    bins with ok on each side, one-sided where only one exists."""
    n = len(x)
    lo = next((j for j in range(i - 1, -1, -1) if ok[j]), -1)
    hi = next((j for j in range(i + 1, n) if ok[j]), n)
    if lo < 0 and hi >= n:
        return math.nan
    if lo < 0:
        return (f[hi] - f[i]) / (x[hi] - x[i])
    if hi >= n:
        return (f[i] - f[lo]) / (x[i] - x[lo])
    h1, h2 = x[i] - x[lo], x[hi] - x[i]
    return (-h2 / (h1 * (h1 + h2))) * f[lo] + ((h2 - h1) / (h1 * h2)) * f[i] + \
        (h1 / (h2 * (h1 + h2))) * f[hi]


def local_slope(x, f, ok, i):
    """local_slope (stats/euler.c): deriv inside, the parabola through i and its next two
    neighbours at an end."""
    n = len(x)
    lo = next((j for j in range(i - 1, -1, -1) if ok[j]), -1)
    hi = next((j for j in range(i + 1, n) if ok[j]), n)
    if (lo >= 0) == (hi < n):
        return deriv(x, f, ok, i)
    step = 1 if lo < 0 else -1
    j1 = hi if lo < 0 else lo
    j2 = next((j for j in range(j1 + step, n if step > 0 else -1, step) if ok[j]), None)
    if j2 is None:
        return deriv(x, f, ok, i)
    x0, x1, x2 = x[i], x[j1], x[j2]
    return f[i] * (2 * x0 - x1 - x2) / ((x0 - x1) * (x0 - x2)) + \
        f[j1] * (x0 - x2) / ((x1 - x0) * (x1 - x2)) + f[j2] * (x0 - x1) / ((x2 - x0) * (x2 - x1))


def merged_moments(r, sel):
    """The profiles of the windows sel of a read_windows record in SI units, as chansph extract
    forms them: ok (bins with samples), y (mean position), u, v, w (means), uu, vv, ww, uv
    (NaN where a bin has no sample): the counts, means and co-moments merged (Chan et al.
    1979); the stresses about the local mean U(y) = U + g (y - <y>) of each bin where the
    records hold the co-moments with y (format 1.12), else about the bin mean."""
    mom = r["mom"]
    n = mom[sel][:, :, MOM_N].sum(axis=0)
    ok = n > 0
    nn = np.maximum(n, 1)
    mean = sum(mom[i][:, MEAN:MEAN + 8] * mom[i][:, [MOM_N]] for i in sel) / nn[:, None]
    pairs = ((0, 0), (1, 1), (2, 2), (0, 1))  # uu vv ww uv
    c2 = np.zeros((len(n), len(pairs)))
    cy, cyy = np.zeros((len(n), 3)), np.zeros(len(n))
    local = mom.shape[2] > CYY
    for i in sel:
        d = mom[i][:, MEAN:MEAN + 6] - mean[:, :6]
        for c, (p, q) in enumerate(pairs):
            c2[:, c] += mom[i][:, C2 + c] + mom[i][:, MOM_N] * d[:, p] * d[:, q]
        if local:
            for k in range(3):
                cy[:, k] += mom[i][:, CY + k] + mom[i][:, MOM_N] * d[:, k] * d[:, 5]
            cyy += mom[i][:, CYY] + mom[i][:, MOM_N] * d[:, 5] ** 2
    if local:
        for b in np.nonzero(ok)[0]:
            g = [local_slope(mean[:, 5], mean[:, k], ok, b) for k in range(3)]
            g = [x if math.isfinite(x) else 0.0 for x in g]
            if not (np.isfinite(cy[b]).all() and math.isfinite(cyy[b])):
                continue
            for c, (p, q) in enumerate(pairs):
                c2[b, c] += -g[p] * cy[b, q] - g[q] * cy[b, p] + g[p] * g[q] * cyy[b]
    out = {"ok": ok, "y": np.where(ok, mean[:, 5], np.nan)}
    for k, name in enumerate(("u", "v", "w")):
        out[name] = np.where(ok, mean[:, k], np.nan)
    for c, name in enumerate(("uu", "vv", "ww", "uv")):
        out[name] = np.where(ok, c2[:, c] / nn, np.nan)
    return out


def merged_profile(r, sel):
    """Profiles of U+, u_rms+, v_rms+, w_rms+, -u'v'+ (force-balance wall units) over the windows
    sel of a read_windows record (merged_moments); the upper half of an unfolded file mirrored
    onto the lower one."""
    m = merged_moments(r, sel)
    y, u, uu, vv, ww, uv = (m[k] for k in ("y", "u", "uu", "vv", "ww", "uv"))
    delta, ut = r["delta"], r["ut"]
    if not r["fold"]:
        up = y > delta
        y = np.where(up, 2 * delta - y, y)
        uv = np.where(up, -uv, uv)
    return {"yplus": y * ut / r["nu"], "y_delta": y / delta, "U+": u / ut,
            "u_rms+": np.sqrt(uu) / ut, "v_rms+": np.sqrt(vv) / ut, "w_rms+": np.sqrt(ww) / ut,
            "-u'v'+": -uv / ut**2}


def peak_position(yplus, f):
    """y+ of the maximum of the binned profile f: the vertex of the parabola through the largest
    bin and its two neighbours (bins of any spacing), or the largest bin's y+ where it is the
    first or the last finite one or the three points do not bend downwards."""
    yplus, f = np.asarray(yplus, dtype=float), np.asarray(f, dtype=float)
    ok = np.flatnonzero(np.isfinite(f))
    if ok.size == 0:
        return math.nan
    j = int(np.argmax(f[ok]))
    if j == 0 or j == ok.size - 1:
        return float(yplus[ok[j]])
    (x0, x1, x2), (f0, f1, f2) = yplus[ok[j - 1:j + 2]], f[ok[j - 1:j + 2]]
    d01, d12 = (f1 - f0) / (x1 - x0), (f2 - f1) / (x2 - x1)
    curv = (d12 - d01) / (x2 - x0)
    if not curv < 0:
        return float(x1)
    # f = f1 + d (x - x1) + curv (x - x1)^2 with d the slope at x1 of the parabola
    d = d01 + curv * (x1 - x0)
    return float(x1 - d / (2 * curv))


def pooled_windows(dirs, t0, t1, units="force"):
    """The completed windows inside [t0, t1] of a series, pooled: its runs' window records (a
    later run's time follows the earlier one's last window, as error_vs_time does). Returns
    (pool, times): pool a read_windows record whose "mom" holds the windows taken, with "ut" in
    the units asked ("force": u_tau^2 = delta f; "wall": the mean wall shear stress of the
    windows taken, both walls, as `chansph extract --units wall`), times their (start, end)."""
    t_off, pool, times, wall = 0.0, None, [], np.zeros(2)
    for run in dirs.split("+"):
        r = read_windows(os.path.join(run, "stats.nc"))
        win = r["win"].copy()
        win[:, :2] += t_off
        sel = [i for i in range(len(win)) if r["done"][i] and win[i, 0] >= t0 - 1e-9
               and win[i, 1] <= t1 + 1e-9]
        if sel:
            times += [(win[i, 0], win[i, 1]) for i in sel]
            wall += (win[sel, 4].sum() + win[sel, 5].sum(), 2 * r["nwall"][sel].sum())
            if pool is None:
                pool = dict(r, mom=r["mom"][sel])
            else:
                if r["mom"].shape[1:] != pool["mom"].shape[1:] or r["fold"] != pool["fold"]:
                    raise InputError(f"{run}: its bins differ from the earlier run's")
                pool["mom"] = np.concatenate((pool["mom"], r["mom"][sel]))
        t_off = win[r["done"]][-1, 1]
    if pool is None:
        raise InputError(f"{dirs}: no completed window inside {t0}-{t1}")
    if units == "wall":
        pool["ut"] = math.sqrt(max(wall[0] / max(wall[1], 1), 0.0))
    return pool, times


def window_profile(dirs, t0, t1, units="force"):
    """Profiles over [t0, t1] of a series (pooled_windows), and the span of the windows taken."""
    pool, times = pooled_windows(dirs, t0, t1, units)
    return merged_profile(pool, list(range(len(pool["mom"])))), (times[0][0], times[-1][1])
