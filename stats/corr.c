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
  c->mspec =
      mem_calloc((size_t)cfg->n_levels * (nk + CM_LEN), sizeof(double), "correlation engine");
  c->grid = fftw_malloc(4 * (size_t)nx * (size_t)nz * sizeof(double));
  c->out = fftw_malloc(3 * nk * sizeof(fftw_complex));
  c->mgrid = fftw_malloc((size_t)nx * (size_t)nz * sizeof(double));
  c->mout = fftw_malloc(nk * sizeof(fftw_complex));
  if (!c->grid || !c->out || !c->mgrid || !c->mout)
    die("out of memory: correlation engine (FFTW arrays)");
  /* three transforms of nx x nz at once; FFTW_ESTIMATE chooses the plan without timing, so
     the same sizes give the same plan, and the same sums, on every run and restart */
  const int n[2] = {nx, nz};
  c->plan = fftw_plan_many_dft_r2c(2, n, 3, c->grid, NULL, 1, nx * nz, c->out, NULL, 1, (int)nk,
                                   FFTW_ESTIMATE);
  c->mplan = fftw_plan_dft_r2c_2d(nx, nz, c->mgrid, c->mout, FFTW_ESTIMATE); /* the mask */
  corr_win_init(c);
}

void corr_free(struct corr *c) {
  if (c->plan) fftw_destroy_plan(c->plan);
  if (c->mplan) fftw_destroy_plan(c->mplan);
  if (c->grid) fftw_free(c->grid);
  if (c->out) fftw_free(c->out);
  if (c->mgrid) fftw_free(c->mgrid);
  if (c->mout) fftw_free(c->mout);
  free(c->spec), free(c->samples), free(c->empty), free(c->hits), free(c->ent), free(c->all);
  free(c->mspec), free(c->win), free(c->wsamp), free(c->wspec), free(c->wmask);
  memset(c, 0, sizeof *c);
}

/* One particle of a slab: sort key (plane, local pencil, grid point), memory position, values. */
struct hit {
  uint64_t key;
  size_t a;
  double u, v, w;
};

/* Gathered entries in the order (pencil, plane and grid point): for each grid point the
   pencils' partials in global pencil order, on any decomposition. */
static int ent_cmp(const void *pa, const void *pb) {
  const double *x = pa, *y = pb;
  if (x[5] != y[5]) return x[5] < y[5] ? -1 : 1;
  return x[0] < y[0] ? -1 : x[0] > y[0];
}

static int hit_cmp(const void *pa, const void *pb) {
  const struct hit *x = pa, *y = pb;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->a < y->a ? -1 : x->a > y->a;
}

/* Bin the gathered partials of plane pl onto the grid in their order (pencil order for each
   grid point), remove the plane means, transform, and add the spectra to level
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
  for (size_t q = 0; q < np; q++) c->mgrid[q] = cnt[q] > 0 ? 1.0 : 0.0;
  fftw_execute(c->plan);
  fftw_execute(c->mplan);
  const size_t nk = (size_t)nx * (size_t)c->nzh;
  const fftw_complex *U = c->out, *V = U + nk, *W = V + nk, *M = c->mout;
  double *Sm = c->mspec + (size_t)l * (nk + CM_LEN);
  for (size_t k = 0; k < nk; k++) Sm[k] += M[k][0] * M[k][0] + M[k][1] * M[k][1];
  Sm[nk + CM_PLANES] += 1.0, Sm[nk + CM_EMPTY] += (double)np - filled;
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
  corr_win_add(c, l, (const double(*)[2])U, (const double(*)[2])V, (const double(*)[2])W,
               (const double(*)[2])M, (double)np - filled);
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
  const uint64_t nzl = s->nplane > 1 ? (uint64_t)(s->plane1 - s->plane0) : 1; /* local planes */
  const int plane0 = s->nplane > 1 ? s->plane0 : 0;
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
      const uint64_t lpen = (uint64_t)spar_lcol(&par, s, a) * nzl +
                            (uint64_t)(spar_plane(&par, s, a) - plane0); /* local pencil */
      h->key = ((uint64_t)pl * ncl * nzl + lpen) * np + q;
      h->a = a, h->u = s->u[a], h->v = mir[pl] ? -s->v[a] : s->v[a], h->w = s->w[a];
    }
  }
  struct hit *H = c->hits;
  if (nh) qsort(H, nh, sizeof *H, hit_cmp);
  /* 2. per-(plane, pencil, grid point) partial sums in that order: [plane np + q, sums of u v
     w, count, global pencil] */
  size_t ne = 0;
  for (size_t i = 0; i < nh;) {
    if (ne == c->ent_cap) {
      c->ent_cap = c->ent_cap ? 2 * c->ent_cap : 1024;
      c->ent = mem_realloc(c->ent, c->ent_cap * CORR_ENT, sizeof(double), "statistics engine");
    }
    double *e = c->ent + ne++ * CORR_ENT;
    const uint64_t key = H[i].key, pl = key / (ncl * nzl * np), q = key % np;
    const uint64_t lpen = key / np % (ncl * nzl);
    e[0] = (double)(pl * np + q), e[1] = e[2] = e[3] = e[4] = 0.0;
    e[5] = (double)((uint64_t)(par.col0 + (int)(lpen / nzl)) * (uint64_t)par.nplane +
                    (uint64_t)plane0 + lpen % nzl);
    for (; i < nh && H[i].key == key; i++)
      e[1] += H[i].u, e[2] += H[i].v, e[3] += H[i].w, e[4] += 1.0;
  }
  /* 3. every rank's partials on every rank, in pencil order */
  c->nall = spar_gather_var(&par, c->ent, ne, CORR_ENT, &c->all, &c->all_cap);
  spar_close(&par);
  if (c->nall) qsort(c->all, c->nall, CORR_ENT * sizeof(double), ent_cmp);
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
  /* optional (format 1.15): resumed without it, the mask sums cover only the planes after the
     resume, and the results stay uncorrected (corr.h, Gaps) */
  const size_t dm[2] = {d4[0], d4[1] * d4[2] + CM_LEN};
  struct state_field *f =
      state_add(L, "stats/correlations/mask_spectra", STATE_F64, 2, dm, c->mspec, NULL);
  f->optional = 1;
  corr_win_state(c, L);
}

