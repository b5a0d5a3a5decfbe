/** @file lagr.c @brief Implementation of lagr.h. */
#include "lagr.h"
#include "engine.h"
#include "ncutil.h"

#include <math.h>
#include <netcdf.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "moments.h"
#include "ncout.h"
#include "spar.h"
#include "state.h"

/* A particle record gathered from the ranks: id, position, velocity, acceleration (zero if
   the snapshot has none), 1 if a release candidate (fluid, in a release slab). */
enum { LR_ID, LR_X, LR_Y, LR_Z, LR_U, LR_V, LR_W, LR_AX, LR_AY, LR_AZ, LR_CAND, LR_LEN };
_Static_assert((int)LR_LEN == (int)LAGR_REC, "LAGR_REC in lagr.h");

static size_t rec(const struct lagr *g, int level, size_t k) { /* offset of a sums record */
  return ((size_t)level * g->nlag + k) * LG_LEN;
}

static double *slot_rec(const struct lagr *g, int slot, int level, size_t k) {
  return g->slot_sums + (size_t)slot * (size_t)g->cfg.n_levels * g->nlag * LG_LEN +
         rec(g, level, k);
}

static size_t n_st(const struct lagr_config *c) { /* station records (1 without stations) */
  return (size_t)(c->n_stations ? c->n_stations : 1);
}

/* A slot's record of the dispersion PDF of its release: a flag (1: the release's crossings
   are all there; 0 after a resume from a checkpoint without the record, format <= 1.11), then
   [level][station][pdf_bins + 3] as g->pdf. */
static size_t slot_pdf_len(const struct lagr *g) {
  return 1 + (size_t)g->cfg.n_levels * n_st(&g->cfg) * (size_t)(g->cfg.pdf_bins + 3);
}

static double *slot_pdf(const struct lagr *g, int slot) {
  return g->slot_pdf + (size_t)slot * slot_pdf_len(g);
}

void lagr_init(struct lagr *g, const struct lagr_config *cfg) {
  memset(g, 0, sizeof *g);
  g->cfg = *cfg;
  if (cfg->n_levels <= 0) return;
  g->nlag = (size_t)cfg->n_lags + 1;
  g->n_slots = (int)ceil(cfg->horizon / cfg->release_every - 1e-9) + 1;
  const size_t nl = (size_t)cfg->n_levels;
  g->sums = mem_calloc(nl * g->nlag * LG_LEN, sizeof(double), "Lagrangian engine");
  /* the release slots: all in use after one horizon; resident from the start */
  g->slot_sums = mem_calloc_resident((size_t)g->n_slots * nl * g->nlag * LG_LEN, sizeof(double),
                                     "Lagrangian engine");
  g->slots = mem_calloc((size_t)g->n_slots * SL_LEN, sizeof(double), "Lagrangian engine");
  g->tl = mem_calloc(nl * 3 * SCAL_LEN, sizeof(double), "Lagrangian engine");
  g->rb = mem_calloc(nl * LF_LEN * g->nlag * SCAL_LEN, sizeof(double), "Lagrangian engine");
  g->slot_pdf = mem_calloc_resident((size_t)g->n_slots * slot_pdf_len(g), sizeof(double),
                                    "Lagrangian engine");
  g->pdf_rb = mem_calloc(nl * n_st(cfg) * (size_t)(cfg->pdf_bins + 2) * SCAL_LEN, sizeof(double),
                         "Lagrangian engine");
  g->pdf =
      mem_calloc(nl * (size_t)(cfg->n_stations ? cfg->n_stations : 1) * (size_t)(cfg->pdf_bins + 3),
                 sizeof(double), "Lagrangian engine");
  g->next_release = cfg->t_start;
}

void lagr_free(struct lagr *g) {
  free(g->sums), free(g->slot_sums), free(g->slots), free(g->tl), free(g->pdf);
  free(g->rb), free(g->slot_pdf), free(g->pdf_rb), free(g->tl_rel), free(g->tl_rel_t);
  free(g->tracks), free(g->index), free(g->mine), free(g->all);
  memset(g, 0, sizeof *g);
}

static double wrap(double d, double l) { /* minimum image */
  if (l <= 0.0) return d;
  return d - l * floor(d / l + 0.5);
}

static void reserve_tracks(struct lagr *g, size_t n) {
  if (n <= g->cap) return;
  size_t cap = g->cap ? g->cap : 256;
  while (cap < n) cap *= 2;
  g->tracks = mem_realloc(g->tracks, cap * TR_LEN, sizeof(double), "Lagrangian tracks");
  g->cap = cap;
}

/* Add a track's values at the current sample (particle record p) to record R (lag k of its
   release); tau = t - t0, the actual lag of the sample (the same on every rank). */
static void contribute(const double *tr, const double *p, double tau, double *R) {
  const double sg = tr[TR_MIRROR] != 0.0 ? -1.0 : 1.0;
  const double vt[3] = {p[LR_U], sg * p[LR_V], p[LR_W]};
  const double at[3] = {p[LR_AX], sg * p[LR_AY], p[LR_AZ]};
  R[LG_N] += 1.0, R[LG_TAU] += tau;
  for (int i = 0; i < 3; i++) {
    const double v0 = tr[TR_V0 + i], a0 = tr[TR_A0 + i];
    double *V = R + LG_VEL + 5 * i, *A = R + LG_ACC + 5 * i;
    V[0] += v0, V[1] += vt[i], V[2] += v0 * v0, V[3] += vt[i] * vt[i], V[4] += v0 * vt[i];
    A[0] += a0, A[1] += at[i], A[2] += a0 * a0, A[3] += at[i] * at[i], A[4] += a0 * at[i];
    const double dv = vt[i] - v0, dv2 = dv * dv;
    R[LG_STRUCT + 3 * i] += dv2, R[LG_STRUCT + 3 * i + 1] += dv2 * dv;
    R[LG_STRUCT + 3 * i + 2] += dv2 * dv2;
    R[LG_DISP + i] += tr[TR_DISP + i] * tr[TR_DISP + i], R[LG_DR + i] += tr[TR_DISP + i];
    const double rate = tau > 0.0 ? tr[TR_DISP + i] / tau : 0.0; /* lag 0: no displacement */
    R[LG_RATE + 2 * i] += rate, R[LG_RATE + 2 * i + 1] += rate * rate;
  }
}

/* Correlation coefficient of the pair (block of 5 sums) over n samples. */
static double corr5(const double *S, double n) {
  if (n < 2.0) return NAN;
  const double m0 = S[0] / n, mt = S[1] / n;
  const double c = S[4] / n - m0 * mt, v0 = S[2] / n - m0 * m0, vt = S[3] / n - mt * mt;
  return v0 > 0.0 && vt > 0.0 ? c / sqrt(v0 * vt) : NAN;
}

double lagr_tl(const double *rho, size_t nlag, double dtau) {
  const double target = exp(-0.5);
  double half = NAN; /* T_E / 2 */
  for (size_t k = 1; k < nlag; k++)
    if (isfinite(rho[k]) && isfinite(rho[k - 1]) && rho[k] <= target) {
      half = dtau * ((double)(k - 1) + (rho[k - 1] - target) / (rho[k - 1] - rho[k]));
      break;
    }
  if (!isfinite(half)) return NAN;
  const double end = fmin(8.0 * half, dtau * (double)(nlag - 1)); /* 4 T_E */
  double sum = 0.0;
  for (size_t k = 1; k < nlag; k++) {
    const double t0 = dtau * (double)(k - 1), t1 = dtau * (double)k;
    if (t0 >= end) break;
    if (t1 <= end) {
      sum += 0.5 * dtau * (rho[k - 1] + rho[k]);
    } else { /* partial interval up to end */
      const double f = (end - t0) / dtau, re = rho[k - 1] + f * (rho[k] - rho[k - 1]);
      sum += 0.5 * (end - t0) * (rho[k - 1] + re);
    }
  }
  return sum;
}

static void functions_of(const struct lagr *g, const double *sums, double *out);

/* One completed release's own values, each a batch: its lag functions (functions_of on its
   sums) and, where its crossings are all recorded, its dispersion PDFs, mu_y and variance. */
static void release_batches(struct lagr *g, int slot) {
  const struct lagr_config *c = &g->cfg;
  const size_t nlag = g->nlag, nb = (size_t)c->pdf_bins;
  double *fn = mem_alloc(LF_LEN * nlag, sizeof(double), "Lagrangian engine");
  for (int l = 0; l < c->n_levels; l++) {
    functions_of(g, slot_rec(g, slot, l, 0), fn);
    double *B = g->rb + (size_t)l * LF_LEN * nlag * SCAL_LEN;
    for (size_t i = 0; i < LF_LEN * nlag; i++)
      if (isfinite(fn[i])) scal_add(B + i * SCAL_LEN, fn[i]);
  }
  free(fn);
  const double *sp = slot_pdf(g, slot);
  if (sp[0] != 1.0) return;
  const double width = 2.0 * c->delta / (double)nb;
  for (size_t ls = 0; ls < (size_t)c->n_levels * (size_t)c->n_stations; ls++) {
    const double *P = sp + 1 + ls * (nb + 3), n = P[nb];
    if (!(n > 0.0)) continue;
    double *B = g->pdf_rb + ls * (nb + 2) * SCAL_LEN;
    for (size_t b = 0; b < nb; b++) scal_add(B + b * SCAL_LEN, P[b] / (n * width));
    const double mu = P[nb + 1] / n;
    scal_add(B + nb * SCAL_LEN, mu);
    scal_add(B + (nb + 1) * SCAL_LEN, P[nb + 2] / n - mu * mu);
  }
}

