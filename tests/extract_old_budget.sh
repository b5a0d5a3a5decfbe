#!/usr/bin/env bash
# extract_old_budget.sh CHANSPH OUT A.nc B.nc
# Two segments whose Reynolds-stress budget records are of checkpoint format 1.6-1.10 (136
# fields: fluctuations about the bin's mean; the shipped segments of jobs/states): extract joins
# them into OUT with a note naming each file's records as left out, the written range has the
# Eulerian profiles and no rsb_* profiles, and its own records are of today's length.
# B does not record the state it started from (written before stats.nc did): without --force
# the join is refused naming B and the key (exit 1, no OUT); with it, joined on the user's word.
set -u
chansph=$1 out=$2 a=$3 b=$4
rm -f "$out"
msg=$("$chansph" extract "$a" "$b" --nc "$out" 2>&1)
rc=$?
[ $rc -eq 1 ] && echo "$msg" | grep -q "error: $b: does not record the state it started from.*--force" &&
  [ ! -e "$out" ] || { echo "$msg"; echo "FAIL: a segment without its start joined without --force (exit $rc)"; exit 1; }
"$chansph" extract "$a" "$b" --nc "$out" --force > "$out.log" 2>&1 || { cat "$out.log"; echo "FAIL: extract"; exit 1; }
for f in "$a" "$b"; do
  grep -q "note: $f: the Reynolds-stress budget records (reynolds_budget) have 136 fields, not [0-9]* (an earlier format): left out" "$out.log" ||
    { cat "$out.log"; echo "FAIL: no note naming $f"; exit 1; }
done
/usr/bin/python3 - "$out" <<'PY'
import sys
import netCDF4
import numpy as np
d = netCDF4.Dataset(sys.argv[1])
rsb = [v for v in d.variables if v.startswith("rsb_")]
u = np.asarray(d["u_mean"][:])
rec = d["eulerian"]["reynolds_budget"]
print(f"u_mean finite in {np.isfinite(u).sum()} of {u.size} bins; rsb_* variables {len(rsb)}; "
      f"records {rec.shape}, nonzero {int(np.count_nonzero(rec[:]))}")
if not np.all(np.isfinite(u)) or rsb or rec.shape[2] == 136 or np.count_nonzero(rec[:]):
    print("FAIL: the joined range is not the Eulerian profiles without the old budgets")
PY
