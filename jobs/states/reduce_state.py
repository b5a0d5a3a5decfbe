#!/usr/bin/python3
"""Reduce a chansph particles.nc to a shipped state: the variables init.from reads (id x y z u v
w rho mass) and the global attributes, the floating-point variables as float32, deflated.

usage: python3 jobs/states/reduce_state.py RUN/particles.nc jobs/states/NAME.nc

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


def main():
    p = cli.parser("reduce_state.py", __doc__)
    p.add_argument("particles", metavar="RUN/particles.nc")
    p.add_argument("state", metavar="jobs/states/NAME.nc")
    a = p.parse_args()
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