/* Room for n releases in the history of T_L (both arrays; at least one row, so that an empty
   history still has memory for the checkpoint's state list). */
static void reserve_history(struct lagr *g, size_t n) {
  if (n <= g->rel_cap && g->tl_rel) return;
  size_t cap = g->rel_cap ? g->rel_cap : 64;
  while (cap < n) cap *= 2;
  const size_t row = (size_t)g->cfg.n_levels * 3;
  g->tl_rel = mem_realloc(g->tl_rel, cap * row, sizeof(double), "Lagrangian T_L history");
  g->tl_rel_t = mem_realloc(g->tl_rel_t, cap, sizeof(double), "Lagrangian T_L history");
  g->rel_cap = cap;
}

/* Retire the release of slot, completed at simulated time t: its sums join the merged ones, its
   T_L the batches and the history, its lag functions and PDF the per-release batches. */
static void retire(struct lagr *g, int slot, double t_end) {
  const int nl = g->cfg.n_levels;
  const double dtau = g->cfg.horizon / g->cfg.n_lags;
  release_batches(g, slot);
  reserve_history(g, g->n_rel + 1);
  double *hist = g->tl_rel + g->n_rel * (size_t)nl * 3;
  g->tl_rel_t[g->n_rel++] = t_end;
  memset(slot_pdf(g, slot), 0, slot_pdf_len(g) * sizeof(double));
  double *rho = mem_calloc(g->nlag, sizeof(double), "Lagrangian engine");
  for (int l = 0; l < nl; l++) {
    for (size_t k = 0; k < g->nlag; k++) {
      const double *R = slot_rec(g, slot, l, k);
      double *G = g->sums + rec(g, l, k);
      for (int q = 0; q < LG_LEN; q++) G[q] += R[q];
    }
    for (int i = 0; i < 3; i++) { /* this release's T_L: one batch */
      for (size_t k = 0; k < g->nlag; k++) {
        const double *R = slot_rec(g, slot, l, k);
        rho[k] = corr5(R + LG_VEL + 5 * i, R[LG_N]);
      }
      const double t = lagr_tl(rho, g->nlag, dtau);
      if (isfinite(t)) scal_add(g->tl + ((size_t)l * 3 + (size_t)i) * SCAL_LEN, t);
      hist[l * 3 + i] = isfinite(t) ? t : NAN;
    }
  }
  free(rho);
  memset(slot_rec(g, slot, 0, 0), 0, (size_t)nl * g->nlag * LG_LEN * sizeof(double));
  /* drop the release's tracks, keeping the order of the others */
  size_t w = 0;
  for (size_t r = 0; r < g->ntracks; r++)
    if (g->tracks[r * TR_LEN + TR_SLOT] != (double)slot) {
      if (w != r) memcpy(g->tracks + w * TR_LEN, g->tracks + r * TR_LEN, TR_LEN * sizeof(double));
      w++;
    }
  g->ntracks = w;
  memset(g->slots + (size_t)slot * SL_LEN, 0, SL_LEN * sizeof(double));
  g->releases += 1.0;
}

/* The slab of a release level a particle at height y is in: 0 (level), 1 (mirror), -1. */
static int in_slab(const struct lagr_config *c, int l, double y) {
  const double ym = 2.0 * c->delta - c->y[l];
  if (fabs(y - c->y[l]) < c->half) return 0;
  if (fabs(ym - c->y[l]) >= 2.0 * c->half && fabs(y - ym) < c->half) return 1;
  return -1;
}

static int rec_cmp(const void *pa, const void *pb) {
  const double a = *(const double *)pa, b = *(const double *)pb;
  return a < b ? -1 : a > b;
}

/* The tracked particles and (if a release is due) the release candidates of all ranks, on
   every rank, sorted by id: the Lagrangian update then runs on identical inputs everywhere. */
static void gather(struct lagr *g, const struct stats_snapshot *s, int due) {
  const struct lagr_config *c = &g->cfg;
  /* mark the tracked ids (index[id] = 1; -1 elsewhere, restored below) */
  size_t len = 0;
  for (size_t r = 0; r < g->ntracks; r++) {
    const double id = g->tracks[r * TR_LEN + TR_ID];
    if (id >= 0 && (size_t)id + 1 > len) len = (size_t)id + 1;
  }
  if (len > g->index_len) {
    g->index = mem_realloc(g->index, len, sizeof(long), "statistics engine");
    for (size_t i = g->index_len; i < len; i++) g->index[i] = -1;
    g->index_len = len;
  }
  for (size_t r = 0; r < g->ntracks; r++) {
    const double id = g->tracks[r * TR_LEN + TR_ID];
    if (id >= 0) g->index[(size_t)id] = 1;
  }
  size_t n = 0;
  for (size_t a = 0; a < s->n; a++) {
    const int64_t id = s->id[a];
    const int tracked = id >= 0 && (size_t)id < g->index_len && g->index[id] == 1;
    int cand = 0;
    if (due && !(s->skip && s->skip[a]) && fabs(wrap(s->x[a] - c->x0, c->lx)) < c->half)
      for (int l = 0; l < c->n_levels && !cand; l++) cand = in_slab(c, l, s->y[a]) >= 0;
    if (!tracked && !cand) continue;
    if (n == g->mine_cap) {
      g->mine_cap = g->mine_cap ? 2 * g->mine_cap : 256;
      g->mine = mem_realloc(g->mine, g->mine_cap * LR_LEN, sizeof(double), "statistics engine");
    }
    double *p = g->mine + n++ * LR_LEN;
    p[LR_ID] = (double)id, p[LR_X] = s->x[a], p[LR_Y] = s->y[a], p[LR_Z] = s->z ? s->z[a] : 0.0;
    p[LR_U] = s->u[a], p[LR_V] = s->v[a], p[LR_W] = s->w[a];
    p[LR_AX] = s->ax ? s->ax[a] : 0.0, p[LR_AY] = s->ay ? s->ay[a] : 0.0;
    p[LR_AZ] = s->az ? s->az[a] : 0.0, p[LR_CAND] = cand;
  }
  for (size_t r = 0; r < g->ntracks; r++) {
    const double id = g->tracks[r * TR_LEN + TR_ID];
    if (id >= 0) g->index[(size_t)id] = -1;
  }
  struct spar par;
  spar_open(&par, s);
  g->nall = spar_gather_var(&par, g->mine, n, LR_LEN, &g->all, &g->all_cap);
  spar_close(&par);
  if (g->nall) qsort(g->all, g->nall, LR_LEN * sizeof(double), rec_cmp);
  for (size_t i = 1; i < g->nall; i++)
    if (g->all[i * LR_LEN + LR_ID] == g->all[(i - 1) * LR_LEN + LR_ID])
      die("statistics: particle id %.0f held by two ranks", g->all[i * LR_LEN + LR_ID]);
}

