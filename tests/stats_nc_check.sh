#!/usr/bin/env bash
# stats.nc opens cleanly in ncdump, NCO (ncks -m) and python3-netCDF4 (issue 5, acceptance 7):
# no error, no warning on stderr, every variable of every group readable and with units
# (except the raw records of mixed quantities and the string labels of their fields, issue 13
# point 12).
set -eu
f=$1
status=0
check() { # name, command...
  local name=$1; shift
  local err
  if ! err=$("$@" 2>&1 >/dev/null); then echo "$name: FAILED: $err"; status=1; return; fi
  if [ -n "$err" ]; then echo "$name: warnings: $err"; status=1; return; fi
  echo "$name: clean"
}
check "ncdump -h" ncdump -h "$f"
check "ncdump (data)" ncdump "$f"
if command -v ncks > /dev/null; then
  check "ncks -m" ncks -m "$f"
  check "ncks (data, groups)" ncks -g eulerian "$f"
else
  echo "ncks: NCO not installed (jobs/setup.sh installs it)"; status=1
fi
check "python3-netCDF4" /usr/bin/python3 -W error -c '
import sys, netCDF4
def walk(g):
    for v in g.variables.values():
        v[:]
        # mixed quantities and string labels of record fields: no units
        if v.name not in ("windows", "moments", "snapshot_u", "planes", "planes_kinetic",
                          "reynolds_budget", "planes_total", "planes_total_kinetic") \
                and v.dtype != str:
            getattr(v, "units")
    for c in g.groups.values():
        walk(c)
with netCDF4.Dataset(sys.argv[1]) as d:
    walk(d)
' "$f"
exit $status
