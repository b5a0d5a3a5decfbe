/** @file pdf.c @brief Implementation of pdf.h: accumulation, checkpoint state, results and
 *         warnings (the stats.nc writer and reader and the engine's table are in pdf_nc.c). */
#include "pdf.h"
#include "contract.h"

#include <math.h>
#include <mpi.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "spar.h"
#include "state.h"
#include "timers.h"

const double pdf_lo[PDF_COMP] = {-10.0, -10.0, -10.0};
const double pdf_hi[PDF_COMP] = {35.0, 10.0, 10.0};

void pdf_init(struct pdf *p, const struct pdf_config *cfg) {
  memset(p, 0, sizeof *p);
  p->cfg = *cfg;
  if (cfg->n_levels <= 0) return;
  if (!(cfg->fine > 0.0) || !(cfg->u_tau > 0.0) || cfg->bins < 1 || cfg->bins > PDF_MAX_BINS ||
      !(cfg->range > 0.0) || !(cfg->window > 0.0))
    die("PDF engine: bad configuration (fine %g, u_tau %g, bins %d, range %g, window %g)",
        cfg->fine, cfg->u_tau, cfg->bins, cfg->range, cfg->window);
  for (int c = 0; c < PDF_COMP; c++) {
    p->nf[c] = (int)ceil((pdf_hi[c] - pdf_lo[c]) / cfg->fine - 1e-9);
    p->nfine += (size_t)p->nf[c];
  }
  pdf_reserve(p, 1);
  p->win[PW_T0] = cfg->t_start, p->win[PW_T1] = cfg->t_start + cfg->window;
}

void pdf_free(struct pdf *p) {
  free(p->win), free(p->pow), free(p->hist), free(p->ent), free(p->all), free(p->cnt);
  memset(p, 0, sizeof *p);
}

void pdf_reserve(struct pdf *p, size_t rows) {
  if (rows <= p->cap) return;
  const size_t old = p->cap, cap = rows > 2 * old ? rows : 2 * old;
  const size_t nl = (size_t)p->cfg.n_levels, npow = nl * PDF_COMP * PDF_POW;
  p->win = mem_realloc(p->win, cap * PW_LEN, sizeof(double), "PDF engine");
  p->pow = mem_realloc(p->pow, cap * npow, sizeof(double), "PDF engine");
  p->hist = mem_realloc(p->hist, cap * nl * p->nfine, sizeof(double), "PDF engine");
  memset(p->win + old * PW_LEN, 0, (cap - old) * PW_LEN * sizeof(double));
  memset(p->pow + old * npow, 0, (cap - old) * npow * sizeof(double));
  memset(p->hist + old * nl * p->nfine, 0, (cap - old) * nl * p->nfine * sizeof(double));
  p->cap = cap;
}

/* Move the open window forward to the one holding time t: a window with snapshots is closed
   and the next one opened at its end; an empty one just moves by one window length. */
static void pdf_advance(struct pdf *p, double t) {
  while (t >= p->win[p->nwin * PW_LEN + PW_T1]) {
    const double *w = p->win + p->nwin * PW_LEN;
    const double t1 = w[PW_T1];
    if (w[PW_NSNAP] > 0.0) {
      pdf_reserve(p, ++p->nwin + 1);
    }
    double *o = p->win + p->nwin * PW_LEN;
    o[PW_T0] = t1, o[PW_T1] = t1 + p->cfg.window;
  }
}

/* The fine bin of x in component c (the end bins take what lies beyond). */
static size_t fine_bin(const struct pdf *p, int c, double x) {
  const double k = floor((x - pdf_lo[c]) / p->cfg.fine);
  return k < 0.0 ? 0 : k >= p->nf[c] ? (size_t)p->nf[c] - 1 : (size_t)k;
}

/* Grow the scratch of a snapshot: ncl column records of rec doubles, and the counts. */
static void pdf_scratch(struct pdf *p, size_t ncl, size_t npl) {
  p->rec = npl * PDF_COMP * PDF_POW;
  if (ncl * p->rec > p->ent_cap) {
    p->ent_cap = ncl * p->rec;
    p->ent = mem_realloc(p->ent, p->ent_cap, sizeof(double), "PDF engine");
  }
  if (npl * p->nfine > p->cnt_cap) {
    p->cnt_cap = npl * p->nfine;
    p->cnt = mem_realloc(p->cnt, p->cnt_cap, sizeof(double), "PDF engine");
  }
  memset(p->ent, 0, ncl * p->rec * sizeof(double));
  memset(p->cnt, 0, npl * p->nfine * sizeof(double));
}