/* The gathered record of particle id, or NULL (not on any rank). */
static const double *find(const struct lagr *g, double id) {
  size_t lo = 0, hi = g->nall;
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    const double m = g->all[mid * LR_LEN + LR_ID];
    if (m == id) return g->all + mid * LR_LEN;
    if (m < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  return NULL;
}

/* A new release in slot: the candidates in id order (the same on any decomposition). */
static void release(struct lagr *g, int slot, const struct stats_snapshot *s) {
  const struct lagr_config *c = &g->cfg;
  double *sl = g->slots + (size_t)slot * SL_LEN;
  sl[SL_T0] = s->t, sl[SL_LAST_K] = 0.0, sl[SL_ACTIVE] = 1.0, sl[SL_N] = 0.0;
  memset(slot_pdf(g, slot), 0, slot_pdf_len(g) * sizeof(double));
  slot_pdf(g, slot)[0] = 1.0;
  for (size_t i = 0; i < g->nall; i++) {
    const double *p = g->all + i * LR_LEN;
    if (p[LR_CAND] == 0.0) continue;
    for (int l = 0; l < c->n_levels; l++) {
      const int mirror = in_slab(c, l, p[LR_Y]);
      if (mirror < 0) continue;
      reserve_tracks(g, g->ntracks + 1);
      double *tr = g->tracks + g->ntracks * TR_LEN;
      memset(tr, 0, TR_LEN * sizeof(double));
      const double sg = mirror ? -1.0 : 1.0;
      tr[TR_SLOT] = slot, tr[TR_LEVEL] = l, tr[TR_MIRROR] = mirror, tr[TR_ID] = p[LR_ID];
      tr[TR_V0] = p[LR_U], tr[TR_V0 + 1] = sg * p[LR_V], tr[TR_V0 + 2] = p[LR_W];
      tr[TR_A0] = p[LR_AX], tr[TR_A0 + 1] = sg * p[LR_AY], tr[TR_A0 + 2] = p[LR_AZ];
      tr[TR_LAST] = p[LR_X], tr[TR_LAST + 1] = p[LR_Y], tr[TR_LAST + 2] = p[LR_Z];
      contribute(tr, p, 0.0, slot_rec(g, slot, l, 0));
      g->ntracks++, sl[SL_N] += 1.0;
      break;
    }
  }
}

void lagr_sample(struct lagr *g, const struct stats_snapshot *s) {
  const struct lagr_config *c = &g->cfg;
  if (c->n_levels <= 0 || s->t < c->t_start) return;
  const int due = s->t >= g->next_release;
  if (!g->ntracks && !due) return;
  gather(g, s, due);
  const double dtau = c->horizon / c->n_lags, ly = 2.0 * c->delta;
  const size_t nbin = (size_t)c->pdf_bins + 3;
  /* displacements, station crossings and lag samples of the tracked particles */
  for (size_t r = 0; r < g->ntracks; r++) {
    double *tr = g->tracks + r * TR_LEN;
    const double *p = find(g, tr[TR_ID]);
    if (!p) continue; /* on no rank (lost) */
    const double x = p[LR_X], y = p[LR_Y], z = p[LR_Z];
    const double dx = wrap(x - tr[TR_LAST], c->lx), dz = wrap(z - tr[TR_LAST + 2], c->lz);
    const double dprev = tr[TR_DISP], yprev = tr[TR_LAST + 1];
    tr[TR_DISP] += dx, tr[TR_DISP + 2] += dz;
    tr[TR_DISP + 1] += (tr[TR_MIRROR] != 0.0 ? -1.0 : 1.0) * (y - yprev);
    tr[TR_LAST] = x, tr[TR_LAST + 1] = y, tr[TR_LAST + 2] = z;
    const int l = (int)tr[TR_LEVEL];
    for (int st = 0; st < c->n_stations; st++) {
      const unsigned bit = 1u << st;
      if (((unsigned)tr[TR_DONE] & bit) || tr[TR_DISP] < c->station[st]) continue;
      const double f = dx != 0.0 ? (c->station[st] - dprev) / dx : 1.0;
      double yc = yprev + f * (y - yprev); /* y where the track crossed the station */
      if (tr[TR_MIRROR] != 0.0) yc = ly - yc;
      double *P = g->pdf + ((size_t)l * (size_t)c->n_stations + (size_t)st) * nbin;
      int b = (int)floor(yc / ly * c->pdf_bins);
      b = b < 0 ? 0 : b >= c->pdf_bins ? c->pdf_bins - 1 : b;
      P[b] += 1.0, P[c->pdf_bins] += 1.0, P[c->pdf_bins + 1] += yc, P[c->pdf_bins + 2] += yc * yc;
      double *Q = slot_pdf(g, (int)tr[TR_SLOT]) + 1 +
                  ((size_t)l * (size_t)c->n_stations + (size_t)st) * nbin; /* its release's */
      Q[b] += 1.0, Q[c->pdf_bins] += 1.0, Q[c->pdf_bins + 1] += yc, Q[c->pdf_bins + 2] += yc * yc;
      tr[TR_DONE] = (double)((unsigned)tr[TR_DONE] | bit);
    }
  }
  for (int sl = 0; sl < g->n_slots; sl++) {
    double *S = g->slots + (size_t)sl * SL_LEN;
    if (S[SL_ACTIVE] == 0.0) continue;
    const double tau = s->t - S[SL_T0], k = floor(tau / dtau + 1e-9);
    if (k > S[SL_LAST_K] && k <= c->n_lags) {
      for (size_t r = 0; r < g->ntracks; r++) {
        const double *tr = g->tracks + r * TR_LEN;
        if (tr[TR_SLOT] != (double)sl) continue;
        const double *p = find(g, tr[TR_ID]);
        if (p) contribute(tr, p, tau, slot_rec(g, sl, (int)tr[TR_LEVEL], (size_t)k));
      }
      S[SL_LAST_K] = k;
    }
    if (k >= c->n_lags) retire(g, sl, s->t);
  }
  if (due) {
    int slot = -1;
    for (int sl = 0; sl < g->n_slots && slot < 0; sl++)
      if (g->slots[(size_t)sl * SL_LEN + SL_ACTIVE] == 0.0) slot = sl;
    if (slot >= 0) release(g, slot, s);
    while (g->next_release <= s->t) g->next_release += c->release_every;
  }
}

static void *reserve_tr(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  if (rank != 2 || dims[1] != TR_LEN) return NULL;
  reserve_tracks(g, dims[0] ? dims[0] : 1);
  g->ntracks = dims[0];
  return g->tracks;
}

/* The history of T_L in a checkpoint (format 1.13): tl_release first (it sets the length),
   then tl_release_time, which must have as many rows. */
static void *reserve_tl_rel(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  if (rank != 3 || dims[1] != (size_t)g->cfg.n_levels || dims[2] != 3) return NULL;
  reserve_history(g, dims[0]);
  g->n_rel = dims[0];
  return g->tl_rel;
}

static void *reserve_tl_rel_t(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  return rank == 1 && dims[0] == g->n_rel ? g->tl_rel_t : NULL;
}

/* The sums of a checkpoint of format <= 1.9 (records of width LG_LEN_1_6 up to format 1.6,
   LG_LEN_1_8 in 1.7-1.8, LG_LEN_1_9 in 1.9, read into the front of g->sums or g->slot_sums):
   spread them to records of LG_LEN, from the last one back. The sums after the stored ones (of
   dr before 1.7, of the actual lags before 1.9, of the interval-mean velocities before 1.10)
   were not kept: NaN in a record with samples (the mean displacement, lag time or
   interval-mean velocity variance of the run stays NaN), 0 in one without (exact). */
static void widen(double *a, size_t rows, size_t width) {
  for (size_t r = rows; r-- > 0;) {
    double *R = a + r * LG_LEN;
    memmove(R, a + r * width, width * sizeof(double));
    for (size_t i = width; i < LG_LEN; i++) R[i] = R[LG_N] > 0.0 ? NAN : 0.0;
  }
}

static int known_width(size_t w) { /* a record width of some checkpoint format */
  return w == LG_LEN || w == LG_LEN_1_9 || w == LG_LEN_1_8 || w == LG_LEN_1_6;
}

static void *reserve_sums(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  const int ok =
      rank == 3 && dims[0] == (size_t)g->cfg.n_levels && dims[1] == g->nlag && known_width(dims[2]);
  return ok ? g->sums : NULL;
}

static void *reserve_slot_sums(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  const int ok = rank == 3 && dims[0] == (size_t)g->n_slots &&
                 dims[1] == (size_t)g->cfg.n_levels * g->nlag && known_width(dims[2]);
  return ok ? g->slot_sums : NULL;
}

static void widen_sums(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  if (rank == 3 && dims[2] < LG_LEN) widen(g->sums, dims[0] * dims[1], dims[2]);
}

static void widen_slot_sums(void *owner, int rank, const size_t *dims) {
  struct lagr *g = owner;
  if (rank == 3 && dims[2] < LG_LEN) widen(g->slot_sums, dims[0] * dims[1], dims[2]);
}

void lagr_state(struct lagr *g, struct state_list *L) {
  if (g->cfg.n_levels <= 0) return;
  reserve_tracks(g, 1);
  const size_t nl = (size_t)g->cfg.n_levels, ns = (size_t)g->n_slots;
  const size_t st = (size_t)(g->cfg.n_stations ? g->cfg.n_stations : 1);
  const size_t d3[3] = {nl, g->nlag, LG_LEN}, d4[3] = {ns, nl * g->nlag, LG_LEN};
  const size_t ds[2] = {ns, SL_LEN}, dt[3] = {nl, 3, SCAL_LEN};
  const size_t dp[3] = {nl, st, (size_t)g->cfg.pdf_bins + 3}, dtr[2] = {g->ntracks, TR_LEN};
  /* format <= 1.9: records without the sums of the interval-mean velocities (LG_LEN_1_9),
     <= 1.8 also without those of the actual lags (LG_LEN_1_8) and, <= 1.6, of dr (LG_LEN_1_6),
     widened after reading */
  struct state_field *f = state_add(L, "stats/lagrangian/sums", STATE_F64, 3, d3, g->sums, NULL);
  f->reserve = reserve_sums, f->after_read = widen_sums, f->owner = g;
  f = state_add(L, "stats/lagrangian/slot_sums", STATE_F64, 3, d4, g->slot_sums, NULL);
  f->reserve = reserve_slot_sums, f->after_read = widen_slot_sums, f->owner = g;
  state_add(L, "stats/lagrangian/slots", STATE_F64, 2, ds, g->slots, NULL);
  state_add(L, "stats/lagrangian/tl_batches", STATE_F64, 3, dt, g->tl, "s");
  state_add(L, "stats/lagrangian/pdf", STATE_F64, 3, dp, g->pdf, NULL);
  f = state_add(L, "stats/lagrangian/tracks", STATE_F64, 2, dtr, g->tracks, NULL);
  f->reserve = reserve_tr, f->owner = g;
  /* format 1.12: the per-release batches; absent before (the standard errors then count the
     releases completed after the resume; the running releases' PDFs are left out of them) */
  const size_t drb[3] = {nl, LF_LEN * g->nlag, SCAL_LEN}, dsp[2] = {ns, slot_pdf_len(g)};
  const size_t dpb[3] = {nl * st, (size_t)g->cfg.pdf_bins + 2, SCAL_LEN};
  state_add(L, "stats/lagrangian/release_batches", STATE_F64, 3, drb, g->rb, NULL)->optional = 1;
  state_add(L, "stats/lagrangian/slot_pdf", STATE_F64, 2, dsp, g->slot_pdf, NULL)->optional = 1;
  state_add(L, "stats/lagrangian/pdf_batches", STATE_F64, 3, dpb, g->pdf_rb, NULL)->optional = 1;
  /* format 1.13: each completed release's own T_L and the time it completed; absent before
     (the history then holds the releases completed after the resume) */
  reserve_history(g, 1);
  const size_t dh[3] = {g->n_rel, nl, 3}, dht[1] = {g->n_rel};
  f = state_add(L, "stats/lagrangian/tl_release", STATE_F64, 3, dh, g->tl_rel, "s");
  f->reserve = reserve_tl_rel, f->owner = g, f->optional = 1;
  f = state_add(L, "stats/lagrangian/tl_release_time", STATE_F64, 1, dht, g->tl_rel_t, "s");
  f->reserve = reserve_tl_rel_t, f->owner = g, f->optional = 1;
  state_add(L, "stats/lagrangian/next_release", STATE_F64, 0, NULL, &g->next_release, "s");
  state_add(L, "stats/lagrangian/releases", STATE_F64, 0, NULL, &g->releases, NULL);
}

void lagr_functions(const struct lagr *g, int level, double *out, double *tl) {
  functions_of(g, g->sums + rec(g, level, 0), out);
  for (int i = 0; i < 3; i++)
    tl[i] = lagr_tl(out + (LF_RHO_L + i) * g->nlag, g->nlag, g->cfg.horizon / g->cfg.n_lags);
}

/* The lag functions (rows LF_*) of the sums of one level (nlag records of LG_LEN). */
static void functions_of(const struct lagr *g, const double *sums, double *out) {
  const size_t nlag = g->nlag;
  for (size_t k = 0; k < nlag; k++) {
    const double *R = sums + k * LG_LEN;
    const double n = R[LG_N];
    for (int i = 0; i < 3; i++) {
      out[(LF_RHO_L + i) * nlag + k] = corr5(R + LG_VEL + 5 * i, n);
      out[(LF_RHO_A + i) * nlag + k] = corr5(R + LG_ACC + 5 * i, n);
      out[(LF_D + i) * nlag + k] = n > 0 ? R[LG_STRUCT + 3 * i] / n : NAN;
      out[(LF_S + i) * nlag + k] = n > 0 ? R[LG_STRUCT + 3 * i + 1] / n : NAN;
      out[(LF_K + i) * nlag + k] = n > 0 ? R[LG_STRUCT + 3 * i + 2] / n : NAN;
      out[(LF_SIG2 + i) * nlag + k] = n > 0 ? R[LG_DISP + i] / n : NAN;
      const double m = n > 0 ? R[LG_DR + i] / n : NAN; /* NaN: resumed from format <= 1.6 */
      out[(LF_U0 + i) * nlag + k] = n > 0 ? R[LG_VEL + 5 * i] / n : NAN;
      out[(LF_UT + i) * nlag + k] = n > 0 ? R[LG_VEL + 5 * i + 1] / n : NAN;
      out[(LF_DR + i) * nlag + k] = m;
      out[(LF_DVAR + i) * nlag + k] = n > 0 ? R[LG_DISP + i] / n - m * m : NAN;
      const double r1 = n > 0 ? R[LG_RATE + 2 * i] / n : NAN; /* NaN: from format <= 1.9 */
      out[(LF_RVAR + i) * nlag + k] = n > 0 ? R[LG_RATE + 2 * i + 1] / n - r1 * r1 : NAN;
    }
    out[LF_N * nlag + k] = n;
    out[LF_TAU * nlag + k] = n > 0 ? R[LG_TAU] / n : NAN; /* NaN: resumed from format <= 1.8 */
  }
}

int lagr_warnings(const struct lagr *g, char *buf, size_t len) {
  const struct lagr_config *c = &g->cfg;
  const size_t nlag = g->nlag;
  int n = 0;
  size_t m = 0;
  buf[0] = '\0';
  if (c->n_levels > 0 && g->releases == 0.0) {
    m += (size_t)snprintf(buf + m, len - m,
                          "warning: lagrangian: no release completed (horizon %g s): no "
                          "Lagrangian statistics; run longer than lagrangian.horizon\n",
                          c->horizon);
    return 1;
  }
  double *fn = mem_alloc(1, LF_LEN * nlag * sizeof(double), "Lagrangian statistics");
  if (!fn) return 0;
  for (int l = 0; l < c->n_levels && m < len; l++) {
    double tl[3];
    lagr_functions(g, l, fn, tl);
    size_t empty = 0;
    for (size_t k = 0; k < nlag; k++) empty += !(fn[LF_N * nlag + k] > 0.0);
    if (empty) {
      m += (size_t)snprintf(buf + m, len - m,
                            "warning: lagrangian level y+ = %g: %zu of %zu lags have no samples "
                            "(lag interval horizon / n_lags = %g s is shorter than the "
                            "statistics sampling interval, output.stats_every steps): increase "
                            "lagrangian.horizon or decrease lagrangian.n_lags\n",
                            c->y_plus[l], empty, nlag, c->horizon / c->n_lags);
      n++;
    }
    static const char *const comp[3] = {"u", "v", "w"};
    char which[16] = "";
    for (int i = 0; i < 3; i++)
      if (!isfinite(tl[i]))
        snprintf(which + strlen(which), sizeof which - strlen(which), "%s%s", which[0] ? ", " : "",
                 comp[i]);
    if (which[0] && m < len) {
      m += (size_t)snprintf(buf + m, len - m,
                            "warning: lagrangian level y+ = %g: T_L of %s is NaN (rho_L does not "
                            "fall to e^-1/2 within the horizon %g s, or too few lags): increase "
                            "lagrangian.horizon\n",
                            c->y_plus[l], which, c->horizon);
      n++;
    }
  }
  free(fn);
  return n;
}

#define CK(call) NC_TRY(call, done)

/* The standard error of the mean of the batches of a Welford record (NaN below 2). */
static double batch_se(const double *W) {
  return W[SCAL_N] >= 2.0 ? sqrt(W[SCAL_M2] / (W[SCAL_N] - 1.0) / W[SCAL_N]) : NAN;
}

static int put_rows(int g, int v, int level, size_t n, const double *src) {
  double *tmp = mem_alloc(1, n * sizeof *tmp, "Lagrangian statistics");
  for (size_t i = 0; i < n; i++) tmp[i] = isfinite(src[i]) ? src[i] : NC_FILL_DOUBLE;
  const size_t st[2] = {(size_t)level, 0}, ct[2] = {1, n};
  const int rc = nc_put_vara_double(g, v, st, ct, tmp);
  free(tmp);
  return rc;
}

/* T_L of each level and component: from the merged releases, the mean over the releases and
   its standard error. */
static int write_integral_times(const struct lagr *g, int gr, int dl, int dc, const double *tl,
                                char *err, size_t errlen) {
  const int nl = g->cfg.n_levels;
  int rc = NC_NOERR, v;
  const int dlc[2] = {dl, dc};
  double *a = mem_alloc(1, (size_t)nl * 9 * sizeof(double), "Lagrangian statistics");
  for (int l = 0; l < nl; l++)
    for (int i = 0; i < 3; i++) {
      const double *W = g->tl + ((size_t)l * 3 + (size_t)i) * SCAL_LEN;
      a[l * 3 + i] = isfinite(tl[3 * l + i]) ? tl[3 * l + i] : NC_FILL_DOUBLE;
      a[3 * nl + l * 3 + i] = W[SCAL_N] > 0 ? W[SCAL_MEAN] : NC_FILL_DOUBLE;
      a[6 * nl + l * 3 + i] =
          W[SCAL_N] >= 2 ? sqrt(W[SCAL_M2] / (W[SCAL_N] - 1) / W[SCAL_N]) : NC_FILL_DOUBLE;
    }
  static const char *const nm[3] = {"T_L", "T_L_release_mean", "T_L_stderr"};
  static const char *const lnm[3] = {
      "Lagrangian integral time of u, v, w (Eq. 5.61) from the merged releases",
      "mean over the releases of their own T_L", "standard error of T_L over the releases"};
  for (int j = 0; j < 3 && rc == NC_NOERR; j++) {
    rc = ncout_def(gr, nm[j], NC_DOUBLE, 2, dlc, "s", lnm[j], &v);
    if (rc == NC_NOERR) rc = ncout_fill(gr, v);
    if (rc == NC_NOERR) rc = nc_put_var_double(gr, v, a + (size_t)j * 3 * nl);
  }
  free(a);
  CK(rc);
done:
  return rc;
}

/* The history of T_L: each completed release's own T_L per level and component (release order,
   dimension release, its coordinate the time each completed). Its mean over the finite values
   is T_L_release_mean, their standard deviation / sqrt(count) T_L_stderr, unless the run
   resumed from a checkpoint without the history (format <= 1.12): then it holds the releases
   completed after the resume only. */
static int write_history(const struct lagr *g, int gr, int dl, int dc, char *err, size_t errlen) {
  const size_t n = g->n_rel, row = (size_t)g->cfg.n_levels * 3;
  int rc = NC_NOERR, dr, v;
  CK(nc_def_dim(gr, "release", n, &dr)); /* 0: unlimited, of length 0 */
  CK(ncout_def(gr, "release", NC_DOUBLE, 1, &dr, "s",
               "simulated time at which the release completed (its last lag sampled)", &v));
  if (n) CK(nc_put_var_double(gr, v, g->tl_rel_t));
  const int d3[3] = {dr, dl, dc};
  CK(ncout_def(gr, "T_L_release", NC_DOUBLE, 3, d3, "s",
               "Lagrangian integral time of u, v, w (Eq. 5.61) of each completed release, from "
               "its own rho_L, in release order",
               &v));
  CK(ncout_fill(gr, v));
  if (n) {
    const size_t st[3] = {0, 0, 0}, ct[3] = {n, (size_t)g->cfg.n_levels, 3};
    CK(ncout_put_filled(gr, v, st, ct, g->tl_rel, n * row));
  }
done:
  return rc;
}

/* The PDFs of the track heights at the stations, their mean and variance (Eq. 5.67-5.68). */
static int write_pdfs(const struct lagr *g, int gr, int dl, double *tmp, char *err, size_t errlen) {
  const struct lagr_config *c = &g->cfg;
  const int nl = c->n_levels, ns = c->n_stations, nb = c->pdf_bins;
  int rc = NC_NOERR, v;
  int dst, db;
  CK(nc_def_dim(gr, "station", (size_t)ns, &dst));
  CK(nc_def_dim(gr, "pdf_bin", (size_t)nb, &db));
  CK(ncout_def(gr, "station", NC_DOUBLE, 1, &dst, "m", "downstream distance x - x0", &v));
  CK(nc_put_var_double(gr, v, c->station));
  for (int b = 0; b < nb; b++) tmp[b] = (b + 0.5) * 2.0 * c->delta / nb;
  CK(ncout_def(gr, "pdf_bin", NC_DOUBLE, 1, &db, "m", "y at the centre of the PDF bin", &v));
  {
    double *lo = mem_alloc(1, 2 * (size_t)nb * sizeof *lo, "Lagrangian statistics"), *hi = lo + nb;
    rc = NC_NOERR;
    for (int b = 0; b < nb; b++)
      lo[b] = b * 2.0 * c->delta / nb, hi[b] = (b + 1) * 2.0 * c->delta / nb;
    if (rc == NC_NOERR)
      rc = ncout_bounds(gr, "pdf_bin", v, db, "m", "limits of the PDF bin", lo, hi, (size_t)nb);
    free(lo);
    CK(rc);
  }
  CK(nc_put_var_double(gr, v, tmp));
  const int d3[3] = {dl, dst, db}, dls[2] = {dl, dst};
  int vp, vmu, vvar, vn;
  CK(ncout_def(gr, "pdf_y", NC_DOUBLE, 3, d3, "1/m",
               "PDF P(y; x) of the heights where the tracks cross the station", &vp));
  CK(ncout_def(gr, "pdf_mu_y", NC_DOUBLE, 2, dls, "m", "mean height mu_y (Eq. 5.67)", &vmu));
  CK(ncout_fill(gr, vmu));
  CK(ncout_def(gr, "pdf_var_y", NC_DOUBLE, 2, dls, "m^2",
               "variance of the height about mu_y (Eq. 5.68, printed there as sigma_y)", &vvar));
  CK(ncout_fill(gr, vvar));
  CK(ncout_def(gr, "pdf_count", NC_DOUBLE, 2, dls, "1", "tracks that crossed the station", &vn));
  int vpe, vmue, vvare, vnb;
  CK(ncout_def(gr, "pdf_y_stderr", NC_DOUBLE, 3, d3, "1/m",
               "standard error of pdf_y over the completed releases (each release's own PDF a "
               "batch)",
               &vpe));
  CK(ncout_fill(gr, vpe));
  CK(ncout_def(gr, "pdf_mu_y_stderr", NC_DOUBLE, 2, dls, "m",
               "standard error of pdf_mu_y over the completed releases", &vmue));
  CK(ncout_fill(gr, vmue));
  CK(ncout_def(gr, "pdf_var_y_stderr", NC_DOUBLE, 2, dls, "m^2",
               "standard error of pdf_var_y over the completed releases", &vvare));
  CK(ncout_fill(gr, vvare));
  CK(ncout_def(gr, "pdf_release_batches", NC_DOUBLE, 2, dls, "1",
               "completed releases with crossings of the station: the batches of the pdf "
               "standard errors",
               &vnb));
  const double width = 2.0 * c->delta / nb;
  for (int l = 0; l < nl; l++)
    for (int s = 0; s < ns; s++) {
      const double *P = g->pdf + ((size_t)l * ns + (size_t)s) * (size_t)(nb + 3);
      const double n = P[nb], mu = n > 0 ? P[nb + 1] / n : NC_FILL_DOUBLE;
      const double var = n > 0 ? P[nb + 2] / n - mu * mu : NC_FILL_DOUBLE;
      for (int b = 0; b < nb; b++) tmp[b] = n > 0 ? P[b] / (n * width) : 0.0;
      const size_t st3[3] = {(size_t)l, (size_t)s, 0}, ct3[3] = {1, 1, (size_t)nb};
      const size_t st2[2] = {(size_t)l, (size_t)s};
      CK(nc_put_vara_double(gr, vp, st3, ct3, tmp));
      CK(nc_put_var1_double(gr, vmu, st2, &mu));
      CK(nc_put_var1_double(gr, vvar, st2, &var));
      CK(nc_put_var1_double(gr, vn, st2, &n));
      const double *B = g->pdf_rb + ((size_t)l * ns + (size_t)s) * (size_t)(nb + 2) * SCAL_LEN;
      for (int b = 0; b < nb; b++) {
        const double se = batch_se(B + (size_t)b * SCAL_LEN);
        tmp[b] = isfinite(se) ? se : NC_FILL_DOUBLE;
      }
      CK(nc_put_vara_double(gr, vpe, st3, ct3, tmp));
      const double se_mu = batch_se(B + (size_t)nb * SCAL_LEN);
      const double se_var = batch_se(B + (size_t)(nb + 1) * SCAL_LEN);
      const double se_n = B[(size_t)nb * SCAL_LEN + SCAL_N];
      CK(nc_put_var1_double(gr, vmue, st2, isfinite(se_mu) ? &se_mu : &(double){NC_FILL_DOUBLE}));
      CK(nc_put_var1_double(gr, vvare, st2,
                            isfinite(se_var) ? &se_var : &(double){NC_FILL_DOUBLE}));
      CK(nc_put_var1_double(gr, vnb, st2, &se_n));
    }
done:
  return rc;
}

/* The per-level, per-lag functions of group lagrangian, three components each: their row of
   lagr_functions(), name and long-name patterns (%c: the component letter) and units. */
static const char LAGR_COMP[] = "uvw", LAGR_POS[] = "xyz";
static const struct {
  int row;
  const char *fmt, *units, *lfmt;
  const char *letters;
} lagr_rows[] = {
    {LF_RHO_L, "rho_L_%c", "1", "Lagrangian velocity autocorrelation of %c (Eq. 5.60)", LAGR_COMP},
    {LF_RHO_A, "rho_a_%c", "1", "Lagrangian acceleration autocorrelation of a_%c (Eq. 5.62)",
     LAGR_COMP},
    {LF_D, "D_%c", "m^2/s^2", "second-order structure function of %c (Eq. 5.63)", LAGR_COMP},
    {LF_S, "S_%c", "m^3/s^3", "third-order structure function of %c (Eq. 5.64)", LAGR_COMP},
    {LF_K, "K_%c", "m^4/s^4", "fourth-order structure function of %c (Eq. 5.65)", LAGR_COMP},
    {LF_SIG2, "sigma2_%c", "m^2", "dispersion <(%c(t0 + tau) - %c(t0))^2> (Eq. 5.66)", LAGR_POS},
    {LF_U0, "%c_release_mean", "m/s", "Lagrangian mean velocity at release <%c(t0)>", LAGR_COMP},
    {LF_UT, "%c_lag_mean", "m/s", "Lagrangian mean velocity at the lag <%c(t0 + tau)>", LAGR_COMP},
    {LF_DR, "disp_mean_%c", "m", "mean displacement <%c(t0 + tau) - %c(t0)>", LAGR_POS},
    {LF_DVAR, "disp_var_%c", "m^2",
     "variance of the displacement %c(t0 + tau) - %c(t0) about its mean", LAGR_POS},
    {LF_RVAR, "rate_var_%c", "m^2/s^2",
     "variance of the interval-mean velocity (%c(t0 + tau) - %c(t0)) / tau, each sample over "
     "its own actual lag tau (Taylor: <u_i'^2> at release as tau -> 0)",
     LAGR_POS},
};

/* The lag functions of lagr_rows and their standard errors over the releases, with the
   batch counts (release_batches), on dimensions d2 = (level, lag); fn: lagr_functions of
   every level, tmp: scratch of nlag. */
static int write_functions(const struct lagr *g, int gr, const int d2[2], const double *fn,
                           double *tmp, char *err, size_t errlen) {
  const int nl = g->cfg.n_levels;
  const size_t nlag = g->nlag;
  int rc = NC_NOERR, v;
  for (size_t j = 0; j < sizeof lagr_rows / sizeof lagr_rows[0]; j++)
    for (int i = 0; i < 3; i++) {
      char name[48], ln[256];
      const int row = lagr_rows[j].row + i;
      snprintf(name, sizeof name, lagr_rows[j].fmt, lagr_rows[j].letters[i]);
      snprintf(ln, sizeof ln, lagr_rows[j].lfmt, lagr_rows[j].letters[i], lagr_rows[j].letters[i]);
      CK(ncout_def(gr, name, NC_DOUBLE, 2, d2, lagr_rows[j].units, ln, &v));
      CK(ncout_fill(gr, v));
      for (int l = 0; l < nl; l++)
        CK(put_rows(gr, v, l, nlag, fn + ((size_t)l * LF_LEN + (size_t)row) * nlag));
      /* its standard error over the completed releases, each release's own value a batch */
      const size_t used = strlen(ln);
      snprintf(ln + used, sizeof ln - used, ": standard error over the releases");
      strncat(name, "_stderr", sizeof name - strlen(name) - 1);
      CK(ncout_def(gr, name, NC_DOUBLE, 2, d2, lagr_rows[j].units, ln, &v));
      CK(ncout_fill(gr, v));
      for (int l = 0; l < nl; l++) {
        const double *B = g->rb + ((size_t)l * LF_LEN + (size_t)row) * nlag * SCAL_LEN;
        for (size_t k = 0; k < nlag; k++) tmp[k] = batch_se(B + k * SCAL_LEN);
        CK(put_rows(gr, v, l, nlag, tmp));
      }
    }
  CK(ncout_def(gr, "release_batches", NC_DOUBLE, 2, d2, "1",
               "completed releases with samples at the lag: the batches of the *_stderr", &v));
  for (int l = 0; l < nl; l++) {
    const double *B = g->rb + ((size_t)l * LF_LEN + LF_D) * nlag * SCAL_LEN;
    for (size_t k = 0; k < nlag; k++) tmp[k] = B[k * SCAL_LEN + SCAL_N];
    CK(put_rows(gr, v, l, nlag, tmp));
  }
done:
  return rc;
}

/* A labelled slot axis (dimension dim, coordinate of string labels, ncout_labels) of n slots:
   first n_pre labels "PRE_k" (k = 0 .. n_pre - 1), then n - n_pre labels from tail. */
static int slot_axis(int gr, const char *dim, const char *long_name, size_t n, size_t n_pre,
                     const char *pre, const char *const *tail, int *dimid) {
  char *text = mem_alloc(n, 32, "Lagrangian statistics");
  const char **lab = mem_alloc(n, sizeof *lab, "Lagrangian statistics");
  for (size_t i = 0; i < n; i++) {
    if (i < n_pre)
      snprintf(text + 32 * i, 32, "%s_%zu", pre, i);
    else
      snprintf(text + 32 * i, 32, "%s", tail[i - n_pre]);
    lab[i] = text + 32 * i;
  }
  int rc = nc_def_dim(gr, dim, n, dimid);
  if (rc == NC_NOERR) rc = ncout_labels(gr, dim, *dimid, long_name, lab);
  free(lab), free(text);
  return rc;
}

/* The labels of the sums of a record (LG_*) into lab[LG_LEN][24]. */
static void sum_labels(char lab[LG_LEN][24]) {
  static const char *const vel[3] = {"u", "v", "w"}, *const acc[3] = {"ax", "ay", "az"};
  static const char *const pos[3] = {"x", "y", "z"};
  static const char *const pair[5] = {"sum_%s0", "sum_%st", "sum_%s0^2", "sum_%st^2",
                                      "sum_%s0*%st"};
  snprintf(lab[LG_N], 24, "n");
  snprintf(lab[LG_TAU], 24, "sum_tau");
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 5; j++) {
      snprintf(lab[LG_VEL + 5 * i + j], 24, pair[j], vel[i], vel[i]);
      snprintf(lab[LG_ACC + 5 * i + j], 24, pair[j], acc[i], acc[i]);
    }
    for (int j = 0; j < 3; j++)
      snprintf(lab[LG_STRUCT + 3 * i + j], 24, "sum_d%s^%d", vel[i], j + 2);
    snprintf(lab[LG_DISP + i], 24, "sum_d%s^2", pos[i]);
    snprintf(lab[LG_DR + i], 24, "sum_d%s", pos[i]);
    snprintf(lab[LG_RATE + 2 * i], 24, "sum_d%s/tau", pos[i]);
    snprintf(lab[LG_RATE + 2 * i + 1], 24, "sum_(d%s/tau)^2", pos[i]);
  }
}

