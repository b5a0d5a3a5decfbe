/** @file corr_nc.c @brief The group `correlations` of stats.nc (corr.h): its writer (whole
 *         run, or a range of its windows for `chansph extract --window --nc`), its reader of
 *         the window records, and the engine's table of operations. */
#include "contract.h"
#include "corr.h"
#include "engine.h"
#include "ncutil.h"

#include <math.h>
#include <netcdf.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "ncout.h"

static const double two_pi = 6.283185307179586;

#define CK(call) NC_TRY(call, done)

/* The coordinate variables of the correlations group: separations, wavenumbers and the
   flattened r2c index with its wavenumbers. d: dimension ids {x, z, kx, kz, k_index}. */
static int write_axes(const struct corr *c, int g, const int d[5], double *tmp, char *err,
                      size_t errlen) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const int dx = d[0], dz = d[1], dkx = d[2], dkz = d[3], dkk = d[4];
  int rc = NC_NOERR, v;
  for (int i = 0; i < nx; i++) tmp[i] = i * c->cfg.lx / nx;
  CK(ncout_def(g, "separation_x", NC_DOUBLE, 1, &dx, "m", "streamwise separation l_x", &v));
  CK(nc_put_var_double(g, v, tmp));
  for (int i = 0; i < nz; i++) tmp[i] = nz > 1 ? i * c->cfg.lz / nz : 0.0;
  CK(ncout_def(g, "separation_z", NC_DOUBLE, 1, &dz, "m", "spanwise separation l_z", &v));
  CK(nc_put_var_double(g, v, tmp));
  for (int i = 0; i < nxh; i++) tmp[i] = two_pi * i / c->cfg.lx;
  CK(ncout_def(g, "kx", NC_DOUBLE, 1, &dkx, "1/m", "streamwise wavenumber", &v));
  CK(nc_put_var_double(g, v, tmp));
  for (int i = 0; i < nzh; i++) tmp[i] = nz > 1 ? two_pi * i / c->cfg.lz : 0.0;
  CK(ncout_def(g, "kz", NC_DOUBLE, 1, &dkz, "1/m", "spanwise wavenumber", &v));
  CK(nc_put_var_double(g, v, tmp));
  /* the flattened r2c index: its coordinate, and the wavenumbers of each entry (kx negative
     for ix > nx/2) as auxiliary coordinates of spectra */
  {
    const size_t nk = (size_t)nx * (size_t)nzh;
    long long *ki = mem_alloc(1, nk * sizeof *ki, "correlations");
    double *kk = mem_alloc(1, 2 * nk * sizeof *kk, "correlations");
    int vk, vkx, vkz;
    rc = NC_NOERR;
    for (int i = 0; i < nx && rc == NC_NOERR; i++)
      for (int k = 0; k < nzh; k++) {
        const size_t j = (size_t)i * (size_t)nzh + (size_t)k;
        ki[j] = (long long)j;
        kk[j] = two_pi * (i <= nx / 2 ? i : i - nx) / c->cfg.lx;
        kk[nk + j] = nz > 1 ? two_pi * k / c->cfg.lz : 0.0;
      }
    if (rc == NC_NOERR)
      rc = ncout_def(g, "k_index", NC_INT64, 1, &dkk, "1",
                     "index of the r2c grid entry [kx][kz]: ix (nz/2+1) + iz", &vk);
    if (rc == NC_NOERR)
      rc = ncout_def(g, "k_index_kx", NC_DOUBLE, 1, &dkk, "1/m",
                     "streamwise wavenumber of the r2c entry", &vkx);
    if (rc == NC_NOERR)
      rc = ncout_def(g, "k_index_kz", NC_DOUBLE, 1, &dkk, "1/m",
                     "spanwise wavenumber of the r2c entry", &vkz);
    if (rc == NC_NOERR) rc = nc_put_var_longlong(g, vk, ki);
    if (rc == NC_NOERR) rc = nc_put_var_double(g, vkx, kk);
    if (rc == NC_NOERR) rc = nc_put_var_double(g, vkz, kk + nk);
    free(ki), free(kk);
    CK(rc);
  }
done:
  return rc;
}

