#!/usr/bin/env bash
# chansph extract A.nc B.nc --nc J.nc: the segments of one run (B started from A's final state
# with init.from, as a long run continued on another machine) joined into one stats.nc. Its raw
# windows are A's then B's, B's times (window bounds, the budgets' first and last snapshot
# times) shifted by A's reached time; A's last window, which ends where A ended, is complete
# (the engine closes it at the run's end, stats_close; in a file of an older build, where it
# was left open, extract counts it: checked on a copy of A with that flag cleared); the
# profiles of each part of J equal those of its segment alone, to the printed digit; its steps are A's plus B's; `chansph compare` reads J; a segment gathered otherwise (another window length)
# is an input error naming the file and the key (exit 1, no J left).
# usage: extract_join_check.sh CHANSPH SCENE STATS_RUN DNS WORK
#   STATS_RUN: the shared small run (SCENE to t = 1, averaging from 0.2 in windows of 0.1)
set -u
chansph=$1 scene=$2 run=$3 dns=$4 work=$5
rm -rf "$work"
mkdir -p "$work"
seg() { # seg DIR WINDOW: a segment of 0.4 s from the shared run's final state
  "$chansph" run "$scene" --out "$1" --overwrite --set time.t_end=0.4 --set output.t_average_start=0 \
    --set stats.window="$2" --set init.from="$run/particles.nc" > "$1.log" 2>&1 ||
    { tail -3 "$1.log"; echo "FAIL: the segment run $1"; exit 1; }
}
seg "$work/b" 0.1
a=$run/stats.nc b=$work/b/stats.nc j=$work/joined.nc
"$chansph" extract "$a" "$b" --nc "$j" || { echo "FAIL: extract A B --nc"; exit 1; }
# A as an older build wrote it: its last window left open (window_complete 0)
a0=$work/a_open_last.nc j0=$work/joined_open_last.nc
cp "$a" "$a0" && chmod u+w "$a0" && /usr/bin/python3 -c "
import sys, h5py  # netCDF4 cannot open the engine's file for writing (NC_ECANTWRITE)
with h5py.File(sys.argv[1], 'r+') as d:
    d['eulerian/window_complete'][-1] = 0
" "$a0" || { echo "FAIL: copy of A with its last window open"; exit 1; }
"$chansph" extract "$a0" "$b" --nc "$j0" --force 2> "$work/open_last.log" ||
  { cat "$work/open_last.log"; echo "FAIL: extract A0 B --nc"; exit 1; }
/usr/bin/python3 -c "
import sys, netCDF4, numpy as np
a, j = netCDF4.Dataset(sys.argv[1]), netCDF4.Dataset(sys.argv[2])
ca, cj = a['eulerian']['window_complete'][:], j['eulerian']['window_complete'][:]
na = ca.shape[0]
sys.exit(0 if ca[-1] == 0 and cj[na - 1] == 1 and cj.all() else
         f'FAIL: an open last window of A at its end not counted: {list(ca)} -> {list(cj)}')
" "$a0" "$j0" || exit 1
/usr/bin/python3 - "$a" "$b" "$j" << 'PY' || exit 1
import sys
import netCDF4
import numpy as np
A, B, J = (netCDF4.Dataset(p) for p in sys.argv[1:4])
ta = float(A.t_reached)
ga, gb, gj = A["eulerian"], B["eulerian"], J["eulerian"]
na, nb = ga["windows"].shape[0], gb["windows"].shape[0]
print(f"A: {na} rows to t = {ta}, B: {nb} rows to t = {float(B.t_reached)}, "
      f"J: {gj['windows'].shape[0]} rows to t = {float(J.t_reached)}, segments '{J.segments}'")
wa, wb, wj = ga["windows"][:], gb["windows"][:], gj["windows"][:]
shifted = wb.copy()
shifted[:, :2] += ta
bad = []
if not np.array_equal(wj, np.concatenate([wa, shifted])):
    bad.append("windows are not A's then B's shifted by A's t_reached")