/* The names of the rows of lagr_functions (LF_*) into lab[LF_LEN][32]. */
static void function_labels(char lab[LF_LEN][32]) {
  for (size_t j = 0; j < sizeof lagr_rows / sizeof lagr_rows[0]; j++)
    for (int i = 0; i < 3; i++)
      snprintf(lab[lagr_rows[j].row + i], 32, lagr_rows[j].fmt, lagr_rows[j].letters[i]);
  snprintf(lab[LF_N], 32, "n_tracks");
  snprintf(lab[LF_TAU], 32, "lag_time_mean");
}

/* The raw state of the completed releases, as the engine keeps it (what chansph extract pools
   when it joins segments): sums, per-release Welford records of the lag functions and of T_L,
   and with stations the PDF counts and sums and their per-release Welford records. Written
   after the other variables; dl, dk, dc: dimensions level, lag, component. No units: records of
   mixed quantities. */
static int write_raw(const struct lagr *g, int gr, int dl, int dk, int dc, char *err,
                     size_t errlen) {
  const size_t nb = (size_t)g->cfg.pdf_bins;
  static const char *const welford[SCAL_LEN] = {"n", "mean", "M2"};
  static const char *const pdf_tail[3] = {"n", "sum_y", "sum_y^2"};
  static const char *const val_tail[2] = {"mu_y", "var_y"};
  char sl[LG_LEN][24], fl[LF_LEN][32];
  const char *slp[LG_LEN], *flp[LF_LEN];
  sum_labels(sl), function_labels(fl);
  for (int i = 0; i < LG_LEN; i++) slp[i] = sl[i];
  for (int i = 0; i < LF_LEN; i++) flp[i] = fl[i];
  int rc = NC_NOERR, dw, ds, df, dst, dp, dv, v;
  CK(nc_def_dim(gr, "welford_slot", SCAL_LEN, &dw));
  CK(ncout_labels(gr, "welford_slot", dw, "slot of a Welford record: count, mean, M2", welford));
  CK(slot_axis(gr, "sum_slot", "slot of the raw sums of a level and lag", LG_LEN, 0, "", slp, &ds));
  CK(slot_axis(gr, "lag_function", "lag function of a release (a batch)", LF_LEN, 0, "", flp, &df));
  const int d_sums[3] = {dl, dk, ds}, d_rb[4] = {dl, df, dk, dw}, d_tl[3] = {dl, dc, dw};
  CK(ncout_def(gr, "raw_sums", NC_DOUBLE, 3, d_sums, NULL,
               "raw sums over the completed releases' samples of each level and lag", &v));
  CK(ncout_fill(gr, v)); /* NaN: a sum not kept by a checkpoint of an earlier format */
  CK(ncout_put_filled(gr, v, NULL, NULL, g->sums, (size_t)g->cfg.n_levels * g->nlag * LG_LEN));
  CK(ncout_def(gr, "release_welford", NC_DOUBLE, 4, d_rb, NULL,
               "raw Welford records (count, mean, M2) over the completed releases of each "
               "release's own lag functions: the batches of the *_stderr",
               &v));
  CK(nc_put_var_double(gr, v, g->rb));
  CK(ncout_def(gr, "T_L_welford", NC_DOUBLE, 3, d_tl, NULL,
               "raw Welford records (count, mean, M2) of the finite T_L of the completed "
               "releases: T_L_release_mean, T_L_stderr",
               &v));
  CK(nc_put_var_double(gr, v, g->tl));
  if (g->cfg.n_stations <= 0) goto done;
  CK(nc_inq_dimid(gr, "station", &dst));
  CK(slot_axis(gr, "pdf_slot", "slot of the raw PDF record: bin counts, n, sum y, sum y^2", nb + 3,
               nb, "count", pdf_tail, &dp));
  CK(slot_axis(gr, "pdf_value", "value of a release's PDF (a batch): pdf_y bins, mu_y, var_y",
               nb + 2, nb, "pdf_y", val_tail, &dv));
  const int d_pdf[3] = {dl, dst, dp}, d_pb[4] = {dl, dst, dv, dw};
  CK(ncout_def(gr, "raw_pdf", NC_DOUBLE, 3, d_pdf, NULL,
               "raw counts of the crossings per bin, then their count, sum of y [m] and of y^2 "
               "[m^2] (all tracks, also of releases in flight)",
               &v));
  CK(nc_put_var_double(gr, v, g->pdf));
  CK(ncout_def(gr, "pdf_release_welford", NC_DOUBLE, 4, d_pb, NULL,
               "raw Welford records (count, mean, M2) over the completed releases of each "
               "release's own pdf_y, mu_y and var_y: the batches of the pdf *_stderr",
               &v));
  CK(nc_put_var_double(gr, v, g->pdf_rb));
done:
  return rc;
}