/* Add particle a's velocity (v -> -v on a mirror plane) to plane pl: its column's power sums
   e and the plane's fine counts. */
static void pdf_add_particle(struct pdf *p, const struct stats_snapshot *s, size_t a, size_t pl,
                             int mirror, double *e) {
  const double x[PDF_COMP] = {s->u[a] / p->cfg.u_tau, (mirror ? -s->v[a] : s->v[a]) / p->cfg.u_tau,
                              s->w[a] / p->cfg.u_tau};
  double *cnt = p->cnt + pl * p->nfine;
  size_t off = 0;
  for (int c = 0; c < PDF_COMP; c++) {
    double *q = e + (pl * PDF_COMP + (size_t)c) * PDF_POW;
    const double x2 = x[c] * x[c];
    q[0] += 1.0, q[1] += x[c], q[2] += x2, q[3] += x2 * x[c], q[4] += x2 * x2;
    cnt[off + fine_bin(p, c, x[c])] += 1.0;
    off += (size_t)p->nf[c];
  }
}

/* Planes of level l: 2 l (the level) and 2 l + 1 (its mirror 2 delta - y, if the two slabs do
   not overlap). Per (local column, plane) power sums of the slab particles in memory order,
   gathered in column order and added in that order into sums[plane][PDF_COMP][PDF_POW]; the
   fine counts of each plane summed over the ranks (exact: integers). */
static void pdf_snapshot(struct pdf *p, const struct stats_snapshot *s, double *sums) {
  const struct pdf_config *c = &p->cfg;
  const size_t npl = 2 * (size_t)c->n_levels;
  struct spar par;
  spar_open(&par, s);
  const size_t ncl = (size_t)(par.col1 - par.col0);
  pdf_scratch(p, ncl, npl);
  spar_chain_begin(&par, p->ent, ncl * p->rec); /* planes cut: the columns' sums from below */
  for (size_t a = 0; a < s->n; a++) {
    if (s->skip && s->skip[a]) continue;
    double *e = p->ent + (size_t)spar_lcol(&par, s, a) * p->rec;
    for (int l = 0; l < c->n_levels; l++) {
      const double ym = 2.0 * c->delta - c->y[l];
      if (fabs(s->y[a] - c->y[l]) < c->half) pdf_add_particle(p, s, a, 2 * (size_t)l, 0, e);
      if (fabs(ym - c->y[l]) >= 2.0 * c->half && fabs(s->y[a] - ym) < c->half)
        pdf_add_particle(p, s, a, 2 * (size_t)l + 1, 1, e);
    }
  }
  spar_chain_end(&par, p->ent, ncl * p->rec);
  const size_t ncol = spar_gather_row(&par, p->ent, ncl, p->rec, &p->all, &p->all_cap);
  memset(sums, 0, p->rec * sizeof(double));
  for (size_t k = 0; k < ncol; k++)
    for (size_t i = 0; i < p->rec; i++) sums[i] += p->all[k * p->rec + i];
  if (par.size > 1)
    CHECK_MPI(
        MPI_Allreduce(MPI_IN_PLACE, p->cnt, (int)(npl * p->nfine), MPI_DOUBLE, MPI_SUM, par.comm));
  spar_close(&par);
}

void pdf_close(struct pdf *p, double t) {
  if (p->cfg.n_levels > 0 && t >= p->cfg.t_start) pdf_advance(p, t);
}

void pdf_sample(struct pdf *p, const struct stats_snapshot *s) {
  if (p->cfg.n_levels <= 0 || s->t < p->cfg.t_start) return;
  timer_push("stats: pdfs"); /* its own line of the phase report: the engine's overhead */
  pdf_advance(p, s->t);
  double sums[2 * PDF_MAX_LEVELS * PDF_COMP * PDF_POW];
  pdf_snapshot(p, s, sums);
  const size_t nl = (size_t)p->cfg.n_levels, lp = PDF_COMP * PDF_POW, row = p->nwin;
  for (size_t pl = 0; pl < 2 * nl; pl++) {
    double *pw = p->pow + (row * nl + pl / 2) * lp, *h = p->hist + (row * nl + pl / 2) * p->nfine;
    for (size_t k = 0; k < lp; k++) pw[k] += sums[pl * lp + k];
    for (size_t k = 0; k < p->nfine; k++) h[k] += p->cnt[pl * p->nfine + k];
  }
  p->win[row * PW_LEN + PW_NSNAP] += 1.0;
  timer_pop();
}

