/** @file corr.c @brief Implementation of corr.h. */
#include "corr.h"
#include "engine.h"
#include "ncutil.h"

#include <fftw3.h>
#include <math.h>
#include <netcdf.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "ncout.h"
#include "spar.h"
#include "state.h"

static const double two_pi = 6.283185307179586;

void corr_init(struct corr *c, const struct corr_config *cfg) {
  memset(c, 0, sizeof *c);
  c->cfg = *cfg;
  if (cfg->n_levels <= 0) return;
  const int nx = cfg->nx, nz = cfg->nz;
  c->nzh = nz / 2 + 1;
  const size_t nk = (size_t)nx * (size_t)c->nzh;
  c->spec = mem_calloc((size_t)cfg->n_levels * nk * CS_LEN, sizeof(double), "correlation engine");
  c->samples = mem_calloc((size_t)cfg->n_levels, sizeof(double), "correlation engine");
  c->empty = mem_calloc((size_t)cfg->n_levels, sizeof(double), "correlation engine");
  c->grid = fftw_malloc(4 * (size_t)nx * (size_t)nz * sizeof(double));
  c->out = fftw_malloc(3 * nk * sizeof(fftw_complex));
  if (!c->grid || !c->out) die("out of memory: correlation engine (FFTW arrays)");
  /* three transforms of nx x nz at once; FFTW_ESTIMATE chooses the plan without timing, so
     the same sizes give the same plan, and the same sums, on every run and restart */
  const int n[2] = {nx, nz};
  c->plan = fftw_plan_many_dft_r2c(2, n, 3, c->grid, NULL, 1, nx * nz, c->out, NULL, 1, (int)nk,
                                   FFTW_ESTIMATE);
  corr_win_init(c);
}

void corr_free(struct corr *c) {
  if (c->plan) fftw_destroy_plan(c->plan);
  if (c->grid) fftw_free(c->grid);
  if (c->out) fftw_free(c->out);
  free(c->spec), free(c->samples), free(c->empty), free(c->hits), free(c->ent), free(c->all);
  free(c->win), free(c->wsamp), free(c->wspec);
  memset(c, 0, sizeof *c);
}

/* One particle of a slab: sort key (plane, local column, grid point), memory position, values. */
struct hit {
  uint64_t key;
  size_t a;
  double u, v, w;
};

static int hit_cmp(const void *pa, const void *pb) {
  const struct hit *x = pa, *y = pb;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->a < y->a ? -1 : x->a > y->a;
}

/* Bin the gathered partials of plane pl onto the grid in the order they were gathered (column
   order for each grid point), remove the plane means, transform, and add the spectra to level
   l. Returns 0 if the slab holds no particle. */
static int add_plane(struct corr *c, int l, size_t pl, const double *E, size_t ne) {
  const int nx = c->cfg.nx, nz = c->cfg.nz;
  const size_t np = (size_t)nx * (size_t)nz;
  double *g = c->grid, *cnt = g + 3 * np;
  memset(g, 0, 4 * np * sizeof(double));
  const double k0 = (double)(pl * np), k1 = (double)((pl + 1) * np);
  size_t found = 0;
  for (size_t k = 0; k < ne; k++) {
    const double *e = E + k * CORR_ENT;
    if (e[0] < k0 || e[0] >= k1) continue;
    const size_t q = (size_t)(e[0] - k0);
    g[q] += e[1], g[np + q] += e[2], g[2 * np + q] += e[3], cnt[q] += e[4];
    found++;
  }
  if (!found) return 0;
  double mean[3] = {0, 0, 0}, filled = 0;
  for (size_t q = 0; q < np; q++)
    if (cnt[q] > 0)
      for (int k = 0; k < 3; k++) g[k * np + q] /= cnt[q];
  for (size_t q = 0; q < np; q++)
    if (cnt[q] > 0) {
      for (int k = 0; k < 3; k++) mean[k] += g[k * np + q];
      filled += 1;
    }
  for (int k = 0; k < 3; k++) mean[k] /= filled;
  for (size_t q = 0; q < np; q++) /* empty cells carry no fluctuation */
    for (int k = 0; k < 3; k++) g[k * np + q] = cnt[q] > 0 ? g[k * np + q] - mean[k] : 0.0;
  c->empty[l] += (double)np - filled;
  fftw_execute(c->plan);
  const size_t nk = (size_t)nx * (size_t)c->nzh;
  const fftw_complex *U = c->out, *V = U + nk, *W = V + nk;
  double *S = c->spec + (size_t)l * nk * CS_LEN;
  for (size_t k = 0; k < nk; k++) {
    double *sk = S + k * CS_LEN;
    sk[CS_UU] += U[k][0] * U[k][0] + U[k][1] * U[k][1];
    sk[CS_VV] += V[k][0] * V[k][0] + V[k][1] * V[k][1];
    sk[CS_WW] += W[k][0] * W[k][0] + W[k][1] * W[k][1];
    sk[CS_UV_RE] += U[k][0] * V[k][0] + U[k][1] * V[k][1]; /* conj(U) V */
    sk[CS_UV_IM] += U[k][0] * V[k][1] - U[k][1] * V[k][0];
  }
  c->samples[l] += 1.0;
  corr_win_add(c, l, (const double(*)[2])U, (const double(*)[2])V, (const double(*)[2])W);
  return 1;
}