int lagr_nc_write(const struct lagr *g, int ncid, char *err, size_t errlen) {
  const struct lagr_config *c = &g->cfg;
  const int nl = c->n_levels, ns = c->n_stations, nb = c->pdf_bins;
  const size_t nlag = g->nlag;
  double *fn = mem_alloc(1, (size_t)nl * LF_LEN * nlag * sizeof(double), "Lagrangian statistics");
  double *tl = mem_alloc(1, (size_t)nl * 3 * sizeof(double), "Lagrangian statistics");
  double *tmp = mem_alloc(nlag + (size_t)nb + 16, sizeof(double), "Lagrangian statistics");
  int rc = NC_NOERR, gr, dl, dk, dc, v;
  for (int l = 0; l < nl; l++) lagr_functions(g, l, fn + (size_t)l * LF_LEN * nlag, tl + 3 * l);
  CK(nc_def_grp(ncid, "lagrangian", &gr));
  static const char desc[] =
      "Lagrangian statistics of particles released at x0 and y+ levels (thesis Eq. 5.60-5.68), "
      "ensemble averages over the completed releases";
  CK(nc_put_att_text(gr, NC_GLOBAL, "description", strlen(desc), desc));
  const long long releases = (long long)g->releases; /* a count */
  CK(nc_put_att_longlong(gr, NC_GLOBAL, "releases", NC_INT64, 1, &releases));
  CK(nc_put_att_double(gr, NC_GLOBAL, "x0", NC_DOUBLE, 1, &c->x0));
  CK(nc_put_att_double(gr, NC_GLOBAL, "horizon", NC_DOUBLE, 1, &c->horizon));
  CK(nc_put_att_double(gr, NC_GLOBAL, "release_every", NC_DOUBLE, 1, &c->release_every));
  /* releases closer than the horizon meet the same eddies: their batches are not independent */
  const long long overlap = c->release_every < c->horizon * (1.0 - 1e-9);
  CK(nc_put_att_longlong(gr, NC_GLOBAL, "releases_overlap", NC_INT64, 1, &overlap));
  CK(nc_def_dim(gr, "level", (size_t)nl, &dl));
  CK(nc_def_dim(gr, "lag", nlag, &dk));
  CK(nc_def_dim(gr, "component", 3, &dc));
  CK(ncout_def(gr, "level", NC_DOUBLE, 1, &dl, "m", "release height above the lower wall", &v));
  CK(nc_put_var_double(gr, v, c->y));
  CK(ncout_def(gr, "y_plus", NC_DOUBLE, 1, &dl, "1", "release level in wall units", &v));
  CK(nc_put_var_double(gr, v, c->y_plus));
  for (size_t k = 0; k < nlag; k++) tmp[k] = (double)k * c->horizon / c->n_lags;
  CK(ncout_def(gr, "lag", NC_DOUBLE, 1, &dk, "s", "time lag tau", &v));
  CK(nc_put_var_double(gr, v, tmp));
  static const char *const components[3] = {"u", "v", "w"};
  CK(ncout_labels(gr, "component", dc, "velocity component", components));
  const int d2[2] = {dl, dk};
  if ((rc = write_functions(g, gr, d2, fn, tmp, err, errlen)) != NC_NOERR) goto done;
  CK(ncout_def(gr, "n_tracks", NC_DOUBLE, 2, d2, "1", "particle samples at each lag", &v));
  for (int l = 0; l < nl; l++)
    CK(put_rows(gr, v, l, nlag, fn + ((size_t)l * LF_LEN + LF_N) * nlag));
  CK(ncout_def(gr, "lag_time_mean", NC_DOUBLE, 2, d2, "s",
               "mean actual lag time of the samples of this lag (the nominal lag is the "
               "coordinate lag = k horizon / n_lags)",
               &v));
  CK(ncout_fill(gr, v));
  for (int l = 0; l < nl; l++)
    CK(put_rows(gr, v, l, nlag, fn + ((size_t)l * LF_LEN + LF_TAU) * nlag));
  /* each names its own failing call in err */
  if ((rc = write_integral_times(g, gr, dl, dc, tl, err, errlen)) != NC_NOERR ||
      (rc = write_history(g, gr, dl, dc, err, errlen)) != NC_NOERR ||
      (ns > 0 && (rc = write_pdfs(g, gr, dl, tmp, err, errlen)) != NC_NOERR) ||
      (rc = write_raw(g, gr, dl, dk, dc, err, errlen)) != NC_NOERR)
    goto done;
done:
  free(fn), free(tl), free(tmp);
  return rc;
}

