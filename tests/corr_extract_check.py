#!/usr/bin/env python3
"""Issue 25: the window records of group correlations in stats.nc and their re-averaging by
`chansph extract --window T0:T1 --nc OUT.nc` (docs/stats-format.md, group correlations).

Checks, on a run with at least 3 complete windows (restart_bitwise_all_stats):
1. extract over all windows: R, rho, E equal the run's own group (derived by the engine from
   its 2-D sums) to 1e-12 relative (here and below: of the largest |value| of the level's row,
   the scale of the round-off of sums over wavenumbers); the *_stderr, n_batches, samples and the window
   records bit for bit.
2. R, rho, E of the run's group recomputed here from the window records (numpy FFTs of the
   1-D sums of all windows) equal the run's to 1e-12 relative: the records hold the run.
3. a sub-range of two complete windows, and one of a single window: extract's R, rho, E are
   those numpy computes from the records of those windows alone (1e-12 relative), its
   window records are those rows of the run's, n_batches counts them.
4. the standard errors of rho (and R, E) by batch means over the complete windows computed
   here, each window's rho from its own R, equal the *_stderr of the run's group and of the
   sub-range file (1e-12 relative of the row's largest value).
5. a file whose group has no window records (its configuration attributes removed, as in a
   file written before them): extract copies the group whole and says so on stderr.
6. window records of another layout (more closed windows than rows): exit 1, an error naming
   the file and the group, no output file.
7. the gap correction (docs/stats-format.md): where grid cells were empty, R over the filled
   pairs (R / P, P from the window records' mask sums) and E its cosine transform, as numpy
   computes them in 1-3; gap_corrected and pair_fraction_x, _z as numpy finds them. With
   --gaps the run must have empty cells (every level corrected), else none.

usage: corr_extract_check.py CHANSPH STATS.nc WORK [--gaps]
"""
import os
import subprocess
import sys

import h5py
import netCDF4
import numpy as np

chansph, stats, work = sys.argv[1:4]
gaps = "--gaps" in sys.argv[4:]
os.makedirs(work, exist_ok=True)
COMP = ["uu", "vv", "ww", "uv"]
TOL = 1e-12
failures = []


def check(ok, what):
    print("%s: %s" % ("ok" if ok else "FAIL", what))
    if not ok:
        failures.append(what)


def extract(path, rng, out):
    r = subprocess.run([chansph, "extract", path, "--window", rng, "--nc", out],
                       capture_output=True, text=True)
    sys.stdout.write(r.stdout + r.stderr)
    if r.returncode != 0:
        sys.exit("FAIL: chansph extract %s --window %s --nc exited %d" % (path, rng, r.returncode))
    return r.stderr


def inverse(half, n):
    """The inverse DFT of a spectrum given at its stored k >= 0 (the rest its conjugates)."""
    full = np.zeros((half.shape[0], n), complex)
    m = np.arange(n)
    stored = m < half.shape[1]
    full[:, m[stored]] = half[:, m[stored]]
    partner = ~stored  # the conjugates of the stored k >= 0
    full[:, m[partner]] = np.conj(half[:, (n - m[partner]) % n])
    return np.real(np.fft.ifft(full, axis=1)) * n


def pair_fraction(g, rows):
    """P(l) along x and z of the window rows pooled, and which levels are gap-corrected (their
    mask sums cover all planes and some cell was empty)."""
    ns = np.ma.filled(g["window_samples"][rows], np.nan).sum(axis=0)
    planes = np.ma.filled(g["window_mask_planes"][rows], np.nan).sum(axis=0)
    empty = np.ma.filled(g["window_empty_cells"][rows], np.nan).sum(axis=0)
    nx, nz = g.dimensions["separation_x"].size, g.dimensions["separation_z"].size
    norm = 1.0 / ((nx * nz) ** 2 * planes)
    P = {d: inverse(np.ma.filled(g["window_mask_k" + d][rows], np.nan).sum(axis=0), n) *
         norm[:, None] for d, n in (("x", nx), ("z", nz))}
    return P, (planes == ns) & (planes > 0) & (empty > 0)