void corr_sample(struct corr *c, const struct stats_snapshot *s) {
  if (c->cfg.n_levels <= 0 || s->t < c->cfg.t_start) return;
  const int nx = c->cfg.nx, nz = c->cfg.nz;
  const size_t np = (size_t)nx * (size_t)nz;
  const double sx = nx / c->cfg.lx, sz = nz > 1 ? nz / c->cfg.lz : 0.0;
  corr_win_advance(c, s->t); /* the window of this snapshot (the same on every rank) */
  /* the planes: each level, and its mirror (v -> -v) if the slabs do not overlap */
  int lev[2 * CORR_MAX_LEVELS], mir[2 * CORR_MAX_LEVELS];
  double yp[2 * CORR_MAX_LEVELS];
  size_t npl = 0;
  for (int l = 0; l < c->cfg.n_levels; l++) {
    const double yl = c->cfg.y[l], ym = 2.0 * c->cfg.delta - yl;
    lev[npl] = l, mir[npl] = 0, yp[npl++] = yl;
    if (fabs(ym - yl) >= 2.0 * c->cfg.half) lev[npl] = l, mir[npl] = 1, yp[npl++] = ym;
  }
  /* 1. this rank's slab particles, sorted by (plane, column, grid point), memory order within */
  struct spar par;
  spar_open(&par, s);
  const uint64_t ncl = (uint64_t)(par.col1 - par.col0);
  size_t nh = 0;
  for (size_t a = 0; a < s->n; a++) {
    if (s->skip && s->skip[a]) continue;
    for (size_t pl = 0; pl < npl; pl++) {
      if (fabs(s->y[a] - yp[pl]) >= c->cfg.half) continue;
      long ix = (long)floor(s->x[a] * sx) % nx, iz = nz > 1 ? (long)floor(s->z[a] * sz) % nz : 0;
      ix += ix < 0 ? nx : 0, iz += iz < 0 ? nz : 0;
      const size_t q = (size_t)ix * (size_t)nz + (size_t)iz;
      if (nh == c->hits_cap) {
        c->hits_cap = c->hits_cap ? 2 * c->hits_cap : 1024;
        c->hits = mem_realloc(c->hits, c->hits_cap, sizeof(struct hit), "statistics engine");
      }
      struct hit *h = (struct hit *)c->hits + nh++;
      h->key = ((uint64_t)pl * ncl + (uint64_t)spar_lcol(&par, s, a)) * np + q;
      h->a = a, h->u = s->u[a], h->v = mir[pl] ? -s->v[a] : s->v[a], h->w = s->w[a];
    }
  }
  struct hit *H = c->hits;
  if (nh) qsort(H, nh, sizeof *H, hit_cmp);
  /* 2. per-(plane, column, grid point) partial sums in that order: [plane np + q, sums of u v
     w, count] */
  size_t ne = 0;
  for (size_t i = 0; i < nh;) {
    if (ne == c->ent_cap) {
      c->ent_cap = c->ent_cap ? 2 * c->ent_cap : 1024;
      c->ent = mem_realloc(c->ent, c->ent_cap * CORR_ENT, sizeof(double), "statistics engine");
    }
    double *e = c->ent + ne++ * CORR_ENT;
    const uint64_t key = H[i].key, pl = key / (ncl * np), q = key % np;
    e[0] = (double)(pl * np + q), e[1] = e[2] = e[3] = e[4] = 0.0;
    for (; i < nh && H[i].key == key; i++)
      e[1] += H[i].u, e[2] += H[i].v, e[3] += H[i].w, e[4] += 1.0;
  }
  /* 3. every rank's partials on every rank, in rank (= column) order */
  c->nall = spar_gather_var(&par, c->ent, ne, CORR_ENT, &c->all, &c->all_cap);
  spar_close(&par);
  /* 4. the planes, identical on every rank */
  for (size_t pl = 0; pl < npl; pl++) add_plane(c, lev[pl], pl, c->all, c->nall);
}