/* The length of dimension name of group g (0 if absent). */
static size_t dim_len(int g, const char *name) {
  int d;
  size_t n = 0;
  return nc_inq_dimid(g, name, &d) || nc_inq_dimlen(g, d, &n) ? 0 : n;
}

/* The configuration of group lagrangian g (ncid: the file, for delta): what its writer needs. */
static int read_config(int ncid, int g, struct lagr_config *c) {
  memset(c, 0, sizeof *c);
  const size_t nl = dim_len(g, "level"), nlag = dim_len(g, "lag"), ns = dim_len(g, "station");
  if (nl < 1 || nl > LAGR_MAX_LEVELS || nlag < 3 || ns > LAGR_MAX_STATIONS) return 1;
  c->n_levels = (int)nl, c->n_lags = (int)nlag - 1, c->n_stations = (int)ns;
  c->pdf_bins = ns ? (int)dim_len(g, "pdf_bin") : 0; /* not written without stations */
  return ncout_get_raw(g, "level", nl, c->y) || ncout_get_raw(g, "y_plus", nl, c->y_plus) ||
         (ns && ncout_get_raw(g, "station", ns, c->station)) ||
         nc_get_att_double(g, NC_GLOBAL, "x0", &c->x0) ||
         nc_get_att_double(g, NC_GLOBAL, "horizon", &c->horizon) ||
         nc_get_att_double(g, NC_GLOBAL, "release_every", &c->release_every) ||
         nc_get_att_double(ncid, NC_GLOBAL, "delta", &c->delta) || !(c->horizon > 0.0) ||
         !(c->release_every > 0.0);
}

