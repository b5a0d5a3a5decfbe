#!/usr/bin/python3
"""Reduce a chansph particles.nc to a shipped state: the variables init.from reads (id x y z u v
w rho mass) and the global attributes, the floating-point variables as float32, deflated.

usage: python3 jobs/states/reduce_state.py RUN/particles.nc jobs/states/NAME.nc
       python3 jobs/states/reduce_state.py RUN/checkpoints/ckpt_N.h5 jobs/states/NAME.nc

From a checkpoint (a run stopped early writes no particles.nc): its fluid particles, ids
renumbered 0 .. n-1 in id order, and its scene text as the scene attribute.

float32 keeps about 7 digits: positions to 1e-7 of the domain, velocities to 1e-7 of U_max,
the density to 1e-4 kg/m^3 (a pressure error of c0^2 x 1e-4 / rho0 u_tau^2, below 0.3% of
tau_w in the Re_tau = 180 scenes). A run started from it is a continuation of the state, not a
bitwise restart (use a checkpoint for that).
"""
import os
import sys

import netCDF4
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ncfile import need, open_nc  # noqa: E402

STATE_VARS = ("id", "x", "y", "z", "u", "v", "w", "rho", "mass")


def from_checkpoint(path, state):
    """The fluid particles of checkpoint path as a state file."""
    from chansph_stats.ckpt import read_checkpoint
    c = read_checkpoint(path)
    f = c["fluid"]
    names = {"mass": "mass"}
    try:
        dst = netCDF4.Dataset(state, "w", format="NETCDF4")
    except OSError as e:
        raise cli.InputError(f"{state}: cannot create: {e.strerror or e}")
    with dst:
        dst.setncatts({"scene": c["scene"], "time": float(c["time"]), "step": int(c["step"]),
                       "source": f"chansph checkpoint {os.path.basename(path)}"})
        dst.createDimension("particle", int(f.sum()))
        for name in STATE_VARS:
            kind = "i8" if name == "id" else "f4"
            v = dst.createVariable(name, kind, ("particle",), zlib=True, complevel=9, shuffle=True)
            if name == "id":
                v[:] = np.arange(int(f.sum()), dtype="i8")
            else:
                v[:] = np.asarray(c["particles"][names.get(name, name)][f]).astype(kind)


def main():
    p = cli.parser("reduce_state.py", __doc__)
    p.add_argument("particles", metavar="RUN/particles.nc")
    p.add_argument("state", metavar="jobs/states/NAME.nc")
    a = p.parse_args()
    if a.particles.endswith(".h5"):
        return from_checkpoint(a.particles, a.state)
    with open_nc(a.particles) as src:
        for name in STATE_VARS:
            need(src, name, a.particles, "a chansph particles.nc")
        try:
            dst = netCDF4.Dataset(a.state, "w", format="NETCDF4")
        except OSError as e:
            raise cli.InputError(f"{a.state}: cannot create: {e.strerror or e}")
        with dst:
            dst.setncatts({k: src.getncattr(k) for k in src.ncattrs()})
            for name, dim in src.dimensions.items():
                dst.createDimension(name, len(dim))
            for name in STATE_VARS:
                v = src[name]
                kind = "i8" if name == "id" else "f4"
                out = dst.createVariable(name, kind, v.dimensions, zlib=True, complevel=9,
                                         shuffle=True)
                out.setncatts({k: v.getncattr(k) for k in v.ncattrs() if k != "_FillValue"})
                out[:] = np.asarray(v[:]).astype(kind)


sys.exit(cli.run(main))