void corr_state(struct corr *c, struct state_list *L) {
  if (c->cfg.n_levels <= 0) return;
  const size_t d4[4] = {(size_t)c->cfg.n_levels, (size_t)c->cfg.nx, (size_t)c->nzh, CS_LEN};
  const size_t dims3[3] = {d4[0], d4[1] * d4[2], CS_LEN}, d1[1] = {d4[0]};
  state_add(L, "stats/correlations/spectra", STATE_F64, 3, dims3, c->spec, NULL);
  state_add(L, "stats/correlations/samples", STATE_F64, 1, d1, c->samples, NULL);
  state_add(L, "stats/correlations/empty_cells", STATE_F64, 1, d1, c->empty, NULL);
  corr_win_state(c, L);
}

/* Weight of a stored r2c coefficient (kz column iz) in sums over the full spectrum: its
   conjugate partner (-kx, -kz) is not stored unless kz = 0 or kz = nz/2 (nz even). */
static double weight(int iz, int nz) {
  return iz == 0 || (nz % 2 == 0 && iz == nz / 2) ? 1.0 : 2.0;
}

void corr_results(const struct corr *c, double *rx, double *rz, double *ex, double *ez) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const size_t nk = (size_t)nx * (size_t)nzh, np = (size_t)nx * (size_t)nz;
  const double N = (double)np;
  fftw_complex *in = fftw_malloc(nk * sizeof(fftw_complex));
  double *r = fftw_malloc(np * sizeof(double));
  const int n[2] = {nx, nz};
  fftw_plan back = fftw_plan_dft_c2r(2, n, in, r, FFTW_ESTIMATE);
  for (int l = 0; l < c->cfg.n_levels; l++) {
    const double *S = c->spec + (size_t)l * nk * CS_LEN;
    const double ns = c->samples[l] > 0 ? c->samples[l] : NAN;
    const double norm = 1.0 / (N * N * ns);
    static const int slot_re[4] = {CS_UU, CS_VV, CS_WW, CS_UV_RE};
    for (int q = 0; q < 4; q++) {
      for (size_t k = 0; k < nk; k++) {
        in[k][0] = S[k * CS_LEN + slot_re[q]];
        in[k][1] = q == 3 ? S[k * CS_LEN + CS_UV_IM] : 0.0;
      }
      fftw_execute(back); /* r(l) = sum_k S_k e^{i k l} = N sum_r u(r) u(r + l) */
      for (int i = 0; i < nx; i++) rx[((size_t)l * 4 + q) * nx + i] = r[(size_t)i * nz] * norm;
      for (int k = 0; k < nz; k++) rz[((size_t)l * 4 + q) * nz + k] = r[k] * norm;
    }
    for (int q = 0; q < 3; q++) {
      double *Ex = ex + ((size_t)l * 3 + q) * nxh, *Ez = ez + ((size_t)l * 3 + q) * nzh;
      memset(Ex, 0, (size_t)nxh * sizeof(double));
      memset(Ez, 0, (size_t)nzh * sizeof(double));
      for (int i = 0; i < nx; i++)
        for (int k = 0; k < nzh; k++) {
          const double phi = weight(k, nz) * S[((size_t)i * nzh + k) * CS_LEN + q] * norm;
          Ex[i <= nx - i ? i : nx - i] += phi;
          Ez[k] += phi;
        }
      /* densities over k = 2 pi m / L: sum_m E(k_m) dk = <u_i'^2> */
      for (int m = 0; m < nxh; m++) Ex[m] *= c->cfg.lx / two_pi;
      for (int m = 0; m < nzh; m++) Ez[m] *= nz > 1 ? c->cfg.lz / two_pi : 1.0;
    }
  }
  fftw_destroy_plan(back);
  fftw_free(in), fftw_free(r);
}

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