/* R_ij and rho_ij along x and z at every level (Eq. 5.57, 5.58) and the spectrum slot labels. */
static int write_correlations(const struct corr *c, int g, const int d[4], const double *rx,
                              const double *rz, double *tmp, char *err, size_t errlen) {
  const int nl = c->cfg.n_levels, nx = c->cfg.nx, nz = c->cfg.nz;
  const int dl = d[0], dx = d[1], dz = d[2], dsl = d[3];
  int rc = NC_NOERR, v;
  static const char *const slots[CS_LEN] = {"uu", "vv", "ww", "Re_uv", "Im_uv"};
  CK(ncout_labels(g, "spectrum_slot", dsl, "component of the summed spectra", slots));
  static const char *const comp[4] = {"uu", "vv", "ww", "uv"};
  for (int q = 0; q < 4; q++) {
    char name[32], ln[160];
    const int d2x[2] = {dl, dx}, d2z[2] = {dl, dz};
    for (int dir = 0; dir < 2; dir++) {
      const int n = dir ? nz : nx;
      const double *R = dir ? rz : rx;
      snprintf(name, sizeof name, "R_%s_%c", comp[q], dir ? 'z' : 'x');
      snprintf(ln, sizeof ln, "two-point correlation <%c'(r) %c'(r + l e_%c)> (Eq. 5.57)",
               comp[q][0], comp[q][1], dir ? 'z' : 'x');
      CK(ncout_def(g, name, NC_DOUBLE, 2, dir ? d2z : d2x, "m^2/s^2", ln, &v));
      CK(ncout_fill(g, v));
      for (int l = 0; l < nl; l++) {
        const size_t st[2] = {(size_t)l, 0}, ct[2] = {1, (size_t)n};
        CK(ncout_put_filled(g, v, st, ct, R + ((size_t)l * 4 + q) * n, (size_t)n));
      }
      snprintf(name, sizeof name, "rho_%s_%c", comp[q], dir ? 'z' : 'x');
      snprintf(ln, sizeof ln, "normalised two-point correlation R_%s / <%c'%c'> (Eq. 5.58)",
               comp[q], comp[q][0], comp[q][0]);
      CK(ncout_def(g, name, NC_DOUBLE, 2, dir ? d2z : d2x, "1", ln, &v));
      CK(ncout_fill(g, v));
      for (int l = 0; l < nl; l++) {
        const double *src = R + ((size_t)l * 4 + q) * n;
        const double r0 = R[((size_t)l * 4 + (q == 3 ? 0 : q)) * n];
        for (int i = 0; i < n; i++) tmp[i] = src[i] / r0;
        const size_t st[2] = {(size_t)l, 0}, ct[2] = {1, (size_t)n};
        CK(ncout_put_filled(g, v, st, ct, tmp, (size_t)n));
      }
    }
  }
done:
  return rc;
}

/* The one-sided 1-D spectra E_ii over kx and kz at every level (Eq. 5.59). */
static int write_spectra(const struct corr *c, int g, const int d[3], const double *ex,
                         const double *ez, char *err, size_t errlen) {
  const int nl = c->cfg.n_levels, nzh = c->nzh, nxh = c->cfg.nx / 2 + 1;
  const int dl = d[0], dkx = d[1], dkz = d[2];
  static const char *const comp[4] = {"uu", "vv", "ww", "uv"};
  int rc = NC_NOERR, v;
  for (int q = 0; q < 3; q++) {
    char name[32], ln[160];
    for (int dir = 0; dir < 2; dir++) {
      const int n = dir ? nzh : nxh;
      const int d2[2] = {dl, dir ? dkz : dkx};
      snprintf(name, sizeof name, "E_%s_k%c", comp[q], dir ? 'z' : 'x');
      snprintf(ln, sizeof ln,
               "one-sided 1-D energy spectrum of %c' over k_%c (Eq. 5.59; sum E dk = <%c'%c'>)",
               comp[q][0], dir ? 'z' : 'x', comp[q][0], comp[q][0]);
      CK(ncout_def(g, name, NC_DOUBLE, 2, d2, "m^3/s^2", ln, &v));
      CK(ncout_fill(g, v));
      for (int l = 0; l < nl; l++) {
        const size_t st[2] = {(size_t)l, 0}, ct[2] = {1, (size_t)n};
        CK(ncout_put_filled(g, v, st, ct, (dir ? ez : ex) + ((size_t)l * 3 + q) * n, (size_t)n));
      }
    }
  }
done:
  return rc;
}

/* One [level][ncomp][n] block of the standard errors se ([level][nv], block at offset off of
   each level) as variable name (level, dim). */
static int put_stderr(int g, const char *name, const char *of, const int d2[2], const char *units,
                      const double *se, size_t nv, size_t off, int nl, int n) {
  char ln[160];
  int v, rc = NC_NOERR;
  snprintf(ln, sizeof ln, "standard error (batch means over the complete windows) of %s", of);
  if ((rc = ncout_def(g, name, NC_DOUBLE, 2, d2, units, ln, &v)) != NC_NOERR ||
      (rc = ncout_fill(g, v)) != NC_NOERR)
    return rc;
  for (int l = 0; l < nl && rc == NC_NOERR; l++) {
    const size_t st[2] = {(size_t)l, 0}, ct[2] = {1, (size_t)n};
    rc = ncout_put_filled(g, v, st, ct, se + (size_t)l * nv + off, (size_t)n);
  }
  return rc;
}

/* The gap correction's P(l) along x and z and the levels it corrected (corr.h, Gaps). d:
   {level, separation_x, separation_z}. */
