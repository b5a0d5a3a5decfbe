#!/usr/bin/python3
"""Reduce a chansph particles.nc to a shipped state: the variables init.from reads (id x y z u v
w rho mass) and the global attributes, the floating-point variables as float32, deflated.

usage: python3 jobs/states/reduce_state.py RUN/particles.nc jobs/states/NAME.nc

float32 keeps about 7 digits: positions to 1e-7 of the domain, velocities to 1e-7 of U_max,
the density to 1e-4 kg/m^3 (a pressure error of c0^2 x 1e-4 / rho0 u_tau^2, below 0.3% of
tau_w in the Re_tau = 180 scenes). A run started from it is a continuation of the state, not a
bitwise restart (use a checkpoint for that).
"""
import sys

import netCDF4
import numpy as np

src_path, dst_path = sys.argv[1:3]
src = netCDF4.Dataset(src_path)
dst = netCDF4.Dataset(dst_path, "w", format="NETCDF4")
dst.setncatts({k: src.getncattr(k) for k in src.ncattrs()})
for name, dim in src.dimensions.items():
    dst.createDimension(name, len(dim))
for name in ("id", "x", "y", "z", "u", "v", "w", "rho", "mass"):
    v = src[name]
    kind = "i8" if name == "id" else "f4"
    out = dst.createVariable(name, kind, v.dimensions, zlib=True, complevel=9, shuffle=True)
    out.setncatts({k: v.getncattr(k) for k in v.ncattrs() if k != "_FillValue"})
    out[:] = np.asarray(v[:]).astype(kind)
dst.close()
