/** @file corr_win.c @brief The per-window records of the correlation engine (corr.h): 1-D sums
 *         of the spectra per averaging window, their checkpoint fields and the batch-means
 *         standard errors of E(k_x), E(k_z), R(l_x), R(l_z) (issue 25). */
#include "corr.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "state.h"

static const double two_pi = 6.283185307179586;

void corr_win_reserve(struct corr *c, size_t rows) {
  if (rows <= c->cap) return;
  const size_t old = c->cap, cap = rows > 2 * old ? rows : 2 * old;
  const size_t nl = (size_t)c->cfg.n_levels, ns = nl * c->n1d * CS_LEN;
  const size_t nm = nl * (c->n1d + CM_LEN);
  c->win = mem_realloc(c->win, cap * CW_LEN, sizeof(double), "correlation engine");
  c->wsamp = mem_realloc(c->wsamp, cap * nl, sizeof(double), "correlation engine");
  c->wspec = mem_realloc(c->wspec, cap * ns, sizeof(double), "correlation engine");
  c->wmask = mem_realloc(c->wmask, cap * nm, sizeof(double), "correlation engine");
  memset(c->win + old * CW_LEN, 0, (cap - old) * CW_LEN * sizeof(double));
  memset(c->wsamp + old * nl, 0, (cap - old) * nl * sizeof(double));
  memset(c->wspec + old * ns, 0, (cap - old) * ns * sizeof(double));
  memset(c->wmask + old * nm, 0, (cap - old) * nm * sizeof(double));
  c->cap = cap;
}

void corr_win_init(struct corr *c) {
  c->n1d = (size_t)(c->cfg.nx / 2 + 1) + (size_t)c->nzh;
  if (!(c->cfg.window > 0.0)) c->cfg.window = INFINITY; /* one window, never closed */
  corr_win_reserve(c, 1);
  c->win[CW_T0] = c->cfg.t_start, c->win[CW_T1] = c->cfg.t_start + c->cfg.window;
}

/* Same rule as the PDF engine (pdf.c): a window with snapshots is closed and the next one
   opened at its end; an empty one just moves by one window length. */
void corr_win_close(struct corr *c, double t) {
  if (c->cfg.n_levels <= 0 || t < c->cfg.t_start) return;
  while (t >= c->win[c->nwin * CW_LEN + CW_T1]) {
    const double t1 = c->win[c->nwin * CW_LEN + CW_T1];
    if (c->win[c->nwin * CW_LEN + CW_NSNAP] > 0.0) corr_win_reserve(c, ++c->nwin + 1);
    double *o = c->win + c->nwin * CW_LEN;
    o[CW_T0] = t1, o[CW_T1] = t1 + c->cfg.window;
  }
}

void corr_win_advance(struct corr *c, double t) {
  /* whole-run sums but no window records: resumed from a checkpoint of format 1.7 or older,
     whose windows are unknown; the window of the resume holds only part of its snapshots */
  double run = 0.0;
  for (int l = 0; l < c->cfg.n_levels; l++) run += c->samples[l];
  const int legacy = c->nwin == 0 && c->win[CW_NSNAP] == 0.0 && run > 0.0;
  corr_win_close(c, t);
  double *o = c->win + c->nwin * CW_LEN;
  if (legacy) o[CW_PARTIAL] = 1.0;
  o[CW_NSNAP] += 1.0;
}

/* Weight of a stored r2c column iz in sums over the full spectrum (corr.c: weight). */
static int self_conjugate(int iz, int nz) {
  return iz == 0 || (nz % 2 == 0 && iz == nz / 2);
}

