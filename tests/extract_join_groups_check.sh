#!/usr/bin/env bash
# chansph extract A.nc B.nc --nc J.nc joins the Lagrangian and quadrant groups too (issue 43):
# J's groups are the pooled completed releases and complete averaging windows of A and B,
# written by the engines' own writers. Two short 3-D segments with both engines (B started from
# A's final particles.nc); checked in Python from the raw records of A, B and J:
#   (a) J's raw sums (raw_sums, raw_pdf; quadrants sums, samples) are A's + B's exactly;
#   (b) J's Welford records (release_welford, pdf_release_welford, T_L_welford, batch_welford)
#       are the pairwise merge (Chan et al.) of A's and B's, to 1e-12 relative;
#   (c) J's T_L_release is A's then B's, B's release times shifted by A's t_reached;
#   (d) release_batches, pdf_release_batches, n_batches and releases of J are A's + B's;
#   (e) each *_stderr of J is sqrt(M2 / (n - 1) / n) of its merged record (n >= 2; else fill),
#       and the values (rho_L_u, D_u, pdf_y; uv, uv_fraction) are the engines' formulas of J's
#       raw sums (and differ from A's: a join that did not add the sums would fail).
# Then: a B without the raw records (renamed: a file of an earlier version) or with another
# horizon leaves group lagrangian out with a note naming it, the eulerian part still joined
# (exit 0); --window restricting the range leaves both groups out; one file --nc has neither.
# Last: chansph-stats lagr_table on J (the blocked T_L errors of one release = T_L_stderr).
# usage: extract_join_groups_check.sh CHANSPH SCENE WORK   (SCENE: poiseuille3d.ini)
set -u
chansph=$1 scene=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
engines=(--set stats.window=0.1 --set stats.u_tau_ref=0.6 --set output.stats_every=1
  --set fluid.nu=0.01 --set lagrangian.y_plus=2,5 --set lagrangian.horizon=0.1
  --set lagrangian.release_every=0.05 --set lagrangian.n_lags=5 --set lagrangian.pdf_x=0.01
  --set quadrants.y_plus=2,5)
run() { # run DIR T_END T_AVERAGE_START [more --set ...]
  local dir=$1 t_end=$2 t0=$3
  shift 3
  "$chansph" run "$scene" --out "$dir" --overwrite --set time.t_end="$t_end" \
    --set output.t_average_start="$t0" "${engines[@]}" "$@" > "$dir.log" 2>&1 ||
    { tail -3 "$dir.log"; echo "FAIL: the run $dir"; exit 1; }
}
run "$work/a" 0.5 0.1
run "$work/b" 0.4 0 --set init.from="$work/a/particles.nc"
a=$work/a/stats.nc b=$work/b/stats.nc j=$work/joined.nc
msg=$("$chansph" extract "$a" "$b" --nc "$j" 2>&1) || { echo "$msg"; echo "FAIL: extract A B --nc"; exit 1; }
echo "$msg"
echo "$msg" | grep -q "note: 2 segments joined: groups eulerian, lagrangian, quadrants" ||
  { echo "FAIL: the note does not name the groups joined"; exit 1; }
echo "$msg" | grep -q "in flight at the end of a segment" ||
  { echo "FAIL: no note on the releases in flight at a segment's end"; exit 1; }
/usr/bin/python3 - "$a" "$b" "$j" << 'PY' || exit 1
import sys
import netCDF4
import numpy as np

A, B, J = (netCDF4.Dataset(p) for p in sys.argv[1:4])
for d in (A, B, J):
    d.set_auto_mask(False)
FILL = netCDF4.default_fillvals["f8"]
ta = float(A.t_reached)
bad = []


def check(what, ok, detail):
    print(f"{'ok  ' if ok else 'FAIL'} {what}: {detail}")
    if not ok:
        bad.append(what)


def merge(wa, wb):
    """Pairwise merge of Welford records [..., (n, mean, M2)] (moments.h scal_merge)."""
    na, ma, qa = wa[..., 0], wa[..., 1], wa[..., 2]
    nb, mb, qb = wb[..., 0], wb[..., 1], wb[..., 2]
    n = na + nb
    with np.errstate(invalid="ignore", divide="ignore"):
        d = mb - ma
        m = np.where(na == 0, mb, np.where(nb == 0, ma, ma + d * nb / n))
        q = np.where(na == 0, qb, np.where(nb == 0, qa, qa + qb + d * d * na * nb / n))
    return np.stack([n, m, q], axis=-1)


def rel(x, y):
    """Largest difference of x and y relative to the largest |y| (0 if both are zero)."""
    scale = max(np.max(np.abs(y)), 1e-300)
    return float(np.max(np.abs(x - y))) / scale


def stderr_of(w):
    """The engine's standard error of a Welford record: fill below 2 batches."""
    n, q = w[..., 0], w[..., 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n >= 2, np.sqrt(q / (n - 1) / n), FILL)