/* The history of T_L of group g into the engine (its rows and their completion times). */
static int read_history(struct lagr *g, int gr) {
  const size_t n = dim_len(gr, "release"), row = (size_t)g->cfg.n_levels * 3;
  reserve_history(g, n ? n : 1);
  g->n_rel = n;
  return ncout_get_raw(gr, "release", n, g->tl_rel_t) ||
         ncout_get_raw(gr, "T_L_release", n * row, g->tl_rel);
}

int lagr_nc_read(struct lagr *g, int ncid, char *err, size_t errlen) {
  struct lagr_config c;
  int gr;
  memset(g, 0, sizeof *g);
  if (nc_inq_ncid(ncid, "lagrangian", &gr) != NC_NOERR) {
    snprintf(err, errlen, "no group 'lagrangian'");
    return 1;
  }
  if (read_config(ncid, gr, &c)) {
    snprintf(err, errlen, "group 'lagrangian' has no readable configuration");
    return -1;
  }
  lagr_init(g, &c);
  const size_t nl = (size_t)c.n_levels, ns = (size_t)c.n_stations, nb = (size_t)c.pdf_bins;
  if (ncout_get_raw(gr, "raw_sums", nl * g->nlag * LG_LEN, g->sums) ||
      ncout_get_raw(gr, "release_welford", nl * LF_LEN * g->nlag * SCAL_LEN, g->rb) ||
      ncout_get_raw(gr, "T_L_welford", nl * 3 * SCAL_LEN, g->tl) ||
      (ns &&
       (ncout_get_raw(gr, "raw_pdf", nl * ns * (nb + 3), g->pdf) ||
        ncout_get_raw(gr, "pdf_release_welford", nl * ns * (nb + 2) * SCAL_LEN, g->pdf_rb))) ||
      read_history(g, gr) || nc_get_att_double(gr, NC_GLOBAL, "releases", &g->releases)) {
    snprintf(err, errlen,
             "group 'lagrangian' has no raw sums and per-release records (raw_sums, "
             "release_welford, T_L_welford: written before stats.nc held them)");
    lagr_free(g);
    return 2;
  }
  return 0;
}

