#!/usr/bin/env bash
# stats.budget_every: the budgets and the wall shear stress come with one Eulerian sample in each
# block of budget_every (at a position drawn per block, sim_budget_sample). Two runs of one
# scene, identical trajectories (the statistics are passive), sampling every step, with
# averaging windows shorter than a step (one sample a window): A takes the budgets with every
# sample, C (stats.budget_every = 4) with one in four. Then, window by window, C's budget
# records (Reynolds-stress and momentum planes) and wall-stress sums are A's, to the bit, where
# C took a budget sample and zero elsewhere; exactly one in each block of 4 samples; C's
# u_tau_wall is the mean of A's wall stress over those samples; C's means are A's.
# usage: budget_every_check.sh CHANSPH SCENE RUNS NAME WINDOW [--set args...]
# (WINDOW: an averaging window shorter than the scene's time step [s])
set -u
chansph=$1 scene=$2 runs=$3 name=$4 window=$5
shift 5
base=$runs/budget_every_$name
extra=("$@")
run1() {
  "$chansph" run "$scene" --out "$1" --overwrite "${extra[@]}" --set output.stats_every=1 \
    --set stats.budget_every="$2" --set stats.window="$window" --set output.particles=0 \
    > "$1.log" 2>&1 || { tail "$1.log"; echo "FAIL: run $1"; exit 1; }
}
run1 "${base}_A" 1
run1 "${base}_C" 4
/usr/bin/python3 - "${base}_A/stats.nc" "${base}_C/stats.nc" << 'PY'
import sys
import netCDF4
import numpy as np
A, C = (netCDF4.Dataset(p) for p in sys.argv[1:3])
ea, ec = A["eulerian"], C["eulerian"]
fail = []
wa, wc = ea["windows"][:], ec["windows"][:]
if wa.shape != wc.shape or np.any(wa[:, 2] > 1):
    sys.exit("FAIL: the runs' windows differ, or a window holds more than one sample")
taken = ec["planes"][:, 0, 0]  # the budget samples of each window (field "snapshots")
n = int(wa[:, 2].sum())
sampled = np.flatnonzero(wa[:, 2] > 0)
print(f"{n} samples in {len(wa)} windows; C took the budgets in {int(taken.sum())}")
if not np.all(taken[wa[:, 2] == 0] == 0):
    fail.append("a budget sample in a window without a sample")
# the step of each sample, from its time in A's planes (a constant step on this scene)
names = list(ea["plane_field"][:])
t = ea["planes"][sampled, 0, names.index("time_first")]
dt = float(np.diff(t).mean())
steps = np.rint(t / dt).astype(int)
flags = taken[sampled]
blocks = {}
for s_, f in zip(steps, flags):
    blocks.setdefault(s_ // 4, []).append((s_ % 4, f))
slots = set()
for b, members in blocks.items():
    if len(members) == 4:  # complete blocks: exactly one budget sample
        got = [k for k, f in members if f]
        if len(got) != 1:
            fail.append(f"block of steps {4 * b}-{4 * b + 3}: {len(got)} budget samples")
        slots.update(got)
print(f"steps {steps[0]}..{steps[-1]}, {len(blocks)} blocks; positions within them: {sorted(slots)}")
if len(slots) < 2:
    fail.append("the budget samples sit at one position in every block (not drawn)")
on, off = taken > 0, taken == 0
for rec in ("planes", "planes_kinetic"):
    ra, rc = ea[rec][:], ec[rec][:]
    if not np.array_equal(ra[on], rc[on]):
        fail.append(f"{rec}: C's budget samples differ from A's")
    if np.any(rc[off] != 0):
        fail.append(f"{rec}: nonzero in windows without a budget sample")
# the Reynolds-stress records: each sample's sums are weighted by the time since the previous
# budget sample (tau, field 1 of each block), so they agree per unit tau
ra, rc = ea["reynolds_budget"][:][on], ec["reynolds_budget"][:][on]
rb = sum(1 for f in ea["reynolds_budget_field"][:] if f.startswith("sum_"))  # RB_LEN
for blk in (0, rb):
    da, dc = ra[..., blk:blk + rb].copy(), rc[..., blk:blk + rb].copy()
    da[..., 2:] /= da[..., 1:2]
    dc[..., 2:] /= dc[..., 1:2]
    d = np.abs(da[..., 2:] - dc[..., 2:]).max() / max(np.abs(da[..., 2:]).max(), 1e-300)
    if not np.array_equal(da[..., 0], dc[..., 0]) or d > 1e-12:
        fail.append(f"reynolds_budget block {blk}: C's sums per unit tau differ from A's ({d:.3g})")
if not np.array_equal(ra[..., 2 * rb:], rc[..., 2 * rb:]):
    fail.append("reynolds_budget: the states and times of C's samples differ from A's")
if np.any(ec["reynolds_budget"][:][off] != 0):
    fail.append("reynolds_budget: nonzero in windows without a budget sample")
if not np.array_equal(wa[on][:, 4:6], wc[on][:, 4:6]) or np.any(wc[off][:, 4:6] != 0):
    fail.append("the wall-stress sums are not A's on the budget samples alone")
expect = np.sqrt(0.5 * wa[on][:, 4:6].sum() / on.sum())
uc, ua = float(C.getncattr("u_tau_wall")), float(A.getncattr("u_tau_wall"))
print(f"u_tau_wall: A {ua:.12g}, C {uc:.12g}, A's wall stress over C's samples {expect:.12g}")
if abs(uc - expect) > 1e-12 * expect:
    fail.append("u_tau_wall of C is not the mean over its budget samples")
if abs(ua - uc) <= 1e-9 * ua:
    fail.append("u_tau_wall of C equals A's: the test cannot tell the sample sets apart")
for v in ("u_mean", "uu", "vv", "ww", "uv"):
    if not np.array_equal(np.asarray(A[v][:]), np.asarray(C[v][:])):
        fail.append(f"{v} differs between A and C (the same samples)")
for f in fail:
    print("FAIL:", f)
if not fail:
    print("PASS: the budgets and u_tau_wall of one sample in four, the means of every sample")
sys.exit(1 if fail else 0)
PY