static int write_pair_fraction(const struct corr *c, int g, const int d[3], const double *px,
                               const double *pz, const int *corrected, char *err, size_t errlen) {
  const int nl = c->cfg.n_levels;
  int rc = NC_NOERR, v;
  for (int dir = 0; dir < 2; dir++) {
    const int d2[2] = {d[0], d[1 + dir]}, n = dir ? c->cfg.nz : c->cfg.nx;
    CK(ncout_def(g, dir ? "pair_fraction_z" : "pair_fraction_x", NC_DOUBLE, 2, d2, "1",
                 dir ? "fraction of the grid's cell pairs at separation l_z that are both "
                       "filled (the gap correction divides R by it)"
                     : "fraction of the grid's cell pairs at separation l_x that are both "
                       "filled (the gap correction divides R by it)",
                 &v));
    CK(ncout_fill(g, v));
    for (int l = 0; l < nl; l++) {
      const size_t st[2] = {(size_t)l, 0}, ct[2] = {1, (size_t)n};
      CK(ncout_put_filled(g, v, st, ct, (dir ? pz : px) + (size_t)l * n, (size_t)n));
    }
  }
  CK(ncout_def(g, "gap_corrected", NC_INT, 1, &d[0], "1",
               "1 if R, rho and E of the level are over the filled cell pairs only (some cells "
               "were empty and the mask sums cover every plane), 0 if uncorrected",
               &v));
  CK(nc_put_var_int(g, v, corrected));
done:
  return rc;
}

/* The batch-means standard errors of R, rho and E (corr_range_stderr over every row) and the
   batches per level. d: {level, separation_x, separation_z, kx, kz}. */
static int write_stderr(const struct corr *c, int g, const int d[5], char *err, size_t errlen) {
  const int nl = c->cfg.n_levels, nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh;
  const size_t nxh = (size_t)nx / 2 + 1, nv = corr_nv(c);
  const size_t off_ex = 4 * (size_t)(nx + nz), off_rho = off_ex + 3 * (nxh + (size_t)nzh);
  double *se = mem_alloc((size_t)nl * nv, sizeof(double), "correlations");
  int *nb = mem_alloc(1, (size_t)nl * sizeof(int), "correlations");
  int rc = NC_NOERR, v;
  corr_range_stderr(c, 0, corr_rows(c), se, nb);
  CK(ncout_def(g, "n_batches", NC_INT, 1, &d[0], "1",
               "complete windows with planes at the level: the batches of the *_stderr", &v));
  CK(nc_put_var_int(g, v, nb));
  static const char *const comp[4] = {"uu", "vv", "ww", "uv"};
  for (int q = 0; q < 4; q++)
    for (int dir = 0; dir < 2; dir++) {
      char name[64], of[32];
      const int d2[2] = {d[0], d[1 + dir]}, n = dir ? nz : nx;
      const size_t off = dir ? 4 * (size_t)nx + (size_t)q * nz : (size_t)q * nx;
      snprintf(of, sizeof of, "R_%s_%c", comp[q], dir ? 'z' : 'x');
      snprintf(name, sizeof name, "%s_stderr", of);
      CK(put_stderr(g, name, of, d2, "m^2/s^2", se, nv, off, nl, n));
      snprintf(of, sizeof of, "rho_%s_%c", comp[q], dir ? 'z' : 'x');
      snprintf(name, sizeof name, "%s_stderr", of);
      CK(put_stderr(g, name, of, d2, "1", se, nv, off_rho + off, nl, n));
      if (q == 3) continue;
      const int d2k[2] = {d[0], d[3 + dir]}, nk = dir ? nzh : (int)nxh;
      snprintf(of, sizeof of, "E_%s_k%c", comp[q], dir ? 'z' : 'x');
      snprintf(name, sizeof name, "%s_stderr", of);
      CK(put_stderr(g, name, of, d2k, "m^3/s^2", se, nv,
                    off_ex + (dir ? 3 * nxh + (size_t)q * nzh : (size_t)q * nxh), nl, nk));
    }
done:
  free(se), free(nb);
  return rc;
}

/* Configuration attributes of the group, in this order (read back by corr_nc_read). */
static const char *const cfg_att[] = {"lx",           "lz", "slab_half", "delta", "average_start",
                                      "window_length"};
enum { N_CFG_ATT = 6 };

/* The results R along x and z [level][4][n], E over k_x and k_z [level][3][n], the pair
   fractions P along x and z [level][n] and the levels gap-corrected: of the 2-D sums if the
   engine has them, else of the window records pooled (corr_range_values). */
static void results_of(const struct corr *c, double *rx, double *rz, double *ex, double *ez,
                       double *px, double *pz, int *corrected) {
  if (c->spec) {
    corr_results(c, rx, rz, ex, ez);
    corr_pair_fraction(c, px, pz, corrected);
    return;
  }
  corr_range_pair_fraction(c, 0, corr_rows(c), px, pz, corrected);
  const size_t nl = (size_t)c->cfg.n_levels, nx = (size_t)c->cfg.nx, nz = (size_t)c->cfg.nz;
  const size_t nxh = nx / 2 + 1, nzh = (size_t)c->nzh, nv = corr_nv(c);
  double *v = mem_alloc(nl * nv, sizeof(double), "correlations");
  corr_range_values(c, 0, corr_rows(c), v);
  for (size_t l = 0; l < nl; l++) {
    const double *s = v + l * nv;
    memcpy(rx + l * 4 * nx, s, 4 * nx * sizeof(double));
    memcpy(rz + l * 4 * nz, s + 4 * nx, 4 * nz * sizeof(double));
    memcpy(ex + l * 3 * nxh, s + 4 * nx + 4 * nz, 3 * nxh * sizeof(double));
    memcpy(ez + l * 3 * nzh, s + 4 * nx + 4 * nz + 3 * nxh, 3 * nzh * sizeof(double));
  }
  free(v);
}

