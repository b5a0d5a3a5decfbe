#!/usr/bin/env bash
# init.density = rho0: a state started with init.from has its densities shifted by one constant
# so that their mean is fluid.rho0 (the mean overpressure of a developed state removed); keep
# takes them as they are. The source's densities are raised by 2 kg/m^3 first, so that the
# two differ by far more than what one step changes.
# usage: init_density.sh CHANSPH SCENE SOURCE_PARTICLES_NC OUTDIR PYTHON
set -u
chansph=$1 scene=$2 src=$3 d=$4 py=$5
rm -rf "$d" && mkdir -p "$d" || exit 1
cp "$src" "$d/src.nc" && "$py" -c "
import h5py  # particles.nc is netCDF-4, an HDF5 file
with h5py.File('$d/src.nc', 'r+') as f:
    f['rho'][...] = f['rho'][...] + 2.0
" || { echo "FAIL: cannot edit the source"; exit 1; }
for mode in keep rho0; do
  "$chansph" run "$scene" --out "$d/$mode" --set time.t_end=0.01 --set output.t_average_start=0 --set "init.from=$d/src.nc" \
    --set init.density=$mode > "$d/$mode.log" 2>&1
  rc=$?
  [ $rc -eq 0 ] || { echo "FAIL: run $mode (exit $rc)"; exit 1; }
done
grep -q "densities shifted by" "$d/rho0.log" || { echo "FAIL: no shift in the output"; exit 1; }
grep -q "densities shifted by" "$d/keep.log" && { echo "FAIL: keep shifted"; exit 1; }
"$py" - "$d" <<'PY'
import sys
import netCDF4
import numpy as np
d = sys.argv[1]
def mean_rho(path):
    with netCDF4.Dataset(path) as f:
        kind = f["kind"][:] if "kind" in f.variables else None
        rho = np.asarray(f["rho"][:], float)
        return rho.mean() if kind is None else rho[np.asarray(kind) == 0].mean()
src = mean_rho(d + "/src.nc")
keep, rho0 = mean_rho(d + "/keep/particles.nc"), mean_rho(d + "/rho0/particles.nc")
print("mean rho: source %.6f, keep %.6f, rho0 %.6f" % (src, keep, rho0))
ok = abs(rho0 - 1000.0) < 0.02 and abs(keep - src) < 0.02 and abs(keep - rho0) > 1.0
print("PASS" if ok else "FAIL: the mean density is not where init.density puts it")
sys.exit(0 if ok else 1)
PY
