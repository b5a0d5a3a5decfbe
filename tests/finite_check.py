#!/usr/bin/env python3
"""Every floating-point value in the given chansph files is finite (issue 13, point 1).

usage: finite_check.py [--allow NAME ...] FILE... (HDF5 checkpoints and snapshots *.h5, netCDF stats.nc and
particles.nc *.nc); prints each file with its number of values, exits 1 naming the first
variable that holds a NaN or an infinity. In netCDF files, values equal to _FillValue (no
samples) are masked and not counted. --allow NAME: a variable that may be infinite (a
checkpoint's output/next_write is +inf when stats.nc is written only at the end).
A checkpoint's sim/init_from_time is NaN by design in a run that did not start from a state
(init.from: the time of the state it started from, docs/checkpoint-format.md): that NaN is a
record of absence, not a value, and is not counted as non-finite.
"""
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ckpt import open_h5  # noqa: E402
from chansph_stats.ncfile import open_nc  # noqa: E402


def h5_vars(path):
    out = []
    with open_h5(path) as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                out.append((name, np.asarray(obj[()])))
        f.visititems(visit)
    return out


def nc_vars(path):
    out = []
    with open_nc(path) as d:
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
    p = cli.parser("finite_check.py", __doc__)
    p.add_argument("--allow", action="append", default=[], metavar="NAME",
                   help="a variable that may be infinite (not NaN)")
    p.add_argument("files", nargs="+", metavar="FILE")
    a = p.parse_args()
    allow, status = set(a.allow), 0
    absent = {"sim/init_from_time"}  # NaN: no init.from state (see above)
    for path in a.files:
        found = h5_vars(path) if path.endswith(".h5") else nc_vars(path)
        n = sum(a.size for _, a in found)
        bad = [name for name, a in found
               if not np.all(np.isfinite(a)) and not (name in allow and not np.any(np.isnan(a)))
               and not (name in absent and np.all(np.isnan(a)))]
        print("%s: %d values in %d variables%s" % (path, n, len(found),
              ", non-finite in " + ", ".join(bad) if bad else ", all finite"))
        if bad or not found:
            status = 1
    return status


sys.exit(cli.run(main))