/* The window coordinate (middle, bounds: nominal start and end), the raw window records and
   the completeness flag. d: {window, window_field}. */
static int write_window_axes(const struct corr *c, int g, const int d[2], char *err,
                             size_t errlen) {
  const size_t rows = corr_rows(c);
  double *t = mem_alloc(3 * rows, sizeof(double), "correlations"), *t0 = t + rows, *t1 = t0 + rows;
  int *ok = mem_alloc(rows, sizeof(int), "correlations");
  int rc = NC_NOERR, v;
  for (size_t r = 0; r < rows; r++) {
    t0[r] = c->win[r * CW_LEN + CW_T0], t1[r] = c->win[r * CW_LEN + CW_T1];
    t[r] = 0.5 * (t0[r] + t1[r]);
    ok[r] = r < c->nwin && c->win[r * CW_LEN + CW_PARTIAL] == 0.0;
  }
  static const char *const wf[CW_LEN] = {"t_start", "t_end", "snapshots", "partial"};
  CK(ncout_labels(g, "window_field", d[1], "field of the window records", wf));
  CK(ncout_def(g, "window", NC_DOUBLE, 1, &d[0], "s", "middle of the averaging window", &v));
  CK(nc_put_var_double(g, v, t));
  CK(ncout_bounds(g, "window", v, d[0], "s", "nominal start and end of the window", t0, t1, rows));
  const int dw[2] = {d[0], d[1]};
  CK(ncout_def(g, "windows", NC_DOUBLE, 2, dw, NULL,
               "per window: nominal start and end [s], snapshots, 1 if partial (resumed from a "
               "checkpoint without window records: not a batch)",
               &v));
  CK(nc_put_var_double(g, v, c->win));
  CK(ncout_def(g, "window_complete", NC_INT, 1, &d[0], "1",
               "1 if the window is a batch of the *_stderr (closed, not partial), else 0 (the "
               "open last window of the run, or a partial one)",
               &v));
  CK(nc_put_var_int(g, v, ok));
  const int nwin = (int)c->nwin;
  CK(nc_put_att_int(g, NC_GLOBAL, "closed_windows", NC_INT, 1, &nwin));
done:
  free(t), free(ok);
  return rc;
}

/* Define a double variable of group g and write all of data; a netCDF status. */
static int def_put(int g, const char *name, int nd, const int *dims, const char *units,
                   const char *long_name, const double *data) {
  int v, rc = ncout_def(g, name, NC_DOUBLE, nd, dims, units, long_name, &v);
  return rc != NC_NOERR ? rc : nc_put_var_double(g, v, data);
}

/* The per-window records (issue 25): planes per level and the 1-D sums of the spectra over
   k_x and over k_z. d: {window, window_field, level, kx, kz, spectrum_slot}. */
static int write_windows(const struct corr *c, int g, const int d[6], char *err, size_t errlen) {
  const size_t rows = corr_rows(c), nl = (size_t)c->cfg.n_levels, nzh = (size_t)c->nzh;
  const size_t nxh = (size_t)c->cfg.nx / 2 + 1, n = rows * nl, lm = c->n1d + CM_LEN;
  double *kx = mem_alloc(n * (nxh + nzh) * (CS_LEN + 1) + 2 * n, sizeof(double), "correlations");
  double *kz = kx + n * nxh * CS_LEN, *mx = kz + n * nzh * CS_LEN, *mz = mx + n * nxh;
  double *mp = mz + n * nzh, *me = mp + n;
  int rc = NC_NOERR, v;
  for (size_t i = 0; i < n; i++) { /* [row][level][n1d][slot] -> kx and kz parts */
    const double *X = c->wspec + i * c->n1d * CS_LEN, *XM = c->wmask + i * lm;
    memcpy(kx + i * nxh * CS_LEN, X, nxh * CS_LEN * sizeof(double));
    memcpy(kz + i * nzh * CS_LEN, X + nxh * CS_LEN, nzh * CS_LEN * sizeof(double));
    memcpy(mx + i * nxh, XM, nxh * sizeof(double));
    memcpy(mz + i * nzh, XM + nxh, nzh * sizeof(double));
    mp[i] = XM[c->n1d + CM_PLANES], me[i] = XM[c->n1d + CM_EMPTY];
  }
  if ((rc = write_window_axes(c, g, d, err, errlen)) != NC_NOERR) goto done;
  const int ds[2] = {d[0], d[2]}, dx[4] = {d[0], d[2], d[3], d[5]},
            dz[4] = {d[0], d[2], d[4], d[5]};
  CK(ncout_def(g, "window_samples", NC_DOUBLE, 2, ds, "1", "per window: planes accumulated", &v));
  CK(nc_put_var_double(g, v, c->wsamp));
  CK(ncout_def(g, "window_spectra_kx", NC_DOUBLE, 4, dx, "m^2/s^2",
               "per window: raw sums over the planes and over k_z of conj(F u_i) F u_j at k_x >= "
               "0 (the -k_x partners folded in: uu, vv, ww, Re uv, Im uv of k_x)",
               &v));
  CK(nc_put_var_double(g, v, kx));
  CK(ncout_def(g, "window_spectra_kz", NC_DOUBLE, 4, dz, "m^2/s^2",
               "per window: raw sums over the planes and over k_x of conj(F u_i) F u_j at the "
               "stored k_z >= 0 (uu, vv, ww, Re uv, Im uv)",
               &v));
  CK(nc_put_var_double(g, v, kz));
  const int dmx[3] = {d[0], d[2], d[3]}, dmz[3] = {d[0], d[2], d[4]};
  CK(def_put(g, "window_mask_kx", 3, dmx, "1",
             "per window: raw sums over the planes and over k_z of |F m|^2, m the grid's mask (1 "
             "filled, 0 empty), at k_x >= 0 (the -k_x partners folded in)",
             mx));
  CK(def_put(g, "window_mask_kz", 3, dmz, "1",
             "per window: raw sums over the planes and over k_x of |F m|^2 at the stored k_z >= 0",
             mz));
  CK(def_put(g, "window_mask_planes", 2, ds, "1",
             "per window: planes whose mask was summed (fewer than window_samples: the window "
             "began before a resume from a checkpoint without them)",
             mp));
  CK(def_put(g, "window_empty_cells", 2, ds, "1", "per window: empty grid cells among those planes",
             me));
done:
  free(kx);
  return rc;
}