def results(g, rows):
    """R, rho [name] (level, n) and E [name] (level, n) of the window rows pooled, as numpy
    derives them from the 1-D sums (full spectrum from its Hermitian half, inverse DFT), gap-
    corrected where the engine corrects: R / P, E the cosine transform of that R."""
    raw = {k: np.ma.filled(g[k][rows], np.nan)  # plain arrays: 0/0 is NaN, not masked
           for k in ("window_spectra_kx", "window_spectra_kz", "window_samples")}
    X = raw["window_spectra_kx"].sum(axis=0)  # (level, kx, slot)
    Z = raw["window_spectra_kz"].sum(axis=0)
    ns = raw["window_samples"].sum(axis=0)
    nx, nz = g.dimensions["separation_x"].size, g.dimensions["separation_z"].size
    lx, lz = float(g.lx), float(g.lz)
    norm = 1.0 / ((nx * nz) ** 2 * ns)
    P, corr = pair_fraction(g, rows)
    out = {}
    for d, S, n, L in (("x", X, nx, lx), ("z", Z, nz, lz)):
        for q, c in enumerate(COMP):
            R = inverse(S[:, :, q] + (1j * S[:, :, 4] if q == 3 else 0), n) * norm[:, None]
            R = np.where(corr[:, None], R / P[d], R)
            out["R_%s_%s" % (c, d)] = R
            if q < 3:
                m = np.arange(S.shape[1])
                f = np.where((m == 0) | (2 * m == n), 1.0, 2.0)
                scale = L / (2 * np.pi) if n > 1 else 1.0
                cosine = np.real(np.fft.fft(R, axis=1))[:, : S.shape[1]] / n
                out["E_%s_k%s" % (c, d)] = f * np.where(corr[:, None], cosine,
                                                        S[:, :, q] * norm[:, None]) * scale
        for q, c in enumerate(COMP):
            r0 = out["R_%s_%s" % (COMP[0] if q == 3 else c, d)][:, :1]
            with np.errstate(invalid="ignore", divide="ignore"):  # w' = 0 in 2-D: NaN
                out["rho_%s_%s" % (c, d)] = out["R_%s_%s" % (c, d)] / r0
    return out


def batches(g, rows):
    """The complete windows (batches) among rows."""
    return [r for r in rows if g["window_complete"][r] == 1]


def stderr(g, rows):
    """Batch-means standard errors over the complete windows among rows, each its own R, rho, E."""
    per = [results(g, [r]) for r in batches(g, rows)]
    n = len(per)
    return {k: np.std([p[k] for p in per], axis=0, ddof=1) / np.sqrt(n) for k in per[0]}, n


def close(a, b):
    a, b = np.ma.filled(a, np.nan), np.ma.filled(b, np.nan)
    if a.shape != b.shape or not np.array_equal(np.isnan(a), np.isnan(b)):
        return False
    scale = np.nanmax(np.abs(b), axis=1, keepdims=True) if not np.all(np.isnan(b)) else 0.0
    return bool(np.all(np.abs(np.nan_to_num(a - b)) <= TOL * np.nan_to_num(scale)))


def compare(got, want, what):
    bad = [k for k in want if not close(got[k][:], want[k])]
    check(not bad, "%s%s" % (what, (": DIFFERENT " + ", ".join(bad)) if bad else ""))


run = netCDF4.Dataset(stats)["correlations"]
rows = run.dimensions["window"].size
done = [r for r in range(rows) if run["window_complete"][r] == 1]
print("%s: %d window rows, complete: %s" % (stats, rows, done))
if len(done) < 3:
    sys.exit("FAIL: the run needs at least 3 complete windows")
names = [v for v in run.variables if v.startswith(("R_", "rho_", "E_"))]
values = [v for v in names if not v.endswith("_stderr")]
errors = [v for v in names if v.endswith("_stderr")]
check(len(errors) == 22 and all(v + "_stderr" in run.variables for v in values),
      "stats.nc has the *_stderr of every R, rho, E (rho included): %d" % len(errors))

# 1, 2: all windows
extract(stats, ":", work + "/all.nc")
alln = netCDF4.Dataset(work + "/all.nc")["correlations"]
compare(alln, {k: run[k][:] for k in values}, "extract over all windows: R, rho, E = the run's")
bits = [k for k in errors + ["n_batches", "samples", "windows", "window_samples",
                             "window_spectra_kx", "window_spectra_kz", "window_complete"]
        if not np.array_equal(np.ma.filled(alln[k][:], np.nan), np.ma.filled(run[k][:], np.nan),
                              equal_nan=True)]
check(not bits, "extract over all windows: stderr, n_batches, samples, records bit for bit" +
      (": DIFFERENT " + ", ".join(bits) if bits else ""))
compare(run, results(run, list(range(rows))), "numpy from the records of all windows = the run's")