size_t pdf_rows(const struct pdf *p) {
  if (p->cfg.n_levels <= 0) return 0;
  return p->nwin + (p->win[p->nwin * PW_LEN + PW_NSNAP] > 0.0);
}

/* Checkpoint reading: make room for the stored rows (the open window is the last). */
static void *reserve_rows(struct pdf *p, int rank, const size_t *dims, size_t len, double **a) {
  if (rank < 2 || dims[0] < 1 || dims[rank - 1] != len) return NULL;
  pdf_reserve(p, dims[0]);
  p->nwin = dims[0] - 1;
  return *a;
}

static void *reserve_win(void *owner, int rank, const size_t *dims) {
  struct pdf *p = owner;
  return rank == 2 ? reserve_rows(p, rank, dims, PW_LEN, &p->win) : NULL;
}

static void *reserve_pow(void *owner, int rank, const size_t *dims) {
  struct pdf *p = owner;
  if (rank != 3 || dims[1] != (size_t)p->cfg.n_levels * PDF_COMP) return NULL;
  return reserve_rows(p, rank, dims, PDF_POW, &p->pow);
}

static void *reserve_hist(void *owner, int rank, const size_t *dims) {
  struct pdf *p = owner;
  if (rank != 3 || dims[1] != (size_t)p->cfg.n_levels) return NULL;
  return reserve_rows(p, rank, dims, p->nfine, &p->hist);
}

void pdf_state(struct pdf *p, struct state_list *L) {
  if (p->cfg.n_levels <= 0) return;
  const size_t rows = p->nwin + 1, nl = (size_t)p->cfg.n_levels;
  const size_t dw[2] = {rows, PW_LEN}, dp[3] = {rows, nl * PDF_COMP, PDF_POW};
  const size_t dh[3] = {rows, nl, p->nfine};
  /* optional: a checkpoint written without the engine resumes with it switched on */
  struct state_field *f = state_add(L, "stats/pdfs/windows", STATE_F64, 2, dw, p->win, "s");
  f->reserve = reserve_win, f->owner = p, f->optional = 1;
  f = state_add(L, "stats/pdfs/power_sums", STATE_F64, 3, dp, p->pow, NULL);
  f->reserve = reserve_pow, f->owner = p, f->optional = 1;
  f = state_add(L, "stats/pdfs/fine_counts", STATE_F64, 3, dh, p->hist, NULL);
  f->reserve = reserve_hist, f->owner = p, f->optional = 1;
}

/* Mean, standard deviation, skewness and flatness of power sums S[0..4] (NaN if empty). */
static void moments_of(const double *S, double m[4]) {
  const double n = S[0];
  if (!(n > 0.0)) {
    m[0] = m[1] = m[2] = m[3] = NAN;
    return;
  }
  const double a = S[1] / n, b = S[2] / n, c = S[3] / n, d = S[4] / n;
  const double c2 = b - a * a, c3 = c - 3.0 * a * b + 2.0 * a * a * a;
  const double c4 = d - 4.0 * a * c + 6.0 * a * a * b - 3.0 * a * a * a * a;
  const double sd = c2 > 0.0 ? sqrt(c2) : 0.0;
  m[0] = a, m[1] = sd;
  m[2] = sd > 0.0 ? c3 / (sd * sd * sd) : NAN;
  m[3] = sd > 0.0 ? c4 / (c2 * c2) : NAN;
}

/* Rebin the fine counts h of component c onto the PDF bins pc (added) in units of sd about
   mean (both in u_tau), each fine bin shared in proportion to its overlap; returns the count
   that falls beyond +-range. */
static double rebin(const struct pdf *p, int c, const double *h, double mean, double sd,
                    double *pc) {
  const double R = p->cfg.range, db = 2.0 * R / p->cfg.bins, fw = p->cfg.fine / sd;
  double out = 0.0;
  for (int i = 0; i < p->nf[c]; i++) {
    if (h[i] == 0.0) continue;
    const double xa = (pdf_lo[c] + i * p->cfg.fine - mean) / sd, xb = xa + fw;
    double inside = 0.0;
    const int j0 = (int)floor((xa + R) / db), j1 = (int)floor((xb + R) / db);
    for (int j = j0 < 0 ? 0 : j0; j <= j1 && j < p->cfg.bins; j++) {
      const double lo = fmax(xa, -R + j * db), hi = fmin(xb, -R + (j + 1) * db);
      if (hi <= lo) continue;
      const double share = h[i] * (hi - lo) / fw;
      pc[j] += share, inside += share;
    }
    out += h[i] - inside;
  }
  return out;
}