/* One [level][comp][n] array of standard errors as variable name (level, dim). */
static int put_stderr(int g, const char *name, const char *of, int dl, int dim, const char *units,
                      const double *a, int ncomp, int q, int nl, int n) {
  char ln[160];
  int v, rc = NC_NOERR;
  snprintf(ln, sizeof ln, "standard error (batch means over the complete windows) of %s", of);
  const int d2[2] = {dl, dim};
  if ((rc = ncout_def(g, name, NC_DOUBLE, 2, d2, units, ln, &v)) != NC_NOERR ||
      (rc = ncout_fill(g, v)) != NC_NOERR)
    return rc;
  for (int l = 0; l < nl && rc == NC_NOERR; l++) {
    const size_t st[2] = {(size_t)l, 0}, ct[2] = {1, (size_t)n};
    rc = ncout_put_filled(g, v, st, ct, a + ((size_t)l * ncomp + q) * n, (size_t)n);
  }
  return rc;
}

/* The batch-means standard errors of R and E (corr_stderr) and the batches per level.
   d: {level, separation_x, separation_z, kx, kz}. */
static int write_stderr(const struct corr *c, int g, const int d[5], char *err, size_t errlen) {
  const int nl = c->cfg.n_levels, nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh;
  const int nxh = nx / 2 + 1;
  double *rx = mem_alloc(1, (size_t)nl * 4 * nx * sizeof(double), "correlations");
  double *rz = mem_alloc(1, (size_t)nl * 4 * nz * sizeof(double), "correlations");
  double *ex = mem_alloc(1, (size_t)nl * 3 * nxh * sizeof(double), "correlations");
  double *ez = mem_alloc(1, (size_t)nl * 3 * nzh * sizeof(double), "correlations");
  int *nb = mem_alloc(1, (size_t)nl * sizeof(int), "correlations");
  int rc = NC_NOERR, v;
  corr_stderr(c, rx, rz, ex, ez, nb);
  CK(ncout_def(g, "n_batches", NC_INT, 1, &d[0], "1",
               "complete windows with planes at the level: the batches of the *_stderr", &v));
  CK(nc_put_var_int(g, v, nb));
  static const char *const comp[4] = {"uu", "vv", "ww", "uv"};
  for (int q = 0; q < 4; q++)
    for (int dir = 0; dir < 2; dir++) {
      char name[64], of[32];
      snprintf(of, sizeof of, "R_%s_%c", comp[q], dir ? 'z' : 'x');
      snprintf(name, sizeof name, "%s_stderr", of);
      CK(put_stderr(g, name, of, d[0], d[1 + dir], "m^2/s^2", dir ? rz : rx, 4, q, nl,
                    dir ? nz : nx));
      if (q == 3) continue;
      snprintf(of, sizeof of, "E_%s_k%c", comp[q], dir ? 'z' : 'x');
      snprintf(name, sizeof name, "%s_stderr", of);
      CK(put_stderr(g, name, of, d[0], d[3 + dir], "m^3/s^2", dir ? ez : ex, 3, q, nl,
                    dir ? nzh : nxh));
    }
done:
  free(rx), free(rz), free(ex), free(ez), free(nb);
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
  int rc = NC_NOERR, g, dl, dx, dz, dkx, dkz, dkk, dsl, v;
  corr_results(c, rx, rz, ex, ez);
  CK(nc_def_grp(ncid, "correlations", &g));
  static const char desc[] =
      "two-point correlations and 1-D spectra in wall-parallel planes (thesis Eq. "
      "5.57-5.59); a level and its mirror 2 delta - y (v -> -v) are both sampled";
  CK(nc_put_att_text(g, NC_GLOBAL, "description", strlen(desc), desc));
  CK(nc_def_dim(g, "level", (size_t)nl, &dl));
  CK(nc_def_dim(g, "separation_x", (size_t)nx, &dx));
  CK(nc_def_dim(g, "separation_z", (size_t)nz, &dz));
  CK(nc_def_dim(g, "kx", (size_t)nxh, &dkx));
  CK(nc_def_dim(g, "kz", (size_t)nzh, &dkz));
  CK(nc_def_dim(g, "k_index", (size_t)nx * (size_t)nzh, &dkk));
  CK(nc_def_dim(g, "spectrum_slot", CS_LEN, &dsl));
  CK(ncout_def(g, "level", NC_DOUBLE, 1, &dl, "m", "height of the plane above the lower wall", &v));
  CK(nc_put_var_double(g, v, c->cfg.y));
  CK(ncout_def(g, "y_plus", NC_DOUBLE, 1, &dl, "1", "level in wall units of stats.u_tau_ref", &v));
  CK(nc_put_var_double(g, v, c->cfg.y_plus));
  CK(ncout_def(g, "samples", NC_DOUBLE, 1, &dl, "1", "planes accumulated", &v));
  CK(nc_put_var_double(g, v, c->samples));
  CK(ncout_def(g, "empty_cells", NC_DOUBLE, 1, &dl, "1",
               "grid cells without a particle, summed over the planes (set to zero fluctuation)",
               &v));
  CK(nc_put_var_double(g, v, c->empty));
  {
    const int da[5] = {dx, dz, dkx, dkz, dkk}, dc[4] = {dl, dx, dz, dsl}, ds[3] = {dl, dkx, dkz};
    /* each names its own failing call in err */
    if ((rc = write_axes(c, g, da, tmp, err, errlen)) != NC_NOERR ||
        (rc = write_correlations(c, g, dc, rx, rz, tmp, err, errlen)) != NC_NOERR ||
        (rc = write_spectra(c, g, ds, ex, ez, err, errlen)) != NC_NOERR)
      goto done;
    const int de[5] = {dl, dx, dz, dkx, dkz};
    if ((rc = write_stderr(c, g, de, err, errlen)) != NC_NOERR) goto done;
  }
  {
    const int d3[3] = {dl, dkk, dsl};
    CK(ncout_def(g, "spectra", NC_DOUBLE, 3, d3, "m^2/s^2",
                 "raw sums over the planes of conj(F u_i) F u_j on the r2c grid [kx][kz]: uu, "
                 "vv, ww, Re uv, Im uv (unnormalised FFTW transforms of nx x nz)",
                 &v));
    static const char coords[] = "k_index_kx k_index_kz";
    CK(nc_put_att_text(g, v, "coordinates", strlen(coords), coords));
    CK(nc_put_var_double(g, v, c->spec));
  }
done:
  free(rx), free(rz), free(ex), free(ez), free(tmp);
  return rc;
}

