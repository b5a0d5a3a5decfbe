#!/usr/bin/env bash
# output.q_criterion: particles.nc holds q_criterion (units 1/s^2) for every fluid particle, and
# in the laminar 3-D channel, a pure shear U(y) (Q = 0 exactly, S:S/2 = U'^2/4 > 0), |Q| stays
# below 1e-3 of the largest S:S/2 of the Poiseuille profile away from the walls. The closed form
# Q = -C_ij C_ji / 2 for a linear field is unit_turb's. The last snapshot (which ParaView reads
# through snapshots/particles.xdmf) holds the same q_criterion as particles.nc.
# usage: q_criterion_check.sh CHANSPH SCENES RUNS
set -euo pipefail
chansph=$1 scenes=$2 runs=$3
"$chansph" run "$scenes/poiseuille3d.ini" --out "$runs/q_criterion" --overwrite \
  --set output.q_criterion=1 --set time.t_end=3 --set output.t_average_start=1 \
  --set snapshots.every=1.5 > /dev/null
snap=$(ls "$runs"/q_criterion/snapshots/snap_*.h5 | tail -1)
grep -q 'Attribute Name="q_criterion"' "$runs/q_criterion/snapshots/particles.xdmf" ||
  { echo "FAIL: particles.xdmf lists no q_criterion"; exit 1; }
/usr/bin/python3 - "$runs/q_criterion/particles.nc" "$snap" << 'PY'
import sys
import h5py
import netCDF4
import numpy as np
d = netCDF4.Dataset(sys.argv[1])
with h5py.File(sys.argv[2], "r") as h:
    if not np.array_equal(h["q_criterion"][:], d["q_criterion"][:]):
        sys.exit("FAIL: the last snapshot's q_criterion differs from particles.nc's")
if "q_criterion" not in d.variables:
    sys.exit("FAIL: particles.nc has no q_criterion")
q, y = d["q_criterion"][:].filled(np.nan), d["y"][:].filled(np.nan)
assert d["q_criterion"].units == "1/s^2", d["q_criterion"].units
delta, f, nu = 0.5, 0.8, 0.1  # poiseuille3d.ini
s2 = 0.25 * (f / nu * np.abs(y - delta)) ** 2  # S:S/2 of the steady profile
inner = (y > 0.3 * delta) & (y < 1.7 * delta)
ratio = np.abs(q[inner]).max() / s2[inner].max()
print("q_criterion: %d particles, all finite: %s; interior max |Q| / max S:S/2 = %.2e (limit 1e-3)"
      % (q.size, np.isfinite(q).all(), ratio))
sys.exit(0 if np.isfinite(q).all() and ratio < 1e-3 else 1)
PY