/* The group's header: description, configuration attributes, dimensions and the level axis.
   d: {level, separation_x, separation_z, kx, kz, k_index, spectrum_slot, window,
   window_field}. */
static int write_header(const struct corr *c, int g, int d[9], char *err, size_t errlen) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  int rc = NC_NOERR, v;
  static const char desc[] =
      "two-point correlations and 1-D spectra in wall-parallel planes (thesis Eq. "
      "5.57-5.59); a level and its mirror 2 delta - y (v -> -v) are both sampled";
  static const char range[] =
      "; re-averaged by chansph extract over the windows of the file: R and E from their 1-D "
      "sums (no 2-D sums: spectra and empty_cells left out)";
  static const char gaps[] =
      "; R over the filled cell pairs only where cells were empty (gap_corrected, "
      "pair_fraction_x, pair_fraction_z), E the cosine transform of that R";
  char text[sizeof desc + sizeof gaps + sizeof range];
  snprintf(text, sizeof text, "%s%s%s", desc, gaps, c->spec ? "" : range);
  CK(nc_put_att_text(g, NC_GLOBAL, "description", strlen(text), text));
  const double cv[N_CFG_ATT] = {c->cfg.lx,    c->cfg.lz,      c->cfg.half,
                                c->cfg.delta, c->cfg.t_start, c->cfg.window};
  for (int k = 0; k < N_CFG_ATT; k++)
    CK(nc_put_att_double(g, NC_GLOBAL, cfg_att[k], NC_DOUBLE, 1, cv + k));
  const size_t len[9] = {
      (size_t)c->cfg.n_levels,  (size_t)nx, (size_t)nz,   (size_t)nxh, (size_t)nzh,
      (size_t)nx * (size_t)nzh, CS_LEN,     corr_rows(c), CW_LEN};
  static const char *const dn[9] = {"level",   "separation_x",  "separation_z", "kx",          "kz",
                                    "k_index", "spectrum_slot", "window",       "window_field"};
  for (int k = 0; k < 9; k++) CK(nc_def_dim(g, dn[k], len[k], &d[k]));
  CK(ncout_def(g, "level", NC_DOUBLE, 1, d, "m", "height of the plane above the lower wall", &v));
  CK(nc_put_var_double(g, v, c->cfg.y));
  CK(ncout_def(g, "y_plus", NC_DOUBLE, 1, d, "1", "level in wall units of stats.u_tau_ref", &v));
  CK(nc_put_var_double(g, v, c->cfg.y_plus));
done:
  return rc;
}

/* The planes per level (the 2-D sums' count, or the windows'), the empty cells (2-D sums only)
   and the raw 2-D sums. d as for write_header. */
static int write_sums(const struct corr *c, int g, const int d[9], char *err, size_t errlen) {
  const size_t nl = (size_t)c->cfg.n_levels;
  double *ns = mem_calloc(nl, sizeof(double), "correlations");
  int rc = NC_NOERR, v;
  for (size_t r = 0; r < corr_rows(c) && !c->spec; r++)
    for (size_t l = 0; l < nl; l++) ns[l] += c->wsamp[r * nl + l];
  CK(ncout_def(g, "samples", NC_DOUBLE, 1, d, "1", "planes accumulated", &v));
  CK(nc_put_var_double(g, v, c->spec ? c->samples : ns));
  if (!c->spec) goto done;
  CK(ncout_def(g, "empty_cells", NC_DOUBLE, 1, d, "1",
               "grid cells without a particle, summed over the planes (set to zero fluctuation)",
               &v));
  CK(nc_put_var_double(g, v, c->empty));
  const int d3[3] = {d[0], d[5], d[6]};
  CK(ncout_def(g, "spectra", NC_DOUBLE, 3, d3, "m^2/s^2",
               "raw sums over the planes of conj(F u_i) F u_j on the r2c grid [kx][kz]: uu, "
               "vv, ww, Re uv, Im uv (unnormalised FFTW transforms of nx x nz)",
               &v));
  static const char coords[] = "k_index_kx k_index_kz";
  CK(nc_put_att_text(g, v, "coordinates", strlen(coords), coords));
  CK(nc_put_var_double(g, v, c->spec));
done:
  free(ns);
  return rc;
}