/* Whether two configurations gather the same statistics (levels, lags, releases, stations). */
static int same_config(const struct lagr_config *x, const struct lagr_config *y) {
  int same = x->n_levels == y->n_levels && x->n_lags == y->n_lags && x->x0 == y->x0 &&
             x->horizon == y->horizon && x->release_every == y->release_every &&
             x->n_stations == y->n_stations && x->pdf_bins == y->pdf_bins;
  for (int l = 0; same && l < x->n_levels; l++) same = x->y_plus[l] == y->y_plus[l];
  for (int s = 0; same && s < x->n_stations; s++) same = x->station[s] == y->station[s];
  return same;
}

int lagr_join(struct lagr *g, const struct lagr *b, double offset, char *why, size_t len) {
  if (!same_config(&g->cfg, &b->cfg)) {
    snprintf(why, len,
             "other release levels, lags, horizon, release_every, x0, stations or pdf bins");
    return 1;
  }
  const struct lagr_config *c = &g->cfg;
  const size_t nl = (size_t)c->n_levels, nst = n_st(c), nb = (size_t)c->pdf_bins;
  for (size_t i = 0; i < nl * g->nlag * LG_LEN; i++) g->sums[i] += b->sums[i];
  for (size_t i = 0; i < nl * nst * (nb + 3); i++) g->pdf[i] += b->pdf[i];
  for (size_t i = 0; i < nl * LF_LEN * g->nlag; i++)
    scal_merge(g->rb + i * SCAL_LEN, b->rb + i * SCAL_LEN);
  for (size_t i = 0; i < nl * nst * (nb + 2); i++)
    scal_merge(g->pdf_rb + i * SCAL_LEN, b->pdf_rb + i * SCAL_LEN);
  for (size_t i = 0; i < nl * 3; i++) scal_merge(g->tl + i * SCAL_LEN, b->tl + i * SCAL_LEN);
  /* the history: b's releases after g's, their completion times on the joined time axis */
  const size_t row = nl * 3;
  reserve_history(g, g->n_rel + b->n_rel);
  memcpy(g->tl_rel + g->n_rel * row, b->tl_rel, b->n_rel * row * sizeof(double));
  for (size_t r = 0; r < b->n_rel; r++) g->tl_rel_t[g->n_rel + r] = b->tl_rel_t[r] + offset;
  g->n_rel += b->n_rel, g->releases += b->releases;
  return 0;
}

/* The engine's scene keys, section [lagrangian] (docs/scenes.md is generated from them). */
static const struct scene_key_def key_y_plus = {
    .section = "lagrangian",
    .name = "y_plus",
    .type = SCENE_LIST,
    .def = "",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .flags = SCENE_Y_PLUS,
    .unit = "-",
    .help =
        "Comma-separated y+ release levels (up to 8) of the Lagrangian statistics (thesis Sec. "
        "5.2.3.2, 6.1.3): fluid particles within dr/2 of each level (and of its mirror) and "
        "within dr/2 of x0 are tracked. Empty = off."};
static const struct scene_key_def key_x0 = {
    .section = "lagrangian",
    .name = "x0",
    .type = SCENE_DOUBLE,
    .def = "0",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .unit = "m",
    .help = "Release plane: particles with |x - x0| < dr/2 are released."};
static const struct scene_key_def key_horizon = {
    .section = "lagrangian",
    .name = "horizon",
    .type = SCENE_DOUBLE,
    .def = "1",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .flags = SCENE_LO_OPEN,
    .unit = "s",
    .help = "How long each release is followed (the largest lag tau)."};
static const struct scene_key_def key_release_every = {
    .section = "lagrangian",
    .name = "release_every",
    .type = SCENE_DOUBLE,
    .def = "0",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .unit = "s",
    .help =
        "Time between release iterations; releases overlap when shorter than the horizon. 0 = "
        "the horizon (consecutive, independent releases, thesis Sec. 6.1.3)."};
static const struct scene_key_def key_n_lags = {
    .section = "lagrangian",
    .name = "n_lags",
    .type = SCENE_INT,
    .def = "50",
    .lo = 2,
    .hi = 1e5,
    .unit = "-",
    .help =
        "Lag samples over the horizon (a particle is sampled at the first statistics sample "
        "in each lag interval)."};
static const struct scene_key_def key_pdf_x = {
    .section = "lagrangian",
    .name = "pdf_x",
    .type = SCENE_LIST,
    .def = "",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .unit = "m",
    .help =
        "Comma-separated downstream distances x - x0 (up to 8) of the stations of the PDFs P(y; "
        "x) (Eq. 5.67-5.68); empty = no PDFs."};
static const struct scene_key_def key_pdf_bins = {
    .section = "lagrangian",
    .name = "pdf_bins",
    .type = SCENE_INT,
    .def = "50",
    .lo = 2,
    .hi = 1e5,
    .unit = "-",
    .help = "Bins of the PDFs P(y; x) across the channel."};
static const struct scene_key_def *const keys[] = {
    &key_y_plus, &key_x0, &key_horizon, &key_release_every, &key_n_lags, &key_pdf_x, &key_pdf_bins};

/* The engine's table of operations (engine.h). */
static int config_of(const struct stats_scene *sc, struct lagr_config *cp) {
  struct lagr_config c;
  memset(&c, 0, sizeof c);
  c.n_levels = stats_scene_levels(sc, &key_y_plus, c.y_plus, c.y, LAGR_MAX_LEVELS);
  c.x0 = stats_scene_double(sc, &key_x0), c.half = 0.5 * sc->dr, c.lx = sc->lx;
  c.lz = sc->dim == 3 ? sc->lz : 0.0, c.delta = sc->delta;
  c.horizon = stats_scene_double(sc, &key_horizon);
  c.n_lags = stats_scene_int(sc, &key_n_lags);
  c.pdf_bins = stats_scene_int(sc, &key_pdf_bins);
  const double every = stats_scene_double(sc, &key_release_every);
  c.release_every = every > 0.0 ? every : c.horizon;
  c.n_stations = stats_scene_list(sc, &key_pdf_x, c.station, LAGR_MAX_STATIONS);
  c.t_start = sc->t_average_start;
  *cp = c;
  return c.n_levels > 0;
}

static int engine_init_scene(void *self, const struct stats_scene *sc) {
  struct lagr_config c;
  if (!config_of(sc, &c)) return 0;
  lagr_init(self, &c);
  return 1;
}

/* The records lagr_init allocates (sums, the release slots' sums, the PDFs), before any, and
   the history of T_L that the run will have (nl x 3 values and a time per release completed by
   t_end), twice: they and their copy in a checkpoint (built in memory, restart/ckpt.c). */
static double engine_estimate(const struct stats_scene *sc) {
  struct lagr_config c;
  if (!config_of(sc, &c)) return 0.0;
  const double nl = c.n_levels, nlag = c.n_lags + 1.0, nst = c.n_stations ? c.n_stations : 1;
  const double slots = ceil(c.horizon / c.release_every - 1e-9) + 1.0;
  const double span = sc->t_end - c.t_start - c.horizon;
  const double releases = span > 0.0 && isfinite(span) ? floor(span / c.release_every) + 1.0 : 0.0;
  return 2.0 * sizeof(double) *
         (nl * nlag * LG_LEN * (1.0 + slots) + slots * SL_LEN + nl * 3 * SCAL_LEN +
          nl * nst * (c.pdf_bins + 3.0) + releases * (nl * 3.0 + 1.0));
}

STATS_ENGINE_ADAPTERS(lagr)

static size_t engine_bytes(const void *self) {
  const struct lagr *g = self;
  const size_t d = sizeof(double);
  const size_t nl = (size_t)g->cfg.n_levels, ns = (size_t)g->n_slots;
  const size_t nst = (size_t)(g->cfg.n_stations ? g->cfg.n_stations : 1);
  return nl * g->nlag * LG_LEN * d * (1 + ns) + ns * SL_LEN * d + nl * 3 * SCAL_LEN * d +
         nl * LF_LEN * g->nlag * SCAL_LEN * d + ns * slot_pdf_len(g) * d +
         nl * nst * ((size_t)g->cfg.pdf_bins + 2) * SCAL_LEN * d +
         nl * nst * ((size_t)g->cfg.pdf_bins + 3) * d + g->cap * TR_LEN * d +
         g->index_len * sizeof(long) + (g->mine_cap + g->all_cap) * LAGR_REC * d +
         g->rel_cap * (nl * 3 + 1) * d;
}

static int engine_write(const void *self, double t_reached, int ncid, char *err, size_t errlen) {
  (void)t_reached;
  return lagr_nc_write(self, ncid, err, errlen);
}

static int engine_warnings(const void *self, char *buf, size_t len) {
  return lagr_warnings(self, buf, len);
}

const struct stats_engine lagr_engine = {.name = "Lagrangian statistics",
                                         .keys = keys,
                                         .n_keys = sizeof keys / sizeof keys[0],
                                         .size = sizeof(struct lagr),
                                         .init_scene = engine_init_scene,
                                         .estimate = engine_estimate,
                                         .init = engine_init,
                                         .free = engine_free,
                                         .sample = engine_sample,
                                         .close = NULL,
                                         .state = engine_state,
                                         .bytes = engine_bytes,
                                         .write = engine_write,
                                         .warnings = engine_warnings,
                                         .log = NULL};