void corr_win_add(struct corr *c, int l, const double (*U)[2], const double (*V)[2],
                  const double (*W)[2], const double (*M)[2], double empty) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const size_t nl = (size_t)c->cfg.n_levels, row = c->nwin;
  double *X = c->wspec + ((row * nl + (size_t)l) * c->n1d) * CS_LEN;
  double *Z = X + (size_t)nxh * CS_LEN;
  double *XM = c->wmask + (row * nl + (size_t)l) * (c->n1d + CM_LEN), *ZM = XM + nxh;
  for (int ix = 0; ix < nx; ix++)
    for (int iz = 0; iz < nzh; iz++) {
      const size_t k = (size_t)ix * (size_t)nzh + (size_t)iz;
      const double s[CS_LEN] = {
          U[k][0] * U[k][0] + U[k][1] * U[k][1], V[k][0] * V[k][0] + V[k][1] * V[k][1],
          W[k][0] * W[k][0] + W[k][1] * W[k][1], U[k][0] * V[k][0] + U[k][1] * V[k][1],
          U[k][0] * V[k][1] - U[k][1] * V[k][0]};
      const double sm = M[k][0] * M[k][0] + M[k][1] * M[k][1];
      double *z = Z + (size_t)iz * CS_LEN;
      for (int q = 0; q < CS_LEN; q++) z[q] += s[q];
      ZM[iz] += sm;
      if (ix < nxh) {
        for (int q = 0; q < CS_LEN; q++) X[(size_t)ix * CS_LEN + q] += s[q];
        XM[ix] += sm;
      }
      /* the partner (-kx, -kz) of a column that is not self-conjugate: conj(S) at -kx */
      const int p = (nx - ix) % nx;
      if (!self_conjugate(iz, nz) && p < nxh) {
        for (int q = 0; q < CS_LEN; q++) X[(size_t)p * CS_LEN + q] += q == CS_UV_IM ? -s[q] : s[q];
        XM[p] += sm;
      }
    }
  XM[c->n1d + CM_PLANES] += 1.0, XM[c->n1d + CM_EMPTY] += empty;
  c->wsamp[row * nl + (size_t)l] += 1.0;
}

/* Checkpoint reading: make room for the stored rows (the open window is the last). */
static void *reserve_rows(struct corr *c, int rank, const size_t *dims, size_t len, double **a) {
  if (rank < 2 || dims[0] < 1 || dims[rank - 1] != len) return NULL;
  corr_win_reserve(c, dims[0]);
  c->nwin = dims[0] - 1;
  return *a;
}

static void *reserve_win(void *owner, int rank, const size_t *dims) {
  struct corr *c = owner;
  return rank == 2 ? reserve_rows(c, rank, dims, CW_LEN, &c->win) : NULL;
}

static void *reserve_samp(void *owner, int rank, const size_t *dims) {
  struct corr *c = owner;
  return rank == 2 ? reserve_rows(c, rank, dims, (size_t)c->cfg.n_levels, &c->wsamp) : NULL;
}

static void *reserve_spec(void *owner, int rank, const size_t *dims) {
  struct corr *c = owner;
  if (rank != 3 || dims[1] != (size_t)c->cfg.n_levels * c->n1d) return NULL;
  return reserve_rows(c, rank, dims, CS_LEN, &c->wspec);
}

static void *reserve_mask(void *owner, int rank, const size_t *dims) {
  struct corr *c = owner;
  if (rank != 3 || dims[1] != (size_t)c->cfg.n_levels) return NULL;
  return reserve_rows(c, rank, dims, c->n1d + CM_LEN, &c->wmask);
}

void corr_win_state(struct corr *c, struct state_list *L) {
  const size_t rows = c->nwin + 1, nl = (size_t)c->cfg.n_levels;
  const size_t dw[2] = {rows, CW_LEN}, ds[2] = {rows, nl}, dp[3] = {rows, nl * c->n1d, CS_LEN};
  const size_t dm[3] = {rows, nl, c->n1d + CM_LEN};
  /* optional (format 1.8): a checkpoint of 1.7 or older resumes without them (corr_win_advance) */
  struct state_field *f =
      state_add(L, "stats/correlations/windows", STATE_F64, 2, dw, c->win, NULL);
  f->reserve = reserve_win, f->owner = c, f->optional = 1;
  f = state_add(L, "stats/correlations/window_samples", STATE_F64, 2, ds, c->wsamp, NULL);
  f->reserve = reserve_samp, f->owner = c, f->optional = 1;
  f = state_add(L, "stats/correlations/window_spectra_1d", STATE_F64, 3, dp, c->wspec, NULL);
  f->reserve = reserve_spec, f->owner = c, f->optional = 1;
  /* optional (format 1.15): without it the windows before the resume have no mask sums and
     stay uncorrected (corr.h, Gaps) */
  f = state_add(L, "stats/correlations/window_mask_1d", STATE_F64, 3, dm, c->wmask, NULL);
  f->reserve = reserve_mask, f->owner = c, f->optional = 1;
}

