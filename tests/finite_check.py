#!/usr/bin/env python3
"""Every floating-point value in the given chansph files is finite (issue 13, point 1).

usage: finite_check.py [--allow NAME ...] FILE... (HDF5 checkpoints and snapshots *.h5, netCDF stats.nc and
particles.nc *.nc); prints each file with its number of values, exits 1 naming the first
variable that holds a NaN or an infinity. In netCDF files, values equal to _FillValue (no
samples) are masked and not counted. --allow NAME: a variable that may be infinite (a
checkpoint's output/next_write is +inf when stats.nc is written only at the end).
"""
import sys

import h5py
import netCDF4
import numpy as np


def h5_vars(path):
    out = []
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                out.append((name, np.asarray(obj[()])))
        f.visititems(visit)
    return out


def nc_vars(path):
    out = []
    with netCDF4.Dataset(path) as d:
        def walk(g, prefix):
            for name, v in g.variables.items():
                if getattr(v.dtype, "kind", "") == "f":  # not the string labels
                    a = np.ma.asarray(v[:])
                    out.append((prefix + name, np.ma.compressed(a)))
            for name, sub in g.groups.items():
                walk(sub, prefix + name + "/")
        walk(d, "")
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    args, allow, status = sys.argv[1:], set(), 0
    while len(args) > 1 and args[0] == "--allow":
        allow.add(args[1])
        args = args[2:]
    for path in args:
        found = h5_vars(path) if path.endswith(".h5") else nc_vars(path)
        n = sum(a.size for _, a in found)
        bad = [name for name, a in found
               if not np.all(np.isfinite(a)) and not (name in allow and not np.any(np.isnan(a)))]
        print("%s: %d values in %d variables%s" % (path, n, len(found),
              ", non-finite in " + ", ".join(bad) if bad else ", all finite"))
        if bad or not found:
            status = 1
    sys.exit(status)


main()