def same_stderr(what, got, w):
    want = stderr_of(w)
    fill_ok = np.array_equal(got == FILL, want == FILL)
    live = want != FILL
    check(what, fill_ok and live.any() and rel(got[live], want[live]) <= 1e-12,
          f"{int(live.sum())} finite, max rel diff "
          f"{rel(got[live], want[live]) if live.any() else float('nan'):.3g}, fills agree {fill_ok}")


ga, gb, gj = A["lagrangian"], B["lagrangian"], J["lagrangian"]
qa, qb, qj = A["quadrants"], B["quadrants"], J["quadrants"]
# (a) sums added exactly
for g, name in ((gj, "raw_sums"), (gj, "raw_pdf"), (qj, "sums"), (qj, "samples")):
    x, y = (ga, gb) if g is gj else (qa, qb)
    s = x[name][:] + y[name][:]
    check(f"(a) {g.name}/{name} = A + B", np.array_equal(g[name][:], s) and np.any(y[name][:] != 0),
          f"max |J - (A + B)| {np.max(np.abs(g[name][:] - s)):.3g}")
# (b) Welford records merged pairwise
for g, name in ((gj, "release_welford"), (gj, "pdf_release_welford"), (gj, "T_L_welford"),
                (qj, "batch_welford")):
    x, y = (ga, gb) if g is gj else (qa, qb)
    want, got = merge(x[name][:], y[name][:]), g[name][:]
    both = (x[name][..., 0] > 0) & (y[name][..., 0] > 0)
    check(f"(b) {g.name}/{name} = merge(A, B)",
          got.shape == want.shape and rel(got, want) <= 1e-12 and both.any(),
          f"max rel diff {rel(got, want):.3g}, {int(both.sum())} records with batches in both")
# (c) the history of T_L: A's then B's, B's times shifted by A's t_reached
h = np.concatenate([ga["T_L_release"][:], gb["T_L_release"][:]])
t = np.concatenate([ga["release"][:], gb["release"][:] + ta])
check("(c) T_L_release = A's then B's", np.array_equal(gj["T_L_release"][:], h),
      f"{gj['T_L_release'].shape[0]} rows = {ga['T_L_release'].shape[0]} + "
      f"{gb['T_L_release'].shape[0]}")
check("(c) release = A's then B's + t_reached(A)",
      np.array_equal(gj["release"][:], t) and np.all(np.diff(t) > 0),
      f"max diff {np.max(np.abs(gj['release'][:] - t)):.3g}, A ends {ta}")
# (d) batch counts added
for g, name in ((gj, "release_batches"), (gj, "pdf_release_batches"), (qj, "n_batches")):
    x, y = (ga, gb) if g is gj else (qa, qb)
    check(f"(d) {g.name}/{name} = A + B", np.array_equal(g[name][:], x[name][:] + y[name][:]),
          f"J {g[name][:].ravel()[:4]}, A {x[name][:].ravel()[:4]}, B {y[name][:].ravel()[:4]}")
check("(d) releases = A + B", int(gj.releases) == int(ga.releases) + int(gb.releases),
      f"{int(gj.releases)} = {int(ga.releases)} + {int(gb.releases)}")
# (e) standard errors of the merged records, values of the joined sums
rw, lf = gj["release_welford"][:], list(gj["lag_function"][:])
for k, name in enumerate(lf):
    if name + "_stderr" in gj.variables and name in ("rho_L_u", "D_u", "w_lag_mean", "sigma2_y"):
        same_stderr(f"(e) lagrangian/{name}_stderr", gj[name + "_stderr"][:], rw[:, k])
pw = gj["pdf_release_welford"][:]
nb = gj.dimensions["pdf_bin"].size
same_stderr("(e) lagrangian/pdf_y_stderr", gj["pdf_y_stderr"][:], pw[:, :, :nb])
same_stderr("(e) lagrangian/pdf_mu_y_stderr", gj["pdf_mu_y_stderr"][:], pw[:, :, nb])
same_stderr("(e) lagrangian/T_L_stderr", gj["T_L_stderr"][:], gj["T_L_welford"][:])
bw = qj["batch_welford"][:]
for k, name in enumerate(("uv", "uv_fraction", "time_fraction")):
    same_stderr(f"(e) quadrants/{name}_stderr", qj[name + "_stderr"][:], bw[:, 4 * k:4 * k + 4])


def rho_u(S):
    """rho_L of u from sums records [..., slot] (lagr.c corr5: slots 1..5 of u)."""
    n = S[..., 0]
    m0, mt = S[..., 1] / n, S[..., 2] / n
    c, v0, vt = S[..., 5] / n - m0 * mt, S[..., 3] / n - m0 * m0, S[..., 4] / n - mt * mt
    return c / np.sqrt(v0 * vt)


def value_check(what, got, want, other):
    """got (J's variable) is want (from J's raw records) where that is finite, and A's own
    values (other) differ from want: J's are not A's."""
    live = np.isfinite(want)
    diff = rel(got[live], want[live]) if live.any() else float("nan")
    both = live & (other != FILL)
    moved = rel(other[both], want[both]) if both.any() else 0.0
    check(what, live.any() and diff <= 1e-12 and moved > 0,
          f"max rel diff {diff:.3g}, A's differ by up to {moved:.3g} relative")