# 3, 4: sub-ranges
se, n = stderr(run, list(range(rows)))
compare(run, {k + "_stderr": v for k, v in se.items()},
        "run's *_stderr (rho included) = batch means over its %d windows computed here" % n)
check(list(run["n_batches"][:]) == [n] * run.dimensions["level"].size, "run's n_batches = %d" % n)
a, b = done[1], done[2]
t0, t1 = run["window_bounds"][a][0], run["window_bounds"][b][1]
for sel, rng in (([a, b], "%.9g:%.9g" % (t0, t1)), ([b], "%.9g:%.9g" % tuple(run["window_bounds"][b]))):
    out = "%s/range_%d_%d.nc" % (work, sel[0], sel[-1])
    extract(stats, rng, out)
    sub = netCDF4.Dataset(out)["correlations"]
    compare(sub, results(run, sel), "extract --window %s: R, rho, E = numpy from windows %s" %
            (rng, sel))
    same = all(np.array_equal(sub[k][:], run[k][sel]) for k in
               ("windows", "window_samples", "window_spectra_kx", "window_spectra_kz"))
    check(same and sub.dimensions["window"].size == len(sel),
          "extract --window %s: its window records are rows %s of the run's" % (rng, sel))
    nb = list(sub["n_batches"][:])
    check(nb == [len(sel)] * len(nb), "extract --window %s: n_batches %s" % (rng, nb))
    if len(sel) > 1:
        se, n = stderr(run, sel)
        compare(sub, {k + "_stderr": v for k, v in se.items()},
                "extract --window %s: *_stderr (rho included) = batch means over windows %s" %
                (rng, sel))
    else:
        nan = all(np.all(np.ma.getmaskarray(sub[k][:])) for k in errors)
        check(nan, "extract --window %s: one batch, every *_stderr a fill value" % rng)

# 7: the gap correction
P, corr = pair_fraction(run, list(range(rows)))
check(list(run["gap_corrected"][:]) == [int(c) for c in corr] and all(corr) == gaps and
      (gaps or not any(corr)), "gap_corrected %s (%s)" % (list(run["gap_corrected"][:]),
                                                          "empty cells" if gaps else "no gaps"))
for d in "xz":
    compare(run, {"pair_fraction_" + d: P[d]}, "pair_fraction_%s = numpy's from the mask sums" % d)
if gaps:
    print("P(l_x) at the first levels: %s" % np.round(P["x"][:, :3], 4).tolist())

# 5: a file without window records
old = work + "/old.nc"
subprocess.run(["cp", stats, old], check=True)
os.chmod(old, 0o644)  # stats.nc is written read-only
with h5py.File(old, "a") as h:  # (netCDF4 does not open these files for writing)
    for k in ("lx", "lz", "slab_half", "delta", "average_start", "window_length"):
        del h["correlations"].attrs[k]
note = extract(old, ":", work + "/old_range.nc")
check("copied whole" in note and old in note, "a file without window records: a note naming it")
cp = netCDF4.Dataset(work + "/old_range.nc")["correlations"]


def equal(x, y):
    if x.dtype == str or y.dtype == str:
        return x.dtype == y.dtype and list(x[:]) == list(y[:])
    return np.array_equal(np.ma.filled(x[:], np.nan), np.ma.filled(y[:], np.nan),
                          equal_nan=x.dtype.kind == "f")


same = sorted(cp.variables) == sorted(run.variables) and all(
    equal(cp[k], run[k]) for k in run.variables)
check(same, "a file without window records: group correlations copied whole")

# 6: window records of another layout: an input error naming the file and the group
bad = work + "/bad.nc"
subprocess.run(["cp", stats, bad], check=True)
os.chmod(bad, 0o644)
with h5py.File(bad, "a") as h:
    h["correlations"].attrs["closed_windows"] = np.int32(rows + 1)
r = subprocess.run([chansph, "extract", bad, "--nc", work + "/bad_range.nc"], capture_output=True,
                   text=True)
print(r.stderr.strip())
check(r.returncode == 1 and bad in r.stderr and "group 'correlations'" in r.stderr and
      not os.path.exists(work + "/bad_range.nc"),
      "damaged window records: exit %d, an error naming file and group, no output" % r.returncode)

if failures:
    sys.exit("FAIL: %d check(s): %s" % (len(failures), "; ".join(failures)))
print("PASS: correlations re-averaged over windows of stats.nc")