for v in ("moments", "snapshot_u", "planes_kinetic"):
    if not np.array_equal(gj[v][:], np.concatenate([ga[v][:], gb[v][:]])):
        bad.append(f"{v} is not A's then B's")
# the budgets keep the times of their first and last snapshot (their rates of change divide by
# the span): B's are shifted too, where a row has snapshots (planes: count 0, times 9, 10;
# reynolds_budget: count 0, times 134, 135, the last two fields)
for v, n, times in (("planes", 0, (9, 10)), ("reynolds_budget", 0, (-2, -1))):
    pb = np.array(gb[v][:])
    for k in times:
        pb[..., k] = np.where(pb[..., n] > 0, pb[..., k] + ta, pb[..., k])
    if not (pb[..., n] > 0).any() or not np.array_equal(gj[v][:], np.concatenate([ga[v][:], pb])):
        bad.append(f"{v} is not A's then B's with B's snapshot times shifted by {ta}")
cj, ca, cb = gj["window_complete"][:], ga["window_complete"][:], gb["window_complete"][:]
# both segments ended at a window boundary: every window complete, in A, B and J
if not (ca.all() and cb.all() and cj.all()):
    bad.append(f"completeness: A {list(ca)}, B {list(cb)}, J {list(cj)}: expected all 1")
if abs(float(J.t_reached) - ta - float(B.t_reached)) > 1e-12 or int(J.n_windows) != na + nb:
    bad.append(f"t_reached {float(J.t_reached)} or n_windows {int(J.n_windows)} wrong")
if int(J.steps) != int(A.steps) + int(B.steps):
    bad.append(f"steps {int(J.steps)}: not A's {int(A.steps)} + B's {int(B.steps)}")
if "correlations" in J.groups:
    bad.append("group correlations kept although only group eulerian is joined")
sys.exit("FAIL: " + "; ".join(bad) if bad else 0)
PY
vars=u_mean,uu,vv,uv,u_rms,total_stress,n_samples
ta=$(/usr/bin/python3 -c "import netCDF4,sys; print(repr(float(netCDF4.Dataset(sys.argv[1]).t_reached)))" "$a")
x=$("$chansph" extract "$b" --var $vars | grep -v '^#')
y=$("$chansph" extract "$j" --window "$ta": --var $vars | grep -v '^#')
[ -n "$x" ] && [ "$x" = "$y" ] || { echo "FAIL: J after $ta is not B"; diff <(echo "$x") <(echo "$y") | head; exit 1; }
x=$("$chansph" extract "$a" --window :0.9 --var $vars | grep -v '^#')
y=$("$chansph" extract "$j" --window :0.9 --var $vars | grep -v '^#')
[ -n "$x" ] && [ "$x" = "$y" ] || { echo "FAIL: J before 0.9 is not A"; diff <(echo "$x") <(echo "$y") | head; exit 1; }
"$chansph" compare "$j" --dns "$dns" --out "$work/compare" --no-plots > "$work/compare.log" 2>&1 ||
  { tail -3 "$work/compare.log"; echo "FAIL: chansph compare on the joined file"; exit 1; }
seg "$work/c" 0.05
msg=$("$chansph" extract "$a" "$work/c/stats.nc" --nc "$work/bad.nc" 2>&1)
rc=$?
echo "$msg"
[ $rc -eq 1 ] && echo "$msg" | grep -q "$work/c/stats.nc: window_length 0.05.*not a later segment" ||
  { echo "FAIL: a segment of another window length is not an input error naming it (exit $rc)"; exit 1; }
[ -e "$work/bad.nc" ] && { echo "FAIL: an output was written"; exit 1; }
msg=$("$chansph" extract "$a" "$b" --pdfs 2>&1)
rc=$?
[ $rc -eq 1 ] && echo "$msg" | grep -q "pdfs reads one stats.nc" || { echo "FAIL: --pdfs with 2 files (exit $rc)"; exit 1; }
echo "PASS: two segments of one run joined"