int corr_nc_write(const struct corr *c, int ncid, char *err, size_t errlen) {
  const int nl = c->cfg.n_levels, nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh;
  const int nxh = nx / 2 + 1;
  double *rx = mem_alloc(1, (size_t)nl * 4 * nx * sizeof(double), "correlations");
  double *rz = mem_alloc(1, (size_t)nl * 4 * nz * sizeof(double), "correlations");
  double *ex = mem_alloc(1, (size_t)nl * 3 * nxh * sizeof(double), "correlations");
  double *ez = mem_alloc(1, (size_t)nl * 3 * nzh * sizeof(double), "correlations");
  double *tmp = mem_alloc(1, (size_t)(nx > nz ? nx : nz) * 4 * sizeof(double), "correlations");
  double *px = mem_alloc(1, (size_t)nl * (size_t)(nx + nz) * sizeof(double), "correlations");
  double *pz = px + (size_t)nl * nx;
  int *corrected = mem_alloc(1, (size_t)nl * sizeof(int), "correlations");
  int rc = NC_NOERR, g, d[9];
  results_of(c, rx, rz, ex, ez, px, pz, corrected);
  CK(nc_def_grp(ncid, "correlations", &g));
  if ((rc = write_header(c, g, d, err, errlen)) != NC_NOERR) goto done;
  {
    const int da[5] = {d[1], d[2], d[3], d[4], d[5]}, dc[4] = {d[0], d[1], d[2], d[6]};
    const int ds[3] = {d[0], d[3], d[4]}, de[5] = {d[0], d[1], d[2], d[3], d[4]};
    const int dw[6] = {d[7], d[8], d[0], d[3], d[4], d[6]};
    /* each names its own failing call in err */
    if ((rc = write_axes(c, g, da, tmp, err, errlen)) != NC_NOERR ||
        (rc = write_correlations(c, g, dc, rx, rz, tmp, err, errlen)) != NC_NOERR ||
        (rc = write_spectra(c, g, ds, ex, ez, err, errlen)) != NC_NOERR ||
        (rc = write_pair_fraction(c, g, dc, px, pz, corrected, err, errlen)) != NC_NOERR ||
        (rc = write_stderr(c, g, de, err, errlen)) != NC_NOERR ||
        (rc = write_sums(c, g, d, err, errlen)) != NC_NOERR)
      goto done;
    rc = write_windows(c, g, dw, err, errlen);
  }
done:
  free(rx), free(rz), free(ex), free(ez), free(tmp), free(px), free(corrected);
  return rc;
}

int corr_nc_write_range(const struct corr *c, size_t r0, size_t r1, int ncid, char *err,
                        size_t errlen) {
  const size_t nl = (size_t)c->cfg.n_levels;
  struct corr s = *c; /* the rows r0 .. r1-1 only: their last open if it is the run's open one */
  s.spec = s.samples = s.empty = s.mspec = NULL;
  s.win = c->win + r0 * CW_LEN, s.wsamp = c->wsamp + r0 * nl;
  s.wspec = c->wspec + r0 * nl * c->n1d * CS_LEN;
  s.wmask = c->wmask + r0 * nl * (c->n1d + CM_LEN);
  s.nwin = r1 <= c->nwin ? r1 - r0 : r1 - r0 - 1, s.cap = s.rows = r1 - r0;
  return corr_nc_write(&s, ncid, err, errlen);
}

/* The configuration of a stored group g: levels, grid and the attributes of cfg_att; 2 if the
   attributes are absent (a file written before the window records). */
static int read_config(int g, struct corr_config *c, char *err, size_t errlen) {
  double cv[N_CFG_ATT];
  size_t nl = 0, nx = 0, nz = 0;
  int d, v;
  memset(c, 0, sizeof *c);
  for (int k = 0; k < N_CFG_ATT; k++)
    if (nc_get_att_double(g, NC_GLOBAL, cfg_att[k], cv + k) != NC_NOERR) {
      snprintf(err, errlen, "group 'correlations' has no attribute '%s'", cfg_att[k]);
      return 2;
    }
  if (nc_inq_dimid(g, "level", &d) || nc_inq_dimlen(g, d, &nl) || nl < 1 || nl > CORR_MAX_LEVELS ||
      nc_inq_dimid(g, "separation_x", &d) || nc_inq_dimlen(g, d, &nx) ||
      nc_inq_dimid(g, "separation_z", &d) || nc_inq_dimlen(g, d, &nz) || nx < 1 || nz < 1 ||
      nc_inq_varid(g, "level", &v) || nc_get_var_double(g, v, c->y) ||
      nc_inq_varid(g, "y_plus", &v) || nc_get_var_double(g, v, c->y_plus)) {
    snprintf(err, errlen, "group 'correlations': cannot read its levels and grid");
    return -1;
  }
  c->n_levels = (int)nl, c->nx = (int)nx, c->nz = (int)nz;
  c->lx = cv[0], c->lz = cv[1], c->half = cv[2], c->delta = cv[3], c->t_start = cv[4];
  c->window = cv[5];
  return 0;
}

