"""Readers for the netCDF files chansph writes (stats.nc, particles.nc).

Usage:
    from chansph_nc import read_stats, read_particles
    s = read_stats("runs/laminar/stats.nc")
    s["y"], s["u_mean"], s["u_mean_stderr"], s["attrs"]["u_tau"], s["series"]["u_bulk"]
    s["groups"]["correlations"]["R_uu_x"], s["groups"]["lagrangian"]["rho_L_u"]
(docs/stats-format.md lists every variable)
Needs python3-netcdf4 and python3-numpy (Debian packages).
"""
import netCDF4
import numpy as np

PROFILE_VARS = ("y", "y_mean", "u_mean", "v_mean", "w_mean", "n_samples")


def _values(var):
    data = var[:]
    return data.filled(np.nan) if np.ma.isMaskedArray(data) and data.dtype.kind == "f" \
        else np.asarray(data)


def _group(g):
    out = {name: _values(var) for name, var in g.variables.items()}
    out["attrs"] = {k: g.getncattr(k) for k in g.ncattrs()}
    return out


def read_stats(path):
    """Profiles, time series (every variable on the time dimension), global attributes and the
    engine groups (eulerian, correlations, lagrangian) as dicts of arrays."""
    with netCDF4.Dataset(path) as d:
        out = {"attrs": {k: d.getncattr(k) for k in d.ncattrs()}, "series": {}, "groups": {}}
        for name, var in d.variables.items():
            if var.dimensions == ("time",):
                out["series"][name] = _values(var)
            else:
                out[name] = _values(var)
        for name, g in d.groups.items():
            out["groups"][name] = _group(g)
    return out


def read_particles(path):
    """Particle columns (id, x, y, z, u, v, w, rho, p, gamma, mass) and attributes."""
    with netCDF4.Dataset(path) as d:
        out = {name: np.asarray(var[:]) for name, var in d.variables.items()}
        out["attrs"] = {k: d.getncattr(k) for k in d.ncattrs()}
    return out


def laminar_profile(attrs, y):
    """Analytical Poiseuille velocity for the run's body force: f y (2 delta - y) / (2 nu)."""
    return attrs["body_force"] * y * (2 * attrs["delta"] - y) / (2 * attrs["nu"])