size_t corr_nv(const struct corr *c) {
  const size_t nx = (size_t)c->cfg.nx, nz = (size_t)c->cfg.nz;
  return 8 * nx + 8 * nz + 3 * (nx / 2 + 1) + 3 * (size_t)c->nzh;
}

/* rho along x and z from R (the v layout of corr_nv): each R over its own R(0) at l = 0, R_uv
   over R_uu(0), as the writer does for the whole run. */
static void rho_of(const struct corr *c, double *v) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const double *rx = v, *rz = rx + 4 * nx;
  double *px = v + 4 * nx + 4 * nz + 3 * nxh + 3 * nzh, *pz = px + 4 * nx;
  for (int q = 0; q < 4; q++) {
    const int q0 = q == 3 ? 0 : q;
    for (int i = 0; i < nx; i++) px[q * nx + i] = rx[q * nx + i] / rx[q0 * nx];
    for (int k = 0; k < nz; k++) pz[q * nz + k] = rz[q * nz + k] / rz[q0 * nz];
  }
}

/* One-sided density of an even series R(l_i), i < n, over k = 2 pi m / L (corr_results'
   normalisation: sum_m E(k_m) dk = R(0)): f_m (1/n) sum_i R_i cos(2 pi m i / n) L / (2 pi). */
static void cosine_density(const double *R, int n, double L, double *E) {
  for (int m = 0; m < n / 2 + 1; m++) {
    double s = 0.0;
    for (int i = 0; i < n; i++) s += R[i] * cos(two_pi * (double)(((long)m * i) % n) / n);
    const double f = m == 0 || 2 * m == n ? 1.0 : 2.0;
    E[m] = f * s / n * (n > 1 ? L / two_pi : 1.0);
  }
}

void corr_gap_correct(const struct corr *c, double *rx, double *rz, double *ex, double *ez,
                      const double *px, const double *pz) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  for (int q = 0; q < 4; q++) {
    for (int i = 0; i < nx; i++) rx[q * nx + i] = px[i] > 0 ? rx[q * nx + i] / px[i] : NAN;
    for (int k = 0; k < nz; k++) rz[q * nz + k] = pz[k] > 0 ? rz[q * nz + k] / pz[k] : NAN;
  }
  for (int q = 0; q < 3; q++) {
    cosine_density(rx + q * nx, nx, c->cfg.lx, ex + q * nxh);
    cosine_density(rz + q * nz, nz, c->cfg.lz, ez + q * nzh);
  }
}

/* P(l) along x and z of one level's 1-D mask sums XM (k_x entries, then k_z, then CM_LEN) into
   px [nx], pz [nz]; returns 1 if they cover all ns planes and some cell was empty (the results
   are then corrected), else 0 with NaN. */
static int pair_fraction_1d(const struct corr *c, const double *XM, double ns, double *px,
                            double *pz) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const double planes = XM[c->n1d + CM_PLANES], N = (double)nx * (double)nz;
  if (!(planes > 0) || planes != ns) {
    for (int i = 0; i < nx; i++) px[i] = NAN;
    for (int k = 0; k < nz; k++) pz[k] = NAN;
    return 0;
  }
  const double norm = 1.0 / (N * N * planes), *ZM = XM + nxh;
  for (int i = 0; i < nx; i++) {
    double s = 0.0;
    for (int m = 0; m < nxh; m++)
      s += (m == 0 || 2 * m == nx ? 1.0 : 2.0) * XM[m] * cos(two_pi * (double)((m * i) % nx) / nx);
    px[i] = s * norm;
  }
  for (int k = 0; k < nz; k++) {
    double s = 0.0;
    for (int m = 0; m < nzh; m++)
      s += (self_conjugate(m, nz) ? 1.0 : 2.0) * ZM[m] * cos(two_pi * (double)((m * k) % nz) / nz);
    pz[k] = s * norm;
  }
  return XM[c->n1d + CM_EMPTY] > 0;
}

/* The results of one level's 1-D sums X (k_x entries, then k_z) of ns planes into v (the
   layout of corr_nv), gap-corrected by its mask sums XM where they allow it and allow is set. */