/* Weight of a stored r2c coefficient (kz column iz) in sums over the full spectrum: its
   conjugate partner (-kx, -kz) is not stored unless kz = 0 or kz = nz/2 (nz even). */
static double weight(int iz, int nz) {
  return iz == 0 || (nz % 2 == 0 && iz == nz / 2) ? 1.0 : 2.0;
}

/* P(l) of level l from the 2-D mask sums through the c2r plan back (in, r its arrays): the
   fraction of filled cell pairs at l_x along x (l_z = 0) and at l_z along z; returns 1 if the
   level is to be corrected (its mask sums cover all its planes and it had empty cells). */
static int pair_fraction_2d(const struct corr *c, int l, fftw_plan back, fftw_complex *in,
                            double *r, double *px, double *pz) {
  const int nx = c->cfg.nx, nz = c->cfg.nz;
  const size_t nk = (size_t)nx * (size_t)c->nzh;
  const double *Sm = c->mspec + (size_t)l * (nk + CM_LEN), N = (double)nx * (double)nz;
  const double planes = Sm[nk + CM_PLANES];
  if (!(planes > 0) || planes != c->samples[l]) {
    for (int i = 0; i < nx; i++) px[i] = NAN;
    for (int k = 0; k < nz; k++) pz[k] = NAN;
    return 0;
  }
  for (size_t k = 0; k < nk; k++) in[k][0] = Sm[k], in[k][1] = 0.0;
  fftw_execute_dft_c2r(back, in, r);
  const double norm = 1.0 / (N * N * planes);
  for (int i = 0; i < nx; i++) px[i] = r[(size_t)i * nz] * norm;
  for (int k = 0; k < nz; k++) pz[k] = r[k] * norm;
  return Sm[nk + CM_EMPTY] > 0;
}

void corr_pair_fraction(const struct corr *c, double *px, double *pz, int *corrected) {
  const int nx = c->cfg.nx, nz = c->cfg.nz;
  const size_t nk = (size_t)nx * (size_t)c->nzh, np = (size_t)nx * (size_t)nz;
  fftw_complex *in = fftw_malloc(nk * sizeof(fftw_complex));
  double *r = fftw_malloc(np * sizeof(double));
  const int n[2] = {nx, nz};
  fftw_plan back = fftw_plan_dft_c2r(2, n, in, r, FFTW_ESTIMATE);
  for (int l = 0; l < c->cfg.n_levels; l++)
    corrected[l] = pair_fraction_2d(c, l, back, in, r, px + (size_t)l * nx, pz + (size_t)l * nz);
  fftw_destroy_plan(back);
  fftw_free(in), fftw_free(r);
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
  /* the gap correction (corr.h), the plan's arrays reused: every level's R is read out above */
  double *p = mem_alloc((size_t)(nx + nz), sizeof(double), "correlation engine");
  for (int l = 0; l < c->cfg.n_levels; l++)
    if (pair_fraction_2d(c, l, back, in, r, p, p + nx))
      corr_gap_correct(c, rx + (size_t)l * 4 * nx, rz + (size_t)l * 4 * nz,
                       ex + (size_t)l * 3 * nxh, ez + (size_t)l * 3 * nzh, p, p + nx);
  free(p);
  fftw_destroy_plan(back);
  fftw_free(in), fftw_free(r);
}
