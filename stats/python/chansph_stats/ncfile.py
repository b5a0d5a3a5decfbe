"""The one reader of the netCDF files chansph writes (stats.nc, particles.nc).

Usage (with stats/python on sys.path):
    from chansph_stats.ncfile import read_stats, read_particles, read_windows
    s = read_stats("runs/laminar/stats.nc")
    s["y"], s["u_mean"], s["u_mean_stderr"], s["attrs"]["u_tau"], s["series"]["u_bulk"]
    s["groups"]["correlations"]["R_uu_x"], s["groups"]["lagrangian"]["rho_L_u"]
    w = read_windows("runs/ab/stats.nc")   # the raw window records of group eulerian
(docs/stats-format.md lists every variable.) A file that is missing, not netCDF, or lacks
what is asked for raises cli.InputError naming the file and the variable.
Needs python3-netcdf4 and python3-numpy (Debian packages).
"""
import math

import netCDF4
import numpy as np

from .cli import InputError, regular_file

PROFILE_VARS = ("y", "y_mean", "u_mean", "v_mean", "w_mean", "n_samples")


def open_nc(path):
    """netCDF4.Dataset of path (read-only); InputError if it is missing or not netCDF."""
    regular_file(path)
    try:
        return netCDF4.Dataset(path)
    except OSError as e:
        raise InputError("%s: cannot open as netCDF (%s)" % (path, e.strerror or e))


def present(have, name, path, kind, what="a chansph stats.nc"):
    """InputError "PATH: no KIND 'NAME' (not WHAT?)" unless name is in have."""
    if name not in have:
        raise InputError("%s: no %s '%s' (not %s?)" % (path, kind, name, what))


def need(g, name, path, what="a chansph stats.nc"):
    """Variable name of group (or dataset) g; InputError naming path if it is absent."""
    present(g.variables, name, path, "variable", what)
    return g.variables[name]


def need_group(d, name, path, what="a chansph stats.nc"):
    """Group name of dataset d; InputError naming path if it is absent."""
    present(d.groups, name, path, "group", what)
    return d.groups[name]


def attribute(d, name, path, what="a chansph stats.nc"):
    """Global attribute name of d; InputError naming path if it is absent."""
    present(d.ncattrs(), name, path, "global attribute", what)
    return d.getncattr(name)


def attribute_or_nan(d, name):
    """Global attribute name of d as a float; NaN where it is absent (chansph leaves out a value
    it does not know, e.g. u_tau before the first window, docs/stats-format.md)."""
    return float(d.getncattr(name)) if name in d.ncattrs() else float("nan")


def values(var):
    """The values of a variable; the float ones with fill values (no samples) as NaN."""
    data = var[:]
    return data.filled(np.nan) if np.ma.isMaskedArray(data) and data.dtype.kind == "f" \
        else np.asarray(data)


def _group(g):
    out = {name: values(var) for name, var in g.variables.items()}
    out["attrs"] = {k: g.getncattr(k) for k in g.ncattrs()}
    return out


def read_stats(path):
    """Profiles, time series (every variable on the time dimension), global attributes and the
    engine groups (eulerian, correlations, lagrangian) as dicts of arrays."""
    with open_nc(path) as d:
        out = {"attrs": {k: d.getncattr(k) for k in d.ncattrs()}, "series": {}, "groups": {}}
        for name, var in d.variables.items():
            if var.dimensions == ("time",):
                out["series"][name] = values(var)
            else:
                out[name] = values(var)
        for name, g in d.groups.items():
            out["groups"][name] = _group(g)
    return out


def need_keys(s, path, variables=(), attrs=(), what="a chansph stats.nc"):
    """InputError naming path and the first of variables (keys of s) or attrs (keys of
    s["attrs"]) that a read_stats or read_particles dict s lacks (what: what path should be)."""
    for names, have, kind in ((variables, s, "variable"), (attrs, s["attrs"], "global attribute")):
        for name in names:
            present(have, name, path, kind, what)


def read_particles(path):
    """Particle columns (id, x, y, z, u, v, w, rho, p, gamma, mass) and attributes."""
    with open_nc(path) as d:
        out = {name: np.asarray(var[:]) for name, var in d.variables.items()}
        out["attrs"] = {k: d.getncattr(k) for k in d.ncattrs()}
    return out


def read_windows(path):
    """The raw window records of a stats.nc (group eulerian; docs/stats-format.md) as a dict:
    delta, nu, fold, t_reached (None if absent), win (windows: t0, t1, snapshots, sums of the
    body force and of the two walls' shear stress), mom (moments), pln (planes, None in files
    without the momentum budget), done (windows with samples) and ut (u_tau of the force
    balance over them), nwall (the samples of each window that carried the wall stress)."""
    with open_nc(path) as nc:
        g = need_group(nc, "eulerian", path)
        delta, nu, fold = (attribute(nc, k, path) for k in ("delta", "nu", "fold"))
        r = {"delta": float(delta), "nu": float(nu), "fold": int(fold),
             "t_reached": float(nc.t_reached) if "t_reached" in nc.ncattrs() else None,
             "win": np.array(need(g, "windows", path)[:]),
             "mom": np.array(need(g, "moments", path)[:]),
             "pln": np.array(g["planes"][:]) if "planes" in g.variables else None}
    if r["win"].ndim != 2 or r["win"].shape[0] == 0:
        raise InputError(f"{path}: no averaging window (the run has not begun averaging?)")
    r["done"] = r["win"][:, 2] > 0
    r["ut"] = u_tau_force(r["win"], r["delta"])
    # the samples that carried the wall stress: the budget samples (every stats.budget_every-th),
    # counted by the planes; every sample in files without them
    r["nwall"] = r["pln"][:, 0, 0] if r["pln"] is not None else r["win"][:, 2]
    return r


def u_tau_force(win, delta):
    """u_tau of the force balance, u_tau^2 = delta f, f the mean body force of the windows."""
    return math.sqrt(max(delta * win[:, 3].sum() / max(win[:, 2].sum(), 1), 0.0))


def laminar_profile(attrs, y):
    """Analytical Poiseuille velocity for the run's body force: f y (2 delta - y) / (2 nu)."""
    return attrs["body_force"] * y * (2 * attrs["delta"] - y) / (2 * attrs["nu"])