/* The PDF p (bins) of one row range's counts h of component c with n samples. */
static double pdf_of(const struct pdf *p, int c, const double *h, double n, double mean, double sd,
                     double *pd) {
  const double db = 2.0 * p->cfg.range / p->cfg.bins;
  memset(pd, 0, (size_t)p->cfg.bins * sizeof(double));
  if (!(n > 0.0) || !(sd > 0.0)) {
    for (int j = 0; j < p->cfg.bins; j++) pd[j] = NAN;
    return NAN;
  }
  const double out = fmax(rebin(p, c, h, mean, sd, pd), 0.0); /* not below 0 by rounding */
  for (int j = 0; j < p->cfg.bins; j++) pd[j] /= n * db;
  return out / n;
}

static void result_alloc(struct pdf_result *r, size_t nl, size_t bins) {
  memset(r, 0, sizeof *r);
  const size_t nc = nl * PDF_COMP;
  r->n = mem_calloc(nl, sizeof(double), "PDF results");
  r->mom = mem_calloc(nc * 4, sizeof(double), "PDF results");
  r->mom_err = mem_calloc(nc * 4, sizeof(double), "PDF results");
  r->p = mem_calloc(nc * bins, sizeof(double), "PDF results");
  r->p_err = mem_calloc(nc * bins, sizeof(double), "PDF results");
  r->outside = mem_calloc(nc, sizeof(double), "PDF results");
  r->clipped = mem_calloc(nc, sizeof(double), "PDF results");
  r->bin_centres = mem_calloc(bins, sizeof(double), "PDF results");
}

void pdf_result_free(struct pdf_result *r) {
  free(r->n), free(r->mom), free(r->mom_err), free(r->p), free(r->p_err), free(r->outside);
  free(r->clipped), free(r->bin_centres);
  memset(r, 0, sizeof *r);
}

/* Batch-means standard error from the sums s1, s2 of nb batch values (NaN if nb < 2). */
static double batch_err(double s1, double s2, int nb) {
  if (nb < 2) return NAN;
  const double var = (s2 - s1 * s1 / nb) / (nb - 1);
  return var > 0.0 ? sqrt(var / nb) : 0.0;
}

/* Standard errors of level l, component c over the complete windows of rows r0 .. r1-1 with
   samples at the level: each window's moments and PDF (about the range's mean m and rms sd)
   are one batch value. */
static void batch_errors(const struct pdf *p, size_t r0, size_t r1, size_t l, int c, double m,
                         double sd, double *mom_err, double *p_err) {
  const size_t nl = (size_t)p->cfg.n_levels, B = (size_t)p->cfg.bins;
  double s[8] = {0}, *pd = mem_alloc(3 * B, sizeof(double), "PDF results"), *ps = pd + B;
  double *ps2 = ps + B;
  memset(ps, 0, 2 * B * sizeof(double));
  size_t off = 0;
  for (int k = 0; k < c; k++) off += (size_t)p->nf[k];
  int nb = 0;
  for (size_t r = r0; r < r1 && r < p->nwin; r++) {
    const double *S = p->pow + ((r * nl + l) * PDF_COMP + (size_t)c) * PDF_POW;
    if (!(S[0] > 0.0)) continue; /* no sample at this level in the window: no batch */
    double w[4];
    nb++;
    moments_of(S, w);
    for (int k = 0; k < 4; k++) s[k] += w[k], s[4 + k] += w[k] * w[k];
    pdf_of(p, c, p->hist + (r * nl + l) * p->nfine + off, S[0], m, sd, pd);
    for (size_t j = 0; j < B; j++) ps[j] += pd[j], ps2[j] += pd[j] * pd[j];
  }
  for (int k = 0; k < 4; k++) mom_err[k] = batch_err(s[k], s[4 + k], nb);
  mom_err[0] *= p->cfg.u_tau, mom_err[1] *= p->cfg.u_tau;
  for (size_t j = 0; j < B; j++) p_err[j] = batch_err(ps[j], ps2[j], nb);
  free(pd);
}

