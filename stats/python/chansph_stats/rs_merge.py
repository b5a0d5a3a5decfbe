"""The Reynolds-stress budgets (rsb_*) of any range of a stats.nc's windows, from the raw
window records of group eulerian: the Python side of euler_rs_profiles (stats/euler_rs.c,
docs/stats-format.md "Reynolds-stress budgets"), so that a tool can re-average the budgets
over the first n windows as `chansph extract --window` does over a range.

The records (variable `reynolds_budget`, fields `reynolds_budget_field`) are the format 1.11
layout and later (252 fields: the sums of each part by node of the local mean); the records of
an earlier format are not read (rs_records returns None, as `chansph extract` leaves them out).
The local mean's node values, the terms, the production from the range's profiles and the
batch-means standard errors over the complete windows follow the C code line by line.
"""
import math

import numpy as np

from .merge import deriv, merged_moments

# the layout of euler_rs.h: parts, products, nodes, quantities of one block and of a record
PARTS = ("pressure", "viscous", "model", "wall", "body", "pressure_noise")
NPART, NPROD, NODE, NQ = 6, 5, 3, 19
RQ_UU, RQ_VV, RQ_WW, RQ_UV, RQ_MU, RQ_PP = 1, 2, 3, 4, 5, 14
RB_N, RB_TAU, RB_MASS, RB_S = 0, 1, 2, 3
RB_F = RB_S + NPART * NPROD
RB_K = RB_F + NPART * NODE * 3
RB_LEN = RB_K + NQ
RW_FIRST, RW_Q_FIRST = RB_LEN, 2 * RB_LEN
RW_Q_LAST = RW_Q_FIRST + NQ
RW_T_FIRST, RW_T_LAST = RW_Q_LAST + NQ, RW_Q_LAST + NQ + 1
RW_LEN = RW_T_LAST + 1

# the terms (euler.h RT_*), the components (RS_UU ..) with their velocity indices, products
TERMS = ("pressure", "viscous", "model", "wall", "drive", "transfer", "production", "transport",
         "rate", "closure", "pressure_noise")
COMPS = ("uu", "vv", "ww", "uv", "k")
COMP_IJ = ((0, 0), (1, 1), (2, 2), (0, 1))
COMP_Q = (RQ_UU, RQ_VV, RQ_WW, RQ_UV)
COMP_PROD = ((0, 0), (1, 1), (2, 2), (3, 4))
T = {name: i for i, name in enumerate(TERMS)}


def rs_records(nc, path):
    """(records [window][bin][field], config) of group eulerian of an open stats.nc, or None
    when the file has none of the current layout. config: nb, y0, y1, fold, delta."""
    g = nc["eulerian"]
    if "reynolds_budget" not in g.variables or "reynolds_budget_field" not in g.variables:
        return None
    names = [str(x) for x in g["reynolds_budget_field"][:]]
    if (len(names) != RW_LEN or names[RB_S] != "sum_pressure_ubx_Ax" or
            names[RB_F] != "sum_pressure_Ax_lower" or names[RW_T_FIRST] != "time_first"):
        return None
    rsb = np.ma.filled(g["reynolds_budget"][:].astype(float), 0.0)
    cfg = {"nb": rsb.shape[1], "y0": float(nc.bin_lower), "y1": float(nc.bin_upper),
           "fold": int(nc.fold), "delta": float(nc.delta)}
    return rsb, cfg


def weights(cfg, y):
    """weights() of euler_rs.c: the first node k of the two that make U(y) and their weights."""
    nb, y0, y1 = cfg["nb"], cfg["y0"], cfg["y1"]
    x = (y - y0) * (nb / (y1 - y0)) - 0.5
    if not x > 0.0:
        b, s = 0, 0.0
    elif x >= nb - 1:
        b, s = nb - 1, 0.0
    else:
        b = int(x)
        s = x - b
    k, psi = b, (1.0 - s, s)
    w = (y1 - y0) / nb
    lo, hi = y0 + 0.5 * w, y1 - 0.5 * w
    if nb < 2:
        return k, psi
    if y < lo:
        r = (lo - y) / w
        psi = (1.0 + r, -r)
    elif y > hi and not cfg["fold"]:
        r = (y - hi) / w
        k, psi = b - 1, (-r, 1.0 + r)
    return k, psi


def node_values(cfg, prof, ok):
    """node_values() of euler_rs.c: the local mean's values at the bin centres, [nb][3]."""
    nb, y0, y1 = cfg["nb"], cfg["y0"], cfg["y1"]
    w = (y1 - y0) / nb
    out = np.zeros((nb, 3))
    for d, key in enumerate(("u", "v", "w")):
        x, f = [0.0], [0.0]
        for b in range(nb):
            if ok[b]:
                x.append(prof["y"][b])
                f.append(prof[key][b])
        if not cfg["fold"]:
            x.append(2.0 * cfg["delta"])
            f.append(0.0)
        n, k = len(x), 0
        for b in range(nb):
            y = y0 + (b + 0.5) * w
            while k + 1 < n and x[k + 1] < y:
                k += 1
            h = x[k + 1] - x[k] if k + 1 < n else 0.0
            out[b, d] = (f[k] + (f[k + 1] - f[k]) * min(max((y - x[k]) / h, 0.0), 1.0)
                         if h > 0.0 else f[k])
        lo, di, up, rhs = np.zeros(nb), np.ones(nb), np.zeros(nb), out[:, d].copy()
        for b in range(nb):
            if not ok[b]:
                continue
            kk, psi = weights(cfg, prof["y"][b])
            if kk == b:
                di[b], up[b], rhs[b] = psi[0], psi[1], prof[key][b]
            elif kk == b - 1:
                lo[b], di[b], rhs[b] = psi[0], psi[1], prof[key][b]
        good = True  # Thomas algorithm
        for b in range(1, nb):
            good = abs(di[b - 1]) > 1e-9
            if not good:
                break
            r = lo[b] / di[b - 1]
            di[b] -= r * up[b - 1]
            rhs[b] -= r * rhs[b - 1]
        good = good and abs(di[nb - 1]) > 1e-9
        sol = np.zeros(nb)
        for b in range(nb - 1, -1, -1):
            if not good:
                break
            sol[b] = (rhs[b] - (up[b] * sol[b + 1] if b + 1 < nb else 0.0)) / di[b]
            good = math.isfinite(sol[b])
        if good:
            out[:, d] = sol
    return out


