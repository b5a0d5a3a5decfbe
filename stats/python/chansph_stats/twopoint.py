"""What spectra_compare and corr_compare share: the group correlations of a stats.nc, the MKM
Re_tau = 180 files of one kind (chan180.xspec.N, chan180.zcorr.N, ...) by their y+, and the
u_tau that makes wall units.

The MKM files (stats/dns/mkm1999/spectra, correlations; README there) are in units of u_tau
and delta ("Normalization: U_tau, h"); each names its exact y+ in a line
"# nx = 128,  Re = 178.12,  y = 0.16853,  y+ =  30.02".
"""
import glob
import math
import os
import re

import numpy as np

from .cli import InputError
from .dns import numeric_rows
from .ncfile import attribute, need, need_group, open_nc, values

COMP = ("u", "v", "w")
DNS_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "dns", "mkm1999")


def u_tau_arg(text):
    """argparse type of --u-tau: force, wall or a positive number [m/s]."""
    if text in ("force", "wall"):
        return text
    try:
        x = float(text)
    except ValueError:
        x = float("nan")
    if not (math.isfinite(x) and x > 0):
        import argparse
        raise argparse.ArgumentTypeError("%r: expected force, wall or a positive number" % text)
    return x


def read_corr(path, u_tau="force"):
    """Group correlations of a stats.nc as a dict of arrays plus the scalars: delta, nu, lx, lz,
    u_tau (as chosen: the force balance u_tau_force, the wall stress u_tau_wall, or a value),
    n_windows, t range. InputError names the file and the missing group or variable."""
    with open_nc(path) as nc:
        g = need_group(nc, "correlations", path)
        r = {name: values(need(g, name, path)) for name in
             ("y_plus", "level", "samples", "separation_x", "separation_z", "kx", "kz")}
        for c in COMP:
            for d in "xz":
                r["R_%s%s_%s" % (c, c, d)] = values(need(g, "R_%s%s_%s" % (c, c, d), path))
                r["E_%s%s_k%s" % (c, c, d)] = values(need(g, "E_%s%s_k%s" % (c, c, d), path))
                for se in ("R_%s%s_%s_stderr" % (c, c, d), "rho_%s%s_%s_stderr" % (c, c, d)):
                    if se in g.variables:  # batch means (format 1.8 on)
                        r[se] = values(g.variables[se])
        for k in ("delta", "nu", "lx", "lz"):
            r[k] = float(attribute(nc, k, path))
        r["u_tau"] = pick_u_tau(nc, path, u_tau)
        n_cells = len(g.dimensions["separation_x"]) * len(g.dimensions["separation_z"])
        r["empty"] = (values(g.variables["empty_cells"]) / np.maximum(r["samples"], 1) / n_cells
                      if "empty_cells" in g.variables else np.full(len(r["samples"]), np.nan))
        r["gap"] = (values(g.variables["gap_corrected"]).astype(int)
                    if "gap_corrected" in g.variables else np.zeros(len(r["samples"]), int))
        r["eul"] = {k: values(nc.variables[k]) for k in ("y_mean", "n_samples", "uu", "vv", "ww")
                    if k in nc.variables}
        r["n_windows"] = int(nc.getncattr("n_windows")) if "n_windows" in nc.ncattrs() else 0
        r["t"] = tuple(float(nc.getncattr(k)) if k in nc.ncattrs() else float("nan")
                       for k in ("average_start", "average_end"))
    if not np.any(r["samples"] > 0):
        raise InputError("%s: group correlations has no samples (the run has not sampled yet?)"
                         % path)
    return r


def pick_u_tau(nc, path, how):
    """u_tau of a stats.nc: the attribute u_tau_force or u_tau_wall, or the number how."""
    if not isinstance(how, str):
        return float(how)
    name = "u_tau_" + how
    return float(attribute(nc, name, path, "a chansph stats.nc with samples"))


def dns_files(folder, kind):
    """{y+: file} of the MKM files chanNNN.KIND.N of folder (y+ from each file's header)."""
    out = {}
    for f in sorted(glob.glob(os.path.join(folder, "chan*.%s.*" % kind))):
        with open(f, encoding="utf-8", errors="replace") as h:
            m = re.search(r"y\+ =\s*([0-9.]+)", h.read())
        if m:
            out[float(m.group(1))] = f
    if not out:
        raise InputError("%s: no MKM files chanNNN.%s.N with a 'y+ =' header line" %
                         (folder, kind))
    return out


def dns_table(path, ncol, what):
    """The numeric rows of an MKM file as an array (checked by dns.numeric_rows)."""
    rows, _ = numeric_rows(path, ncol, what)
    return np.asarray(rows)


def nearest(levels, yp):
    """The DNS y+ nearest to yp, or None when it is more than 10% + 1 wall unit away."""
    near = min(levels, key=lambda k: abs(k - yp))
    return near if abs(near - yp) <= 0.1 * yp + 1.0 else None


def run_y_plus(r, lev):
    """y+ of a level in the chosen u_tau (the y_plus variable is in stats.u_tau_ref)."""
    return r["level"][lev] * r["u_tau"] / r["nu"]


def eulerian_variance(r, lev, c):
    """The root profile <c'c'> interpolated to the level's height [m^2/s^2] (NaN if absent)."""
    e = r["eul"]
    if len(e) < 5:
        return float("nan")
    ok = e["n_samples"] > 0
    return float(np.interp(r["level"][lev], e["y_mean"][ok], e[c + c][ok]))


def header(r, path):
    print("# %s: %d complete windows, t = %g .. %g s; wall units of u_tau = %.5g m/s "
          "(Re_tau %.1f); lx = %g delta, lz = %g delta" %
          (path, r["n_windows"], r["t"][0], r["t"][1], r["u_tau"],
           r["u_tau"] * r["delta"] / r["nu"], r["lx"] / r["delta"], r["lz"] / r["delta"]))


def save(fig, path):
    """Write a figure as a small PNG (the directory must exist)."""
    fig.savefig(path, dpi=72)
    print("# wrote %s" % path)


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def out_dir(path):
    """--out DIR: created if missing; InputError if it is a file."""
    if os.path.exists(path) and not os.path.isdir(path):
        raise InputError("%s: not a directory (--out)" % path)
    os.makedirs(path, exist_ok=True)
    return path
