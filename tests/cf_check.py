#!/usr/bin/python3
"""CF checks of chansph's netCDF files (issue 13, point 12): every units attribute is a unit
libudunits2 parses (through ctypes: the Debian runtime library and its XML database), every
variable has a long_name or standard_name, the file declares Conventions, and the attributes
that count or flag are integers. Records of mixed quantities (eulerian/windows, moments,
snapshot_u, the raw sums and Welford records of the quadrant and Lagrangian groups) carry no
units. Provenance: history (a "DATE: chansph ..." line per run and resume, newest first),
date_created (ISO 8601), source (version and git commit), ranks and threads.
Axes: every dimension a variable uses has a coordinate variable of that name in the variable's
own group (so xarray labels the axis; exempt: bnds), the
bin coordinates y and pdf_bin have CF bounds (contiguous, holding the centre), time has units
"s" with a reference attribute. Missing values: no NaN or Inf anywhere, a value equal to the
netCDF default fill only in a variable that declares it as _FillValue. xarray (python3-xarray)
opens the file and every group without a warning, with every dimension indexed.
Issue 26, point 14: no NaN or Inf in a global attribute (root or group: a value not known is
left out), the y long_name of a folded file says so, a particle file is CF point data
(featureType point, coordinates "x y z" on every other variable, a coordinate variable particle).

usage: cf_check.py [resumed:]FILE.nc ...   (resumed: the history must hold a resume)
"""
import ctypes
import ctypes.util
import os
import re
import sys

import warnings

import netCDF4
import numpy as np
import xarray

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ncfile import open_nc  # noqa: E402

INTEGER_ATTRS = ("dimension", "steps", "n_fluid", "n_snapshots", "n_windows", "fold", "les",
                 "step", "releases", "ranks", "threads")
STAMP = r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ"
MIXED = ("windows", "moments", "snapshot_u", "sums", "raw_sums", "raw_pdf", "release_welford",
         "pdf_release_welford", "T_L_welford", "batch_welford")
NO_COORD = ("bnds",)
POSITION = ("x", "y", "z")
BINNED = ("y", "pdf_bin")
FILL = netCDF4.default_fillvals["f8"]


def check_bounds(g, name, where, problems, contiguous):
    v = g.variables[name]
    b = v.getncattr("bounds")
    if b not in g.variables or g.variables[b].dimensions != (v.dimensions[0], "bnds"):
        problems.append("%s: bounds %r is not a (%s, bnds) variable of the group" %
                        (where, b, v.dimensions[0]))
        return
    c, lo, hi = np.asarray(v[:]), np.asarray(g.variables[b][:, 0]), np.asarray(g.variables[b][:, 1])
    if not (np.all(lo <= c) and np.all(c <= hi) and np.all(lo < hi)):
        problems.append("%s: bounds %s do not hold the values" % (where, b))
    if contiguous and not np.array_equal(lo[1:], hi[:-1]):
        problems.append("%s: bins %s are not contiguous" % (where, b))


def check_xarray(path, groups, problems):
    """Open the root and every group in xarray: no warning, every dimension indexed."""
    for grp in groups:
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            try:
                with xarray.open_dataset(path, group=grp) as ds:
                    ds.load()
                    bare = [d for d in ds.dims if d not in ds.indexes and d not in NO_COORD]
                    if bare:
                        problems.append("%s:%s: xarray has no index for %s" %
                                        (path, grp or "/", ", ".join(bare)))
            except Exception as e:  # pylint: disable=broad-except
                problems.append("%s:%s: xarray cannot open it: %s" % (path, grp or "/", e))
        for x in w:
            problems.append("%s:%s: xarray warns: %s" % (path, grp or "/", x.message))


def udunits():
    name = ctypes.util.find_library("udunits2") or "libudunits2.so.0"
    lib = ctypes.CDLL(name)
    lib.ut_set_error_message_handler(lib.ut_ignore)
    lib.ut_read_xml.restype = ctypes.c_void_p
    lib.ut_read_xml.argtypes = [ctypes.c_char_p]
    lib.ut_parse.restype = ctypes.c_void_p
    lib.ut_parse.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]
    lib.ut_free.argtypes = [ctypes.c_void_p]
    system = lib.ut_read_xml(None)
    if not system:
        sys.exit("FAIL: libudunits2 cannot read its unit database")

    def parses(u):
        unit = lib.ut_parse(system, u.encode(), 0)  # UT_ASCII
        if unit:
            lib.ut_free(unit)
        return bool(unit)
    return parses


def check_points(d, path, problems):
    """A file of particles (dimension particle): CF point data, so that readers place them."""
    if "particle" not in d.dimensions:
        return
    if d.ncattrs().count("featureType") == 0 or d.getncattr("featureType") != "point":
        problems.append("%s: particle data without featureType = point" % path)
    pos = " ".join(p for p in POSITION if p in d.variables)
    for name, v in d.variables.items():
        if name in POSITION + ("id", "particle") or v.dimensions != ("particle",):
            continue
        if "coordinates" not in v.ncattrs() or v.getncattr("coordinates") != pos:
            problems.append("%s:%s: no coordinates = %r" % (path, name, pos))