def centred(Q, c, Un):
    """sum phi m (u_i - U_i)(u_j - U_j) of component c from the quantities Q of a bin."""
    i, j = COMP_IJ[c]
    e = Q[COMP_Q[c]]
    for n in range(NODE):
        mu = Q[RQ_MU + 3 * n:RQ_MU + 3 * n + 3]
        e -= Un[n][i] * mu[j] + Un[n][j] * mu[i]
        e += Un[n][i] * Un[n][j] * Q[RQ_PP + 2 * n]
        if n + 1 < NODE:
            e += (Un[n][i] * Un[n + 1][j] + Un[n + 1][i] * Un[n][j]) * Q[RQ_PP + 2 * n + 1]
    return e


def terms(B, Q0, Q1, t0, t1, Un, dudy, uv, vv):
    """terms() and derived() of euler_rs.c: [component][term] of a block of sums."""
    out = np.zeros((len(COMPS), len(TERMS)))
    mass, mean_mass = B[RB_MASS], B[RB_MASS] / B[RB_TAU]
    for c in range(4):
        i, j = COMP_IJ[c]
        for k in range(NPART):
            S = B[RB_S + k * NPROD:RB_S + (k + 1) * NPROD]
            v = S[COMP_PROD[c][0]] + S[COMP_PROD[c][1]]
            for n in range(NODE):
                F = B[RB_F + (n * NPART + k) * 3:RB_F + (n * NPART + k) * 3 + 3]
                v -= Un[n][i] * F[j] + Un[n][j] * F[i]
            t = T["drive"] if k == 4 else T["pressure_noise"] if k == 5 else k
            out[c, t] = v / mass
        out[c, T["transfer"]] = centred(B[RB_K:RB_LEN], c, Un) / mass
        e0, e1 = centred(Q0, c, Un), centred(Q1, c, Un)
        out[c, T["rate"]] = (e1 - e0) / (t1 - t0) / mean_mass if t1 > t0 else math.nan
    prod = (-2.0 * uv * dudy, 0.0, 0.0, -vv * dudy)
    for c in range(4):
        out[c, T["production"]] = prod[c]
        out[c, T["transport"]] = out[c, T["transfer"]] - prod[c]
        out[c, T["closure"]] = (out[c, :T["transfer"] + 1].sum() - out[c, T["rate"]])
    out[4] = 0.5 * (out[0] + out[1] + out[2])
    return out


def rs_range(r, rsb, cfg, rows, complete, bins):
    """The budget terms of the range rows (window indices, ascending) at the bins given, and
    their batch-means standard errors over the complete windows of the range:
    ({bin: [component][term]}, {bin: [component][term] stderr}), NaN where a bin has none."""
    prof = merged_moments(r, [i for i in rows if r["done"][i]])
    ok = prof["ok"]
    Uc = node_values(cfg, prof, ok)
    nb = cfg["nb"]
    value, stderr = {}, {}
    for b in bins:
        nan = np.full((len(COMPS), len(TERMS)), math.nan)
        value[b], stderr[b] = nan, nan.copy()
        if not ok[b]:
            continue
        Un = [Uc[b + n - 1] if 0 <= b + n - 1 < nb else np.zeros(3) for n in range(NODE)]
        dudy = deriv(prof["y"], prof["u"], ok, b)
        total, first, last, batches = np.zeros(RB_LEN), None, None, []
        for i in rows:
            W = rsb[i, b]
            if W[RB_N] <= 0.0:
                continue
            first = W if first is None else first
            last = W
            total += W[:RB_LEN]
            if not complete[i] or W[RB_N] < 2.0:
                continue
            blk = W[:RB_LEN] - W[RW_FIRST:RW_FIRST + RB_LEN]
            if not blk[RB_MASS] > 0.0:
                continue
            batches.append(terms(blk, W[RW_Q_FIRST:RW_Q_LAST], W[RW_Q_LAST:RW_T_FIRST],
                                 W[RW_T_FIRST], W[RW_T_LAST], Un, dudy, prof["uv"][b],
                                 prof["vv"][b]))
        if first is None:
            continue
        total -= first[RW_FIRST:RW_FIRST + RB_LEN]
        if total[RB_N] < 1.0 or not total[RB_MASS] > 0.0:
            continue
        value[b] = terms(total, first[RW_Q_FIRST:RW_Q_LAST], last[RW_Q_LAST:RW_T_FIRST],
                         first[RW_T_FIRST], last[RW_T_LAST], Un, dudy, prof["uv"][b],
                         prof["vv"][b])
        if len(batches) >= 2:
            stderr[b] = np.std(np.array(batches), axis=0, ddof=1) / math.sqrt(len(batches))
    return value, stderr
