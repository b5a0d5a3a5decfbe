#!/usr/bin/env bash
# The content of a chansph netCDF file, for comparing two runs of the same state: ncdump -p 9,17
# without its first line (the file name) and without the provenance attributes that describe
# the process rather than the state (history, date_created, threads, ranks; issue 13, point 12).
# usage: nc_content.sh FILE.nc
set -o pipefail
ncdump -p 9,17 "$1" | tail -n +2 |
  awk '/^\t\t:(history|date_created|threads|ranks) = /{skip=1} skip{if (/ ;$/) skip=0; next} 1'