/* The window records of group g into c (configured, rows reserved); nonzero on an error. */
static int read_windows(struct corr *c, int g, size_t rows) {
  const size_t nl = (size_t)c->cfg.n_levels, nzh = (size_t)c->nzh, n = rows * nl;
  const size_t nxh = (size_t)c->cfg.nx / 2 + 1;
  double *kx = mem_alloc(n * (nxh + nzh) * CS_LEN, sizeof(double), "chansph extract");
  double *kz = kx + n * nxh * CS_LEN;
  int vw, vs, vx, vz,
      bad = nc_inq_varid(g, "windows", &vw) || nc_inq_varid(g, "window_samples", &vs) ||
            nc_inq_varid(g, "window_spectra_kx", &vx) ||
            nc_inq_varid(g, "window_spectra_kz", &vz) || nc_get_var_double(g, vw, c->win) ||
            nc_get_var_double(g, vs, c->wsamp) || nc_get_var_double(g, vx, kx) ||
            nc_get_var_double(g, vz, kz);
  for (size_t i = 0; i < n && !bad; i++) { /* kx and kz parts -> [row][level][n1d][slot] */
    double *X = c->wspec + i * c->n1d * CS_LEN;
    memcpy(X, kx + i * nxh * CS_LEN, nxh * CS_LEN * sizeof(double));
    memcpy(X + nxh * CS_LEN, kz + i * nzh * CS_LEN, nzh * CS_LEN * sizeof(double));
  }
  free(kx);
  /* the mask sums (written since checkpoint format 1.15): a file without them stays
     uncorrected (its rows keep zero planes) */
  int vmx, vmz, vmp, vme;
  if (!bad && !nc_inq_varid(g, "window_mask_kx", &vmx) &&
      !nc_inq_varid(g, "window_mask_kz", &vmz) && !nc_inq_varid(g, "window_mask_planes", &vmp) &&
      !nc_inq_varid(g, "window_empty_cells", &vme)) {
    double *mx = mem_alloc(n * (nxh + nzh + 2), sizeof(double), "chansph extract");
    double *mz = mx + n * nxh, *mp = mz + n * nzh, *me = mp + n;
    bad = nc_get_var_double(g, vmx, mx) || nc_get_var_double(g, vmz, mz) ||
          nc_get_var_double(g, vmp, mp) || nc_get_var_double(g, vme, me);
    const size_t lm = c->n1d + CM_LEN;
    for (size_t i = 0; i < n && !bad; i++) {
      double *XM = c->wmask + i * lm;
      memcpy(XM, mx + i * nxh, nxh * sizeof(double));
      memcpy(XM + nxh, mz + i * nzh, nzh * sizeof(double));
      XM[c->n1d + CM_PLANES] = mp[i], XM[c->n1d + CM_EMPTY] = me[i];
    }
    free(mx);
  }
  return bad;
}

int corr_nc_read(struct corr *c, int ncid, char *err, size_t errlen) {
  struct corr_config cfg;
  int g, d, nwin = -1, rc;
  size_t rows = 0, fields = 0;
  memset(c, 0, sizeof *c);
  if (nc_inq_ncid(ncid, "correlations", &g) != NC_NOERR) {
    snprintf(err, errlen, "no group 'correlations'");
    return 1;
  }
  if ((rc = read_config(g, &cfg, err, errlen)) != 0) return rc;
  if (nc_inq_dimid(g, "window", &d) || nc_inq_dimlen(g, d, &rows) ||
      nc_inq_dimid(g, "window_field", &d) || nc_inq_dimlen(g, d, &fields) ||
      nc_get_att_int(g, NC_GLOBAL, "closed_windows", &nwin)) {
    snprintf(err, errlen, "group 'correlations' has no window records");
    return 2;
  }
  if (rows < 1 || fields != CW_LEN || nwin < 0 || (size_t)nwin > rows) {
    snprintf(err, errlen,
             "group 'correlations': %zu window records of %zu fields, %d closed: not this layout",
             rows, fields, nwin);
    return -1;
  }
  corr_init(c, &cfg);
  free(c->spec), free(c->samples), free(c->empty), free(c->mspec); /* 2-D sums: not in stats.nc */
  c->spec = c->samples = c->empty = c->mspec = NULL;
  corr_win_reserve(c, rows);
  c->rows = rows, c->nwin = (size_t)nwin;
  if (read_windows(c, g, rows)) {
    snprintf(err, errlen, "group 'correlations': cannot read the window records");
    corr_free(c);
    return -1;
  }
  return 0;
}