/* Level l, component c of a result over rows r0 .. r1-1. */
static void level_result(const struct pdf *p, size_t r0, size_t r1, size_t l, int c,
                         struct pdf_result *r) {
  const size_t nl = (size_t)p->cfg.n_levels, B = (size_t)p->cfg.bins, lc = l * PDF_COMP + c;
  double S[PDF_POW] = {0}, *h = mem_calloc((size_t)p->nfine, sizeof(double), "PDF results");
  size_t off = 0;
  for (int k = 0; k < c; k++) off += (size_t)p->nf[k];
  for (size_t row = r0; row < r1; row++) {
    const double *src = p->pow + (row * nl + l) * PDF_COMP * PDF_POW + (size_t)c * PDF_POW;
    for (int k = 0; k < PDF_POW; k++) S[k] += src[k];
    for (int i = 0; i < p->nf[c]; i++) h[i] += p->hist[(row * nl + l) * p->nfine + off + i];
  }
  double m[4];
  moments_of(S, m);
  r->n[l] = S[0];
  for (int k = 0; k < 4; k++) r->mom[lc * 4 + k] = k < 2 ? m[k] * p->cfg.u_tau : m[k];
  r->outside[lc] = pdf_of(p, c, h, S[0], m[0], m[1], r->p + lc * B);
  r->clipped[lc] = S[0] > 0.0 ? (h[0] + h[p->nf[c] - 1]) / S[0] : NAN;
  batch_errors(p, r0, r1, l, c, m[0], m[1], r->mom_err + lc * 4, r->p_err + lc * B);
  free(h);
}

void pdf_finalise(const struct pdf *p, size_t r0, size_t r1, struct pdf_result *r) {
  const size_t nl = (size_t)p->cfg.n_levels, B = (size_t)p->cfg.bins;
  result_alloc(r, nl ? nl : 1, B ? B : 1);
  const double db = 2.0 * p->cfg.range / p->cfg.bins;
  for (size_t j = 0; j < B; j++) r->bin_centres[j] = -p->cfg.range + (j + 0.5) * db;
  r->n_batches = (int)((r1 < p->nwin ? r1 : p->nwin) - (r0 < p->nwin ? r0 : p->nwin));
  r->t0 = r1 > r0 ? p->win[r0 * PW_LEN + PW_T0] : NAN;
  r->t1 = r1 > r0 ? p->win[(r1 - 1) * PW_LEN + PW_T1] : NAN;
  for (size_t row = r0; row < r1; row++) r->snapshots += p->win[row * PW_LEN + PW_NSNAP];
  for (size_t l = 0; l < nl; l++)
    for (int c = 0; c < PDF_COMP; c++) level_result(p, r0, r1, l, c, r);
}

/* Power sums and end-bin counts of level l, component c over every row with data. */
static void level_totals(const struct pdf *p, size_t l, int c, double S[PDF_POW], double *ends) {
  const size_t nl = (size_t)p->cfg.n_levels;
  size_t off = 0;
  for (int k = 0; k < c; k++) off += (size_t)p->nf[k];
  memset(S, 0, PDF_POW * sizeof(double));
  *ends = 0.0;
  for (size_t r = 0; r < pdf_rows(p); r++) {
    const double *src = p->pow + ((r * nl + l) * PDF_COMP + (size_t)c) * PDF_POW;
    const double *h = p->hist + (r * nl + l) * p->nfine + off;
    for (int k = 0; k < PDF_POW; k++) S[k] += src[k];
    *ends += h[0] + h[p->nf[c] - 1];
  }
}

int pdf_warnings(const struct pdf *p, char *buf, size_t len) {
  static const char comp[PDF_COMP] = {'u', 'v', 'w'};
  const double db = 2.0 * p->cfg.range / p->cfg.bins;
  int n = 0;
  size_t m = 0;
  buf[0] = '\0';
  for (int l = 0; l < p->cfg.n_levels && m < len; l++)
    for (int c = 0; c < PDF_COMP && m < len; c++) {
      double S[PDF_POW], ends, mo[4];
      level_totals(p, (size_t)l, c, S, &ends);
      moments_of(S, mo);
      const double wide = p->cfg.fine / mo[1] / db, clip = S[0] > 0.0 ? ends / S[0] : 0.0;
      if (!(mo[1] > 0.0) || (wide <= 0.5 && clip <= 1e-4)) continue;
      m += (size_t)snprintf(buf + m, len - m,
                            "warning: pdfs y+ = %g %c: a fine bin is %.3g PDF bins wide, %.3g of "
                            "the samples lie at the ends of the fine grid: decrease pdfs.fine "
                            "(or check stats.u_tau_ref)\n",
                            p->cfg.y_plus[l], comp[c], wide, clip);
      n++;
    }
  return n;
}