S = gj["raw_sums"][:]
labels = list(gj["sum_slot"][:])
with np.errstate(invalid="ignore", divide="ignore"):
    value_check("(e) lagrangian/rho_L_u of the joined sums", gj["rho_L_u"][:], rho_u(S),
                ga["rho_L_u"][:])
    du2 = S[..., labels.index("sum_du^2")] / S[..., 0]
    value_check("(e) lagrangian/D_u of the joined sums", gj["D_u"][:], du2, ga["D_u"][:])
    P = gj["raw_pdf"][:]
    width = 2.0 * float(J.delta) / nb
    value_check("(e) lagrangian/pdf_y of the joined counts", gj["pdf_y"][:],
                P[..., :nb] / (P[..., nb:nb + 1] * width), ga["pdf_y"][:])
    Q = qj["sums"][:]
    n = Q[:, 4:].sum(axis=1, keepdims=True)
    value_check("(e) quadrants/uv of the joined sums", qj["uv"][:], Q[:, :4] / n, qa["uv"][:])
    value_check("(e) quadrants/uv_fraction of the joined sums", qj["uv_fraction"][:],
                Q[:, :4] / Q[:, :4].sum(axis=1, keepdims=True), qa["uv_fraction"][:])
sys.exit("FAIL: " + "; ".join(bad) if bad else 0)
PY
# a B without the raw records (as written before them) or gathered otherwise: a note, no group
# (nccopy: a stats.nc is written from memory, which the netCDF library does not reopen to edit)
nccopy "$b" "$work/old.nc" && nccopy "$b" "$work/other.nc"
/usr/bin/python3 - "$work/old.nc" "$work/other.nc" << 'PY' || { echo "FAIL: cannot edit the copies"; exit 1; }
import sys
import netCDF4
with netCDF4.Dataset(sys.argv[1], "a") as d:
    d["lagrangian"].renameVariable("raw_sums", "renamed_sums")
    d["quadrants"].renameVariable("batch_welford", "renamed_batches")
with netCDF4.Dataset(sys.argv[2], "a") as d:
    d["lagrangian"].horizon = 0.2
PY
expect_left_out() { # expect_left_out B NOTE_PATTERN GROUPS_KEPT [--window ...]
  local bfile=$1 pattern=$2 kept=$3
  shift 3
  rm -f "$work/j2.nc"
  msg=$("$chansph" extract "$a" "$bfile" --nc "$work/j2.nc" "$@" 2>&1)
  local rc=$?
  echo "$msg" | grep note
  [ $rc -eq 0 ] || { echo "FAIL: extract A $bfile exits $rc"; exit 1; }
  echo "$msg" | grep -q -- "$pattern" || { echo "FAIL: no note '$pattern'"; exit 1; }
  got=$(/usr/bin/python3 -c "import netCDF4, sys; print(','.join(sorted(netCDF4.Dataset(sys.argv[1]).groups)))" "$work/j2.nc")
  [ "$got" = "$kept" ] || { echo "FAIL: extract A $bfile $*: groups $got, not $kept"; exit 1; }
}
expect_left_out "$work/old.nc" "old.nc: group 'lagrangian' has no raw sums.*left out" eulerian
expect_left_out "$work/old.nc" "old.nc: group 'quadrants' has no raw sums.*left out" eulerian
expect_left_out "$work/other.nc" "other.nc: group lagrangian gathered otherwise.*horizon" eulerian,quadrants
expect_left_out "$b" "window restricts the joined range" eulerian --window 0:0.7
expect_left_out "$b" "groups eulerian, lagrangian, quadrants" eulerian,lagrangian,quadrants --window 0:
rm -f "$work/one.nc"
"$chansph" extract "$a" --nc "$work/one.nc" > /dev/null 2>&1 || { echo "FAIL: extract A --nc"; exit 1; }
got=$(/usr/bin/python3 -c "import netCDF4, sys; print(','.join(sorted(netCDF4.Dataset(sys.argv[1]).groups)))" "$work/one.nc")
[ "$got" = "eulerian" ] || { echo "FAIL: one file --nc has groups $got, not eulerian (as before)"; exit 1; }
# chansph-stats lagr_table reads the joined file: its blocks of one release are the file's
# T_L_stderr (the same formula, from the history), and every quadrant row is printed
root=$(cd "$(dirname "$0")/.." && pwd)
tab=$("$root/stats/python/chansph-stats" lagr_table "$j" 2>&1) ||
  { echo "$tab"; echo "FAIL: chansph-stats lagr_table on the joined file"; exit 1; }
echo "$tab" | awk -F'|' '$3 ~ /^ [uvw] $/ && $5 !~ /nan/ {n++; if ($5 + 0 != $9 + 0) bad++}
  END {exit !(n >= 1 && !bad)}' ||
  { echo "$tab"; echo "FAIL: lagr_table: blocks of 1 release differ from T_L_stderr"; exit 1; }
[ "$(echo "$tab" | grep -c "share of u'v'")" = 2 ] ||
  { echo "$tab"; echo "FAIL: lagr_table: not 2 quadrant levels"; exit 1; }
echo "PASS: groups lagrangian and quadrants of two segments joined"