static void values_of(const struct corr *c, const double *X, double ns, const double *XM, int allow,
                      double *v) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const double N = (double)nx * (double)nz;
  const double norm = 1.0 / (N * N * ns);
  const double *Z = X + (size_t)nxh * CS_LEN;
  double *rx = v, *rz = rx + 4 * nx, *ex = rz + 4 * nz, *ez = ex + 3 * nxh;
  static const int slot_re[4] = {CS_UU, CS_VV, CS_WW, CS_UV_RE};
  for (int q = 0; q < 4; q++) {
    for (int i = 0; i < nx; i++) { /* R(l_x) = sum over the full k_x of Sx e^{i k l} */
      double s = 0.0;
      for (int m = 0; m < nxh; m++) {
        const double f = m == 0 || 2 * m == nx ? 1.0 : 2.0;
        const double th = two_pi * (double)((m * i) % nx) / nx;
        const double im = q == 3 ? X[(size_t)m * CS_LEN + CS_UV_IM] : 0.0;
        s += f * (X[(size_t)m * CS_LEN + slot_re[q]] * cos(th) - im * sin(th));
      }
      rx[q * nx + i] = s * norm;
    }
    for (int k = 0; k < nz; k++) {
      double s = 0.0;
      for (int m = 0; m < nzh; m++) {
        const double f = self_conjugate(m, nz) ? 1.0 : 2.0;
        const double th = two_pi * (double)((m * k) % nz) / nz;
        const double im = q == 3 ? Z[(size_t)m * CS_LEN + CS_UV_IM] : 0.0;
        s += f * (Z[(size_t)m * CS_LEN + slot_re[q]] * cos(th) - im * sin(th));
      }
      rz[q * nz + k] = s * norm;
    }
  }
  for (int q = 0; q < 3; q++) { /* densities over k = 2 pi m / L (corr_results) */
    for (int m = 0; m < nxh; m++)
      ex[q * nxh + m] = (m == 0 || 2 * m == nx ? 1.0 : 2.0) * X[(size_t)m * CS_LEN + q] * norm *
                        c->cfg.lx / two_pi;
    for (int m = 0; m < nzh; m++)
      ez[q * nzh + m] = (self_conjugate(m, nz) ? 1.0 : 2.0) * Z[(size_t)m * CS_LEN + q] * norm *
                        (nz > 1 ? c->cfg.lz / two_pi : 1.0);
  }
  double *p = mem_alloc((size_t)(nx + nz), sizeof(double), "correlations");
  if (allow && pair_fraction_1d(c, XM, ns, p, p + nx))
    corr_gap_correct(c, rx, rz, ex, ez, p, p + nx);
  free(p);
  rho_of(c, v);
}

/* Row r's own results at level l into v, gap-corrected only if allow (the range's results
   are: a batch is then of the same estimator as the mean it scatters about). */
static void window_values(const struct corr *c, size_t r, size_t l, int allow, double *v) {
  const size_t nl = (size_t)c->cfg.n_levels;
  values_of(c, c->wspec + ((r * nl + l) * c->n1d) * CS_LEN, c->wsamp[r * nl + l],
            c->wmask + (r * nl + l) * (c->n1d + CM_LEN), allow, v);
}

/* The window rows r0 .. r1-1 of level l: their 1-D mask sums added in row order into sum. */
static void mask_sum(const struct corr *c, size_t r0, size_t r1, size_t l, double *sum) {
  const size_t nl = (size_t)c->cfg.n_levels, len = c->n1d + CM_LEN;
  memset(sum, 0, len * sizeof(double));
  for (size_t r = r0; r < r1; r++)
    for (size_t j = 0; j < len; j++) sum[j] += c->wmask[(r * nl + l) * len + j];
}

void corr_range_pair_fraction(const struct corr *c, size_t r0, size_t r1, double *px, double *pz,
                              int *corrected) {
  const size_t nl = (size_t)c->cfg.n_levels, nx = (size_t)c->cfg.nx, nz = (size_t)c->cfg.nz;
  double *sum = mem_alloc(c->n1d + CM_LEN, sizeof(double), "correlations");
  for (size_t l = 0; l < nl; l++) {
    double ns = 0.0;
    for (size_t r = r0; r < r1; r++) ns += c->wsamp[r * nl + l];
    mask_sum(c, r0, r1, l, sum);
    corrected[l] = pair_fraction_1d(c, sum, ns, px + l * nx, pz + l * nz);
  }
  free(sum);
}

