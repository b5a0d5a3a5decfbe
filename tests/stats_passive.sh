#!/usr/bin/env bash
# The statistics are passive: a run that samples the momentum budget at every step (its
# conservative split of the pair forces included, solver/budget_pairs.c) ends in the same
# particle state, to the bit, as the same run without Eulerian statistics.
# usage: stats_passive.sh CHANSPH SCENE RUNS NAME [--set args...]
set -u
chansph=$1 scene=$2 runs=$3 name=$4
shift 4
a=$runs/passive_${name}_on b=$runs/passive_${name}_off
"$chansph" run "$scene" --out "$a" --overwrite "$@" --set output.stats_every=1 --set stats.budget_every=1 > "$a.log" 2>&1 ||
  { tail "$a.log"; echo "FAIL: run with statistics"; exit 1; }
"$chansph" run "$scene" --out "$b" --overwrite "$@" --set stats.eulerian=0 > "$b.log" 2>&1 ||
  { tail "$b.log"; echo "FAIL: run without statistics"; exit 1; }
/usr/bin/python3 - "$a/particles.nc" "$b/particles.nc" << 'PY'
import sys
import netCDF4
import numpy as np
with netCDF4.Dataset(sys.argv[1]) as p, netCDF4.Dataset(sys.argv[2]) as q:
    names = [n for n in ("x", "y", "z", "u", "v", "w", "rho", "p") if n in p.variables]
    bad = [n for n in names if not np.array_equal(p[n][:], q[n][:])]
    print(f"{len(names)} particle variables compared, step {p.getncattr('steps') if 'steps' in p.ncattrs() else '?'}")
    if bad:
        sys.exit(f"FAIL: the statistics changed the particles: {', '.join(bad)} differ")
print("PASS: identical particles with and without the budget")
PY
