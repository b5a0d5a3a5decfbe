#!/usr/bin/env bash
# Issue 26, point 14: the netCDF files of a short folded 2-D run with quadrants and no complete
# window pass tests/cf_check.py: no NaN in global attributes (u_bulk_target without a flux
# drive, u_tau_stderr and correlation_time without windows are left out), no units on the mixed
# record quadrants/sums, the folded y described as folded, particles.nc CF point data.
# usage: nc_cf_points.sh CHANSPH SCENES RUNS PYTHON
set -u
chansph=$1 scenes=$2 runs=$3 py=$4
d=$runs/nc_cf_points
rm -rf "$d"
"$chansph" run "$scenes/poiseuille2d.ini" --out "$d" --set time.t_end=0.05 \
  --set output.t_average_start=0 --set quadrants.y_plus=5 --set stats.fold=1 \
  --set stats.u_tau_ref=0.1 > "$d.log" 2>&1 || { tail "$d.log"; echo "FAIL: run"; exit 1; }
exec "$py" "$(dirname "$0")/cf_check.py" "$d/stats.nc" "$d/particles.nc"
