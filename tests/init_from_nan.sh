#!/usr/bin/env bash
# Issue 13, point 8: init.from with a NaN in the source particles.nc is an input error (exit 1,
# naming the file, variable and particle), not a numerical failure at step 1 (exit 3).
# usage: init_from_nan.sh CHANSPH SCENE RUNS PYTHON
set -u
chansph=$1 scene=$2 runs=$3 py=$4
d=$runs/init_from_nan
rm -rf "$d" "$d.src"
"$chansph" run "$scene" --out "$d.src" --set time.t_end=0.05 --set output.t_average_start=0 \
  > /dev/null || { echo "FAIL: source run"; exit 1; }
"$py" -c "
import h5py  # particles.nc is netCDF-4, an HDF5 file
with h5py.File('$d.src/particles.nc', 'r+') as f:
    f['u'][7] = float('nan')
" || { echo "FAIL: cannot edit the source"; exit 1; }
exec "$(dirname "$0")/expect_fail.sh" 1 \
  "particles.nc \(init.from\): variable 'u' of particle id 7 is not finite \(nan\)" \
  "$chansph" run "$scene" --out "$d" --set "init.from=$d.src/particles.nc"