def check_global(g, where, problems, fold):
    """Finite global attributes; the folded y coordinate described as folded."""
    for k in g.ncattrs():
        v = np.asarray(g.getncattr(k))
        if v.dtype.kind == "f" and not np.all(np.isfinite(v)):
            problems.append("%s: global attribute %s is %s (a value not known is left out)" %
                            (where, k, v))
    if fold and "y" in g.variables and "2 delta" in g.variables["y"].getncattr("long_name"):
        problems.append("%s: y of a folded file is described as %r" %
                        (where, g.variables["y"].getncattr("long_name")))
    for name, sub in g.groups.items():
        check_global(sub, where + name + "/", problems, fold)


def main():
    p = cli.parser("cf_check.py", __doc__)
    p.add_argument("files", nargs="+", metavar="[resumed:]FILE.nc")
    files = p.parse_args().files
    parses = udunits()
    problems, units_seen = [], 0
    for arg in files:
        resumed = arg.startswith("resumed:")
        path = arg[len("resumed:"):] if resumed else arg
        with open_nc(path) as d:
            if "Conventions" not in d.ncattrs():
                problems.append("%s: no global attribute Conventions" % path)
            a = {k: d.getncattr(k) for k in d.ncattrs()}
            lines = str(a.get("history", "")).split("\n")
            if not all(re.match(STAMP + r": chansph (run|resume) .*\(\d+ MPI ranks? x \d+ "
                                r"threads?\)$", l) for l in lines):
                problems.append("%s: history is not one 'DATE: chansph run|resume ...' line per "
                                "process: %r" % (path, a.get("history")))
            if resumed and not any(" chansph resume " in l for l in lines):
                problems.append("%s: the history has no resume" % path)
            if not re.match(STAMP + "$", str(a.get("date_created", ""))):
                problems.append("%s: date_created %r is not ISO 8601" % (path, a.get("date_created")))
            if not re.match(r"chansph \S+ \(git ([0-9a-f]+(-dirty)?|unknown)\)$",
                            str(a.get("source", ""))):
                problems.append("%s: source %r names no version and commit" % (path, a.get("source")))
            for k in ("ranks", "threads"):
                if k not in a or not int(a[k]) >= 1:
                    problems.append("%s: no attribute %s >= 1" % (path, k))

            def walk(g, prefix):
                nonlocal units_seen
                for a in INTEGER_ATTRS:
                    if a in g.ncattrs() and not isinstance(g.getncattr(a), (int,)) and \
                            getattr(g.getncattr(a), "dtype", None) is not None and \
                            g.getncattr(a).dtype.kind not in "iu":
                        problems.append("%s:%s%s: attribute is %s, not an integer" %
                                        (path, prefix, a, g.getncattr(a).dtype))
                for name, v in g.variables.items():
                    attrs = v.ncattrs()
                    where = "%s:%s%s" % (path, prefix, name)
                    for dim in v.dimensions:
                        if dim not in NO_COORD and dim not in g.variables:
                            problems.append("%s: dimension %s has no coordinate variable in "
                                            "the group" % (where, dim))
                    if name in BINNED and v.dimensions == (name,):
                        if "bounds" not in attrs:
                            problems.append("%s: bin coordinate without bounds" % where)
                        else:
                            check_bounds(g, name, where, problems, True)
                    elif "bounds" in attrs:  # the windows: gaps where no sample fell
                        check_bounds(g, name, where, problems, False)
                    if name == "time" and v.dimensions == ("time",) and (
                            "units" not in attrs or v.getncattr("units") != "s" or
                            "reference" not in attrs):
                        problems.append("%s: time needs units 's' and a reference" % where)
                    if getattr(v.dtype, "kind", "") == "f":
                        v.set_auto_mask(False)
                        data = np.asarray(v[:])
                        if not np.all(np.isfinite(data)):
                            problems.append("%s: NaN or Inf written (missing values are "
                                            "_FillValue)" % where)
                        if np.any(data == FILL) and "_FillValue" not in attrs:
                            problems.append("%s: fill values without a _FillValue" % where)
                        if "_FillValue" in attrs and v.getncattr("_FillValue") != FILL:
                            problems.append("%s: _FillValue is not the netCDF default" % where)
                    if "long_name" not in attrs and "standard_name" not in attrs:
                        problems.append("%s: no long_name or standard_name" % where)
                    if "units" in attrs:
                        units_seen += 1
                        u = v.getncattr("units")
                        if not parses(u):
                            problems.append("%s: units '%s' is not a udunits unit" % (where, u))
                        if name in MIXED:
                            problems.append("%s: a record of mixed quantities has units '%s'" %
                                            (where, u))
                for name, sub in g.groups.items():
                    walk(sub, prefix + name + "/")
            walk(d, "")
            check_global(d, path + ":/", problems, int(a.get("fold", 0)) == 1)
            check_points(d, path, problems)
            groups = [None]
            stack = [(d, "")]
            while stack:
                g, prefix = stack.pop()
                for name, sub in g.groups.items():
                    groups.append(prefix + "/" + name)
                    stack.append((sub, prefix + "/" + name))
        check_xarray(path, groups, problems)
    for p in problems:
        print(p)
    print("%d files, %d units attributes checked with libudunits2: %s" %
          (len(files), units_seen, "FAIL" if problems else "PASS"))
    return 1 if problems else 0


sys.exit(cli.run(main))