/* The configuration from the scene; returns its number of levels (0: the engine does not run). */
static int config_of(const struct stats_scene *sc, struct corr_config *c) {
  memset(c, 0, sizeof *c);
  c->n_levels = stats_scene_levels(sc, "correlations.y_plus", c->y_plus, c->y, CORR_MAX_LEVELS);
  const int nx = (int)stats_scene_num(sc, "correlations.nx");
  const int nz = (int)stats_scene_num(sc, "correlations.nz");
  c->nx = nx > 0 ? nx : (int)floor(sc->lx / sc->dr + 0.5);
  c->nz = sc->dim == 2 ? 1 : nz > 0 ? nz : (int)floor(sc->lz / sc->dr + 0.5);
  c->lx = sc->lx, c->lz = sc->lz, c->delta = sc->delta, c->t_start = sc->t_average_start;
  c->window = stats_scene_window(sc);
  c->half = 0.5 * stats_scene_num(sc, "correlations.thickness") * sc->dr;
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
  return sizeof(double) * (c.n_levels * nk * CS_LEN + 4.0 * c.nx * c.nz + 6.0 * nk);
}

static void engine_init(void *self, const void *cfg) {
  corr_init(self, cfg);
}

static void engine_free(void *self) {
  corr_free(self);
}

static void engine_sample(void *self, const struct stats_snapshot *s) {
  corr_sample(self, s);
}

static void engine_state(void *self, struct state_list *L) {
  corr_state(self, L);
}

static size_t engine_bytes(const void *self) {
  const struct corr *c = self;
  const size_t d = sizeof(double);
  const size_t nk = (size_t)c->cfg.nx * (size_t)c->nzh, np = (size_t)c->cfg.nx * c->cfg.nz;
  return (size_t)c->cfg.n_levels * (nk * CS_LEN + 2) * d + 4 * np * d + 3 * nk * 2 * d +
         (c->ent_cap + c->all_cap) * CORR_ENT * d + c->hits_cap * (4 * d + sizeof(size_t)) +
         c->cap * (CW_LEN + (size_t)c->cfg.n_levels * (1 + c->n1d * CS_LEN)) * d;
}

static int engine_write(const void *self, double t_reached, int ncid, char *err, size_t errlen) {
  (void)t_reached;
  return corr_nc_write(self, ncid, err, errlen);
}

const struct stats_engine corr_engine = {.name = "two-point correlations",
                                         .size = sizeof(struct corr),
                                         .init_scene = engine_init_scene,
                                         .estimate = engine_estimate,
                                         .init = engine_init,
                                         .free = engine_free,
                                         .sample = engine_sample,
                                         .state = engine_state,
                                         .bytes = engine_bytes,
                                         .write = engine_write,
                                         .warnings = NULL,
                                         .log = NULL};