void corr_range_values(const struct corr *c, size_t r0, size_t r1, double *v) {
  const size_t nl = (size_t)c->cfg.n_levels, len = c->n1d * CS_LEN, nv = corr_nv(c);
  double *sum = mem_alloc(len + c->n1d + CM_LEN, sizeof(double), "correlations");
  for (size_t l = 0; l < nl; l++) {
    double ns = 0.0;
    memset(sum, 0, len * sizeof(double));
    for (size_t r = r0; r < r1; r++) { /* row order: the same sums on every rank and rerun */
      const double *X = c->wspec + (r * nl + l) * len;
      for (size_t j = 0; j < len; j++) sum[j] += X[j];
      ns += c->wsamp[r * nl + l];
    }
    mask_sum(c, r0, r1, l, sum + len);
    values_of(c, sum, ns > 0 ? ns : NAN, sum + len, 1, v + l * nv);
  }
  free(sum);
}

/* The batches of level l: complete windows (closed, not partial) with planes at the level. */
static int is_batch(const struct corr *c, size_t r, size_t l) {
  return r < c->nwin && c->win[r * CW_LEN + CW_PARTIAL] == 0.0 &&
         c->wsamp[r * (size_t)c->cfg.n_levels + l] > 0.0;
}

void corr_range_stderr(const struct corr *c, size_t r0, size_t r1, double *se, int *nb) {
  const size_t nv = corr_nv(c), nl = (size_t)c->cfg.n_levels;
  const size_t nx = (size_t)c->cfg.nx, nz = (size_t)c->cfg.nz;
  double *v = mem_alloc(2 * nv, sizeof(double), "correlations"), *mean = v + nv;
  double *p = mem_alloc(nl * (nx + nz), sizeof(double), "correlations");
  int *allow = mem_alloc(nl, sizeof(int), "correlations");
  corr_range_pair_fraction(c, r0, r1, p, p + nl * nx, allow); /* the range's estimator */
  for (size_t l = 0; l < nl; l++) {
    int n = 0;
    double *ss = se + l * nv;
    memset(mean, 0, nv * sizeof(double));
    memset(ss, 0, nv * sizeof(double));
    for (size_t r = r0; r < r1; r++) /* two passes: the mean, then the squares about it */
      if (is_batch(c, r, l)) {
        window_values(c, r, l, allow[l], v);
        for (size_t j = 0; j < nv; j++) mean[j] += v[j];
        n++;
      }
    for (size_t j = 0; j < nv; j++) mean[j] /= n;
    for (size_t r = r0; r < r1; r++)
      if (is_batch(c, r, l)) {
        window_values(c, r, l, allow[l], v);
        for (size_t j = 0; j < nv; j++) ss[j] += (v[j] - mean[j]) * (v[j] - mean[j]);
      }
    for (size_t j = 0; j < nv; j++) ss[j] = n < 2 ? NAN : sqrt(ss[j] / (n - 1) / n);
    nb[l] = n;
  }
  free(v), free(p), free(allow);
}

void corr_stderr(const struct corr *c, double *rx, double *rz, double *ex, double *ez, int *nb) {
  const int nx = c->cfg.nx, nz = c->cfg.nz, nzh = c->nzh, nxh = nx / 2 + 1;
  const size_t nv = corr_nv(c);
  double *se = mem_alloc((size_t)c->cfg.n_levels * nv, sizeof(double), "correlations");
  corr_range_stderr(c, 0, c->nwin, se, nb);
  for (size_t l = 0; l < (size_t)c->cfg.n_levels; l++) {
    const double *ss = se + l * nv;
    memcpy(rx + l * 4 * (size_t)nx, ss, 4 * (size_t)nx * sizeof(double));
    memcpy(rz + l * 4 * (size_t)nz, ss + 4 * nx, 4 * (size_t)nz * sizeof(double));
    memcpy(ex + l * 3 * (size_t)nxh, ss + 4 * nx + 4 * nz, 3 * (size_t)nxh * sizeof(double));
    memcpy(ez + l * 3 * (size_t)nzh, ss + 4 * nx + 4 * nz + 3 * nxh,
           3 * (size_t)nzh * sizeof(double));
  }
  free(se);
}
