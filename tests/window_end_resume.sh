#!/usr/bin/env bash
# A run that ends at an averaging-window boundary (t_end = 0.4, windows of 0.1 from 0.1) has
# every window complete in stats.nc, in every engine with windows (eulerian, correlations,
# pdfs, quadrants): the run's end closes the last one (stats_close) instead of leaving it open
# for a snapshot that never comes. Resumed to t_end = 0.6 it gives the same stats.nc data and
# final checkpoint as one run to 0.6 (the closing is what the next snapshot would have done).
# usage: window_end_resume.sh CHANSPH SCENE RUNS
set -u
export CHANSPH_RUN_ID=compare-test
chansph=$1 scene=$2 runs=$3
full=$runs/window_end_full part=$runs/window_end_part
rm -rf "$full" "$part"
opts=(--set output.t_average_start=0.1 --set stats.window=0.1 --set stats.u_tau_ref=0.6
  --set correlations.y_plus=1,2 --set quadrants.y_plus=1,2 --set pdfs.y_plus=1,2
  --set lagrangian.y_plus=1,2 --set lagrangian.horizon=0.2 --set lagrangian.release_every=0.1
  --set lagrangian.n_lags=10)
"$chansph" run "$scene" --out "$full" --set time.t_end=0.6 "${opts[@]}" > /dev/null ||
  { echo "FAIL: full run"; exit 1; }
"$chansph" run "$scene" --out "$part" --set time.t_end=0.4 "${opts[@]}" > "$part.log" 2>&1 ||
  { tail -3 "$part.log"; echo "FAIL: run to t_end = 0.4"; exit 1; }
grep -q "stats: 3 complete windows" "$part.log" ||
  { grep "complete windows" "$part.log" | tail -1; echo "FAIL: log: not 3 complete windows at t = 0.4"; exit 1; }
/usr/bin/python3 - "$part/stats.nc" << 'PY' || exit 1
import sys
import netCDF4
d = netCDF4.Dataset(sys.argv[1])
bad = []
eu = d["eulerian"]["window_complete"][:]
if len(eu) != 3 or not eu.all():
    bad.append(f"eulerian window_complete {list(eu)}: expected [1, 1, 1]")
if int(d.n_windows) != 3:
    bad.append(f"n_windows {int(d.n_windows)}: expected 3")
for g in ("correlations", "pdfs"):
    n = int(d[g].closed_windows)
    if n != 3:
        bad.append(f"{g}: closed_windows {n}: expected 3")
# the correlations write their open window too, here the empty one after the last boundary
co, snaps = d["correlations"]["window_complete"][:], d["correlations"]["windows"][:, 2]
if [int(c) for c, n in zip(co, snaps) if n > 0] != [1, 1, 1] or (snaps[co == 0] > 0).any():
    bad.append(f"correlations window_complete {list(co)}, snapshots {list(snaps)}")
qb = d["quadrants"]["n_batches"][:]
if not (qb == 3).all():
    bad.append(f"quadrants n_batches {list(qb)}: expected 3 at every level")
print(f"t = 0.4: quadrants {list(qb)} batches, eulerian {list(eu)}, correlations {list(co)}, pdfs {int(d['pdfs'].closed_windows)} closed")
sys.exit("FAIL: " + "; ".join(bad) if bad else 0)
PY
"$chansph" resume "$part" --set time.t_end=0.6 > /dev/null || { echo "FAIL: resume to 0.6"; exit 1; }
status=0
if diff <("$(dirname "$0")/nc_content.sh" "$full/stats.nc") \
  <("$(dirname "$0")/nc_content.sh" "$part/stats.nc") > "$part.diff"; then
  echo "stats.nc: data identical"
else
  echo "stats.nc: DIFFERENT"; head -20 "$part.diff"; status=1
fi
last=$(cd "$full/checkpoints" && ls ckpt_*.h5 | tail -n 1)
# the scene text differs (t_end 0.4 then 0.6 against 0.6): compare the state
if h5diff --exclude-path /scene "$full/checkpoints/$last" "$part/checkpoints/$last" > "$part.h5diff"; then
  echo "$last: h5diff finds no difference in the state"
else
  echo "$last: h5diff DIFFERENT"; head -20 "$part.h5diff"; status=1
fi
[ $status -eq 0 ] && echo PASS
exit $status