/* The engine's scene keys, section [correlations] (docs/scenes.md is generated from them). */
static const struct scene_key_def key_y_plus = {
    .section = "correlations",
    .name = "y_plus",
    .type = SCENE_LIST,
    .def = "",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .flags = SCENE_Y_PLUS,
    .unit = "-",
    .help =
        "Comma-separated y+ levels (up to 8) of the two-point correlations and 1-D spectra "
        "(thesis Eq. 5.57-5.59); each level and its mirror 2 delta - y are sampled. Empty = off."};
static const struct scene_key_def key_nx = {
    .section = "correlations",
    .name = "nx",
    .type = SCENE_INT,
    .def = "0",
    .lo = 0,
    .hi = 1e6,
    .unit = "-",
    .help = "Points of the plane grid along x (bin averages, Eq. 5.54-5.55); 0 = lx / dr."};
static const struct scene_key_def key_nz = {
    .section = "correlations",
    .name = "nz",
    .type = SCENE_INT,
    .def = "0",
    .lo = 0,
    .hi = 1e6,
    .unit = "-",
    .help = "Points of the plane grid along z; 0 = lz / dr (1 in 2-D)."};
static const struct scene_key_def key_thickness = {
    .section = "correlations",
    .name = "thickness",
    .type = SCENE_DOUBLE,
    .def = "1",
    .lo = 0,
    .hi = 100,
    .flags = SCENE_LO_OPEN,
    .unit = "dr",
    .help = "Thickness of the slab of particles binned onto each plane, in units of dr."};
static const struct scene_key_def *const keys[] = {&key_y_plus, &key_nx, &key_nz, &key_thickness};

/* The configuration from the scene; returns its number of levels (0: the engine does not run). */
static int config_of(const struct stats_scene *sc, struct corr_config *c) {
  memset(c, 0, sizeof *c);
  c->n_levels = stats_scene_levels(sc, &key_y_plus, c->y_plus, c->y, CORR_MAX_LEVELS);
  const int nx = stats_scene_int(sc, &key_nx);
  const int nz = stats_scene_int(sc, &key_nz);
  c->nx = nx > 0 ? nx : (int)floor(sc->lx / sc->dr + 0.5);
  c->nz = sc->dim == 2 ? 1 : nz > 0 ? nz : (int)floor(sc->lz / sc->dr + 0.5);
  c->lx = sc->lx, c->lz = sc->lz, c->delta = sc->delta, c->t_start = sc->t_average_start;
  c->window = sc->window;
  c->half = 0.5 * stats_scene_double(sc, &key_thickness) * sc->dr;
  return c->n_levels > 0 ? c->n_levels : 0;
}

/* The engine's table of operations (engine.h). */
static int engine_init_scene(void *self, const struct stats_scene *sc) {
  struct corr_config c;
  if (!config_of(sc, &c)) return 0;
  corr_init(self, &c);
  return 1;
}

/* Spectra per level, the FFTW grid and its transform (corr_init). */
static double engine_estimate(const struct stats_scene *sc) {
  struct corr_config c;
  if (!config_of(sc, &c)) return 0.0;
  const double nk = (double)c.nx * (c.nz / 2 + 1);
  return sizeof(double) *
         (c.n_levels * nk * (CS_LEN + 1) + 5.0 * c.nx * c.nz + 8.0 * nk); /* + mask */
}

STATS_ENGINE_ADAPTERS(corr)

static void engine_close(void *self, double t) {
  corr_win_close(self, t);
}

static size_t engine_bytes(const void *self) {
  const struct corr *c = self;
  const size_t d = sizeof(double);
  const size_t nk = (size_t)c->cfg.nx * (size_t)c->nzh, np = (size_t)c->cfg.nx * c->cfg.nz;
  return (size_t)c->cfg.n_levels * (nk * (CS_LEN + 1) + 2 + CM_LEN) * d + 5 * np * d +
         4 * nk * 2 * d + (c->ent_cap + c->all_cap) * CORR_ENT * d +
         c->hits_cap * (4 * d + sizeof(size_t)) +
         c->cap * (CW_LEN + (size_t)c->cfg.n_levels * (1 + c->n1d * (CS_LEN + 1) + CM_LEN)) * d;
}

static int engine_write(const void *self, double t_reached, int ncid, char *err, size_t errlen) {
  (void)t_reached;
  return corr_nc_write(self, ncid, err, errlen);
}

const struct stats_engine corr_engine = {.name = "two-point correlations",
                                         .keys = keys,
                                         .n_keys = sizeof keys / sizeof keys[0],
                                         .size = sizeof(struct corr),
                                         .init_scene = engine_init_scene,
                                         .estimate = engine_estimate,
                                         .init = engine_init,
                                         .free = engine_free,
                                         .sample = engine_sample,
                                         .close = engine_close,
                                         .state = engine_state,
                                         .bytes = engine_bytes,
                                         .write = engine_write,
                                         .warnings = NULL,
                                         .log = NULL};
