#!/usr/bin/python3
"""CF checks of chansph's netCDF files (issue 13, point 12): every units attribute is a unit
libudunits2 parses (through ctypes: the Debian runtime library and its XML database), every
variable has a long_name or standard_name, the file declares Conventions, and the attributes
that count or flag are integers. Records of mixed quantities (eulerian/windows, moments,
snapshot_u) carry no units. Provenance: history (a "DATE: chansph ..." line per run and resume,
newest first), date_created (ISO 8601), source (version and git commit), ranks and threads.

usage: cf_check.py [resumed:]FILE.nc ...   (resumed: the history must hold a resume)
"""
import ctypes
import ctypes.util
import re
import sys

import netCDF4

INTEGER_ATTRS = ("dimension", "steps", "n_fluid", "n_snapshots", "n_windows", "fold", "les",
                 "step", "releases", "ranks", "threads")
STAMP = r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ"
MIXED = ("windows", "moments", "snapshot_u")


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


def main():
    parses = udunits()
    problems, units_seen = [], 0
    for arg in sys.argv[1:]:
        resumed = arg.startswith("resumed:")
        path = arg[len("resumed:"):] if resumed else arg
        with netCDF4.Dataset(path) as d:
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
    for p in problems:
        print(p)
    print("%d files, %d units attributes checked with libudunits2: %s" %
          (len(sys.argv) - 1, units_seen, "FAIL" if problems else "PASS"))
    sys.exit(1 if problems else 0)


main()
