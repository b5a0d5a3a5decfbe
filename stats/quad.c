/** @file quad.c @brief Implementation of quad.h. */
#include "quad.h"
#include "engine.h"
#include "ncutil.h"

#include <math.h>
#include <netcdf.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "moments.h"
#include "ncout.h"
#include "spar.h"
#include "state.h"

void quad_init(struct quad *q, const struct quad_config *cfg) {
  memset(q, 0, sizeof *q);
  q->cfg = *cfg;
  if (cfg->n_levels <= 0) return;
  q->acc = mem_calloc((size_t)cfg->n_levels * QS_LEN, sizeof(double), "quadrant engine");
  q->samples = mem_calloc((size_t)cfg->n_levels, sizeof(double), "quadrant engine");
  q->win = mem_calloc((size_t)cfg->n_levels * (QS_LEN + 1), sizeof(double), "quadrant engine");
  q->batch =
      mem_calloc((size_t)cfg->n_levels * QB_LEN * SCAL_LEN, sizeof(double), "quadrant engine");
  q->win_end = cfg->window > 0.0 ? cfg->t_start + cfg->window : INFINITY;
}

void quad_free(struct quad *q) {
  free(q->acc), free(q->samples), free(q->ent), free(q->all), free(q->win), free(q->batch);
  memset(q, 0, sizeof *q);
}

/* The planes of a snapshot: each level, and its mirror (v -> -v) if the slabs do not overlap. */
static int planes(const struct quad_config *c, int lev[], int mir[], double yp[]) {
  int npl = 0;
  for (int l = 0; l < c->n_levels; l++) {
    const double yl = c->y[l], ym = 2.0 * c->delta - yl;
    lev[npl] = l, mir[npl] = 0, yp[npl++] = yl;
    if (fabs(ym - yl) >= 2.0 * c->half) lev[npl] = l, mir[npl] = 1, yp[npl++] = ym;
  }
  return npl;
}

/* Per (local column, plane) partial sums, QS_LEN slots, of this rank's slab particles, each
   column's particles in memory order (m = NULL: u, v and the count in slots 0-2; else the
   quadrant slots about the plane means m[plane][2]); gathered to every rank in column order,
   then summed over the columns in that order into out[plane][QS_LEN]. */
static void plane_sums(struct quad *q, const struct stats_snapshot *s, struct spar *par, int npl,
                       const int mir[], const double yp[], const double *m, double *out) {
  const size_t ncl = (size_t)(par->col1 - par->col0), rec = (size_t)npl * QS_LEN;
  q->rec = rec;
  if (ncl * rec > q->ent_cap) {
    q->ent_cap = ncl * rec;
    q->ent = mem_realloc(q->ent, q->ent_cap, sizeof(double), "quadrant engine");
  }
  memset(q->ent, 0, ncl * rec * sizeof(double));
  spar_chain_begin(par, q->ent, ncl * rec); /* planes cut: the columns' sums from below */
  for (size_t a = 0; a < s->n; a++) {
    if (s->skip && s->skip[a]) continue;
    for (int pl = 0; pl < npl; pl++) {
      if (fabs(s->y[a] - yp[pl]) >= q->cfg.half) continue;
      double *e = q->ent + (size_t)spar_lcol(par, s, a) * rec + (size_t)pl * QS_LEN;
      const double u = s->u[a], v = mir[pl] ? -s->v[a] : s->v[a];
      if (!m) {
        e[0] += u, e[1] += v, e[2] += 1.0;
        continue;
      }
      const double du = u - m[2 * pl], dv = v - m[2 * pl + 1];
      const int k = dv >= 0.0 ? (du >= 0.0 ? 0 : 1) : (du < 0.0 ? 2 : 3); /* Q1 .. Q4 */
      e[QS_UV + k] += du * dv, e[QS_N + k] += 1.0;
    }
  }
  spar_chain_end(par, q->ent, ncl * rec);
  const size_t ncol = spar_gather_row(par, q->ent, ncl, rec, &q->all, &q->all_cap);
  memset(out, 0, rec * sizeof(double));
  for (size_t c = 0; c < ncol; c++)
    for (size_t i = 0; i < rec; i++) out[i] += q->all[c * rec + i];
}

/* The results of one level's sums a (QS_LEN): uv, share, time of Q1..Q4 into r[QB_LEN]. */
static void level_results(const double *a, double *r) {
  const double n = a[QS_N] + a[QS_N + 1] + a[QS_N + 2] + a[QS_N + 3];
  const double tot = a[QS_UV] + a[QS_UV + 1] + a[QS_UV + 2] + a[QS_UV + 3];
  for (int k = 0; k < 4; k++) {
    r[QB_UV + k] = n > 0 ? a[QS_UV + k] / n : NAN;
    r[QB_SHARE + k] = n > 0 && tot != 0.0 ? a[QS_UV + k] / tot : NAN;
    r[QB_TIME + k] = n > 0 ? a[QS_N + k] / n : NAN;
  }
}

/* Close the open window when a snapshot at t lies past its end (the windows of the Eulerian
   engine: t_start + k window): its values per level become one batch each; an empty window
   is no batch. */
static void close_window(struct quad *q, double t) {
  const struct quad_config *c = &q->cfg;
  if (t < q->win_end) return;
  for (int l = 0; l < c->n_levels; l++) {
    double *w = q->win + (size_t)l * (QS_LEN + 1), r[QB_LEN];
    if (w[QS_LEN] > 0.0) {
      level_results(w, r);
      for (int k = 0; k < QB_LEN; k++)
        if (isfinite(r[k])) scal_add(q->batch + ((size_t)l * QB_LEN + (size_t)k) * SCAL_LEN, r[k]);
    }
    memset(w, 0, (QS_LEN + 1) * sizeof(double));
  }
  q->win_end = c->t_start + c->window * (floor((t - c->t_start) / c->window) + 1.0);
  if (q->win_end <= t) q->win_end += c->window; /* rounding */
}

void quad_close(struct quad *q, double t) {
  if (q->cfg.n_levels > 0 && t >= q->cfg.t_start) close_window(q, t);
}

void quad_sample(struct quad *q, const struct stats_snapshot *s) {
  if (q->cfg.n_levels <= 0 || s->t < q->cfg.t_start) return;
  close_window(q, s->t);
  int lev[2 * QUAD_MAX_LEVELS] = {0}, mir[2 * QUAD_MAX_LEVELS] = {0};
  double yp[2 * QUAD_MAX_LEVELS] = {0}, mean[2 * 2 * QUAD_MAX_LEVELS] = {0};
  double s0[QS_LEN * 2 * QUAD_MAX_LEVELS], s1[QS_LEN * 2 * QUAD_MAX_LEVELS];
  const int npl = planes(&q->cfg, lev, mir, yp);
  struct spar par;
  spar_open(&par, s);
  plane_sums(q, s, &par, npl, mir, yp, NULL, s0); /* the plane means of this instant */
  for (int pl = 0; pl < npl; pl++) {
    const double *t = s0 + QS_LEN * pl, n = t[2];
    mean[2 * pl] = n > 0 ? t[0] / n : 0.0, mean[2 * pl + 1] = n > 0 ? t[1] / n : 0.0;
  }
  plane_sums(q, s, &par, npl, mir, yp, mean, s1);
  spar_close(&par);
  for (int pl = 0; pl < npl; pl++) {
    if (!(s0[QS_LEN * pl + 2] > 0)) continue;
    double *acc = q->acc + (size_t)lev[pl] * QS_LEN;
    double *w = q->win + (size_t)lev[pl] * (QS_LEN + 1);
    for (int k = 0; k < QS_LEN; k++) acc[k] += s1[QS_LEN * pl + k], w[k] += s1[QS_LEN * pl + k];
    q->samples[lev[pl]] += 1.0, w[QS_LEN] += 1.0;
  }
}

void quad_state(struct quad *q, struct state_list *L) {
  if (q->cfg.n_levels <= 0) return;
  const size_t d2[2] = {(size_t)q->cfg.n_levels, QS_LEN}, d1[1] = {d2[0]};
  state_add(L, "stats/quadrants/sums", STATE_F64, 2, d2, q->acc, NULL);
  state_add(L, "stats/quadrants/samples", STATE_F64, 1, d1, q->samples, NULL);
  /* format 1.12: the window batches; a checkpoint without them resumes with none, and the
     window open at the resume becomes a batch of its snapshots after the resume only */
  const size_t dw[2] = {d2[0], QS_LEN + 1}, db[3] = {d2[0], QB_LEN, SCAL_LEN};
  state_add(L, "stats/quadrants/window", STATE_F64, 2, dw, q->win, NULL)->optional = 1;
  state_add(L, "stats/quadrants/window_end", STATE_F64, 0, NULL, &q->win_end, "s")->optional = 1;
  state_add(L, "stats/quadrants/batches", STATE_F64, 3, db, q->batch, NULL)->optional = 1;
}

/* [level][4] from the sums: each quadrant's part of <u'v'> (sum over the quadrant / all
   samples), its share of the whole u'v', and its share of the samples. */
static void quad_results(const struct quad *q, double *uv, double *share, double *time) {
  for (int l = 0; l < q->cfg.n_levels; l++) {
    double r[QB_LEN];
    level_results(q->acc + (size_t)l * QS_LEN, r);
    for (int k = 0; k < 4; k++)
      uv[4 * l + k] = r[QB_UV + k], share[4 * l + k] = r[QB_SHARE + k],
                 time[4 * l + k] = r[QB_TIME + k];
  }
}

/* The batch-means standard errors of uv, uv_fraction and time_fraction (as quad_results) and
   the complete windows of each level. */
static void quad_stderr(const struct quad *q, double *se, double *nwin) {
  const size_t nl = (size_t)q->cfg.n_levels;
  for (size_t l = 0; l < nl; l++) {
    nwin[l] = q->batch[l * QB_LEN * SCAL_LEN + SCAL_N];
    for (int k = 0; k < QB_LEN; k++) {
      const double *W = q->batch + (l * QB_LEN + (size_t)k) * SCAL_LEN;
      se[(size_t)(k / 4) * 4 * nl + 4 * l + (size_t)(k % 4)] =
          W[SCAL_N] >= 2.0 ? sqrt(W[SCAL_M2] / (W[SCAL_N] - 1.0) / W[SCAL_N]) : NAN;
    }
  }
}

/* The labels of the batch values (QB_*) and of the slots of a Welford record (SCAL_*). */
static const char *const batch_label[QB_LEN] = {"uv_Q1",
                                                "uv_Q2",
                                                "uv_Q3",
                                                "uv_Q4",
                                                "uv_fraction_Q1",
                                                "uv_fraction_Q2",
                                                "uv_fraction_Q3",
                                                "uv_fraction_Q4",
                                                "time_fraction_Q1",
                                                "time_fraction_Q2",
                                                "time_fraction_Q3",
                                                "time_fraction_Q4"};
static const char *const welford_label[SCAL_LEN] = {"n", "mean", "M2"};

/* The raw Welford records of the closed windows' values, [level][batch_value][welford_slot]
   (q->batch as the engine keeps it): what chansph extract pools when it joins segments. */
static int write_raw_batches(const struct quad *q, int g, int dl, char *err, size_t errlen) {
  int rc = NC_NOERR, d[3] = {dl, 0, 0}, v;
  NC_TRY(nc_def_dim(g, "batch_value", QB_LEN, &d[1]), done);
  NC_TRY(
      ncout_labels(g, "batch_value", d[1], "value of an averaging window (a batch)", batch_label),
      done);
  NC_TRY(nc_def_dim(g, "welford_slot", SCAL_LEN, &d[2]), done);
  NC_TRY(ncout_labels(g, "welford_slot", d[2], "slot of a Welford record: count, mean, M2",
                      welford_label),
         done);
  NC_TRY(ncout_def(g, "batch_welford", NC_DOUBLE, 3, d, NULL, /* mixed record: no units */
                   "raw Welford records (count, mean, sum of squared deviations M2) over the "
                   "complete averaging windows of each window's uv, uv_fraction and "
                   "time_fraction: the batches of the *_stderr",
                   &v),
         done);
  NC_TRY(nc_put_var_double(g, v, q->batch), done);
done:
  return rc;
}

int quad_nc_write(const struct quad *q, int ncid, char *err, size_t errlen) {
  const size_t nl = (size_t)q->cfg.n_levels;
  double *r = mem_alloc(6 * 4 * nl + nl, sizeof(double), "quadrants"), *se = r + 12 * nl;
  int rc = NC_NOERR, g, dl, dq, d2[2], d3[2], v;
  quad_results(q, r, r + 4 * nl, r + 8 * nl);
  quad_stderr(q, se, se + 12 * nl);
  NC_TRY(nc_def_grp(ncid, "quadrants", &g), done);
  static const char desc[] =
      "quadrant analysis of u'v' (Wallace et al. 1972, Willmarth & Lu 1972): fluctuations about "
      "the plane average of each instant in a slab of one dr at each level and its mirror "
      "(v -> -v); quadrant 1..4 = Q1 (u'>0, v'>0), Q2 ejections (u'<0, v'>0), Q3 (u'<0, v'<0), "
      "Q4 sweeps (u'>0, v'<0)";
  NC_TRY(nc_put_att_text(g, NC_GLOBAL, "description", strlen(desc), desc), done);
  NC_TRY(nc_def_dim(g, "level", nl, &dl), done);
  NC_TRY(nc_def_dim(g, "quadrant", 4, &dq), done);
  static const char *const qlab[4] = {"Q1_outward", "Q2_ejection", "Q3_inward", "Q4_sweep"};
  NC_TRY(ncout_labels(g, "quadrant", dq, "quadrant of (u', v')", qlab), done);
  NC_TRY(
      ncout_def(g, "level", NC_DOUBLE, 1, &dl, "m", "height of the plane above the lower wall", &v),
      done);
  NC_TRY(nc_put_var_double(g, v, q->cfg.y), done);
  NC_TRY(
      ncout_def(g, "y_plus", NC_DOUBLE, 1, &dl, "1", "level in wall units of stats.u_tau_ref", &v),
      done);
  NC_TRY(nc_put_var_double(g, v, q->cfg.y_plus), done);
  NC_TRY(ncout_def(g, "samples", NC_DOUBLE, 1, &dl, "1", "planes accumulated", &v), done);
  NC_TRY(nc_put_var_double(g, v, q->samples), done);
  d2[0] = d3[0] = dl, d2[1] = dq;
  static const char *const name[3] = {"uv", "uv_fraction", "time_fraction"};
  static const char *const units[3] = {"m^2/s^2", "1", "1"};
  static const char *const lname[3] = {
      "part of <u'v'> from each quadrant (the four add up to <u'v'>)",
      "share of u'v' carried by each quadrant (the four add up to 1)",
      "share of the samples in each quadrant"};
  for (int k = 0; k < 3; k++) {
    NC_TRY(ncout_def(g, name[k], NC_DOUBLE, 2, d2, units[k], lname[k], &v), done);
    NC_TRY(ncout_fill(g, v), done); /* a level without samples: _FillValue, never NaN */
    NC_TRY(ncout_put_filled(g, v, NULL, NULL, r + (size_t)k * 4 * nl, 4 * nl), done);
    char sname[32], slname[160];
    snprintf(sname, sizeof sname, "%s_stderr", name[k]);
    snprintf(slname, sizeof slname,
             "standard error of %s (batch means over the complete averaging windows)", name[k]);
    NC_TRY(ncout_def(g, sname, NC_DOUBLE, 2, d2, units[k], slname, &v), done);
    NC_TRY(ncout_fill(g, v), done);
    NC_TRY(ncout_put_filled(g, v, NULL, NULL, se + (size_t)k * 4 * nl, 4 * nl), done);
  }
  NC_TRY(ncout_def(g, "n_batches", NC_DOUBLE, 1, &dl, "1",
                   "complete averaging windows with planes at the level: the batches of the "
                   "*_stderr",
                   &v),
         done);
  NC_TRY(nc_put_var_double(g, v, se + 12 * nl), done);
  NC_TRY(nc_put_att_double(g, NC_GLOBAL, "window_length", NC_DOUBLE, 1, &q->cfg.window), done);
  d3[1] = 0; /* the raw sums, re-averageable: [level][u'v' Q1..Q4, count Q1..Q4] */
  {
    int ds;
    NC_TRY(nc_def_dim(g, "sum_slot", QS_LEN, &ds), done);
    static const char *const slab[QS_LEN] = {"uv_Q1", "uv_Q2", "uv_Q3", "uv_Q4",
                                             "n_Q1",  "n_Q2",  "n_Q3",  "n_Q4"};
    NC_TRY(ncout_labels(g, "sum_slot", ds, "slot of the raw sums", slab), done);
    d3[1] = ds;
    NC_TRY(ncout_def(g, "sums", NC_DOUBLE, 2, d3, NULL, /* mixed record: no units */
                     "raw sums over the planes: u'v' of Q1..Q4 [m^2/s^2], then the sample counts "
                     "of Q1..Q4",
                     &v),
           done);
    NC_TRY(nc_put_var_double(g, v, q->acc), done);
  }
  NC_TRY(write_raw_batches(q, g, dl, err, errlen), done);
done:
  free(r);
  return rc;
}

int quad_nc_read(struct quad *q, int ncid, char *err, size_t errlen) {
  struct quad_config c;
  int g, d;
  size_t nl = 0;
  memset(q, 0, sizeof *q), memset(&c, 0, sizeof c);
  if (nc_inq_ncid(ncid, "quadrants", &g) != NC_NOERR) {
    snprintf(err, errlen, "no group 'quadrants'");
    return 1;
  }
  if (nc_inq_dimid(g, "level", &d) || nc_inq_dimlen(g, d, &nl) || nl < 1 || nl > QUAD_MAX_LEVELS ||
      ncout_get_raw(g, "level", nl, c.y) || ncout_get_raw(g, "y_plus", nl, c.y_plus) ||
      nc_get_att_double(g, NC_GLOBAL, "window_length", &c.window) ||
      nc_get_att_double(ncid, NC_GLOBAL, "delta", &c.delta)) {
    snprintf(err, errlen, "group 'quadrants' has no levels or no window_length");
    return -1;
  }
  c.n_levels = (int)nl;
  quad_init(q, &c);
  if (ncout_get_raw(g, "sums", nl * QS_LEN, q->acc) ||
      ncout_get_raw(g, "samples", nl, q->samples) ||
      ncout_get_raw(g, "batch_welford", nl * QB_LEN * SCAL_LEN, q->batch)) {
    snprintf(err, errlen,
             "group 'quadrants' has no raw sums and window batches (batch_welford: written "
             "before stats.nc held them)");
    quad_free(q);
    return 2;
  }
  return 0;
}

int quad_join(struct quad *q, const struct quad *b, char *why, size_t len) {
  const struct quad_config *x = &q->cfg, *y = &b->cfg;
  int same = x->n_levels == y->n_levels && x->window == y->window;
  for (int l = 0; same && l < x->n_levels; l++) same = x->y_plus[l] == y->y_plus[l];
  if (!same) {
    snprintf(why, len, "other levels (quadrants.y_plus) or window length");
    return 1;
  }
  const size_t nl = (size_t)x->n_levels;
  for (size_t i = 0; i < nl * QS_LEN; i++) q->acc[i] += b->acc[i];
  for (size_t l = 0; l < nl; l++) q->samples[l] += b->samples[l];
  for (size_t i = 0; i < nl * QB_LEN; i++)
    scal_merge(q->batch + i * SCAL_LEN, b->batch + i * SCAL_LEN);
  return 0;
}

/* The engine's scene key, section [quadrants] (docs/scenes.md is generated from it). */
static const struct scene_key_def key_y_plus = {
    .section = "quadrants",
    .name = "y_plus",
    .type = SCENE_LIST,
    .def = "",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .flags = SCENE_Y_PLUS,
    .unit = "-",
    .help =
        "Comma-separated y+ levels (up to 8) of the quadrant analysis of u'v' (Wallace et al. "
        "1972, Willmarth & Lu 1972): in a slab of one dr at each level and its mirror, the "
        "fluctuations about the plane average of each instant sorted into Q1 (outward), Q2 "
        "(ejections), Q3 (inward) and Q4 (sweeps); stats.nc group quadrants "
        "(docs/stats-format.md). "
        "Ejections and sweeps dominate in wall turbulence, not in particle noise. Empty = off."};
static const struct scene_key_def *const keys[] = {&key_y_plus};

/* The engine's table of operations (engine.h). */
static int engine_init_scene(void *self, const struct stats_scene *sc) {
  struct quad_config c;
  memset(&c, 0, sizeof c);
  c.n_levels = stats_scene_levels(sc, &key_y_plus, c.y_plus, c.y, QUAD_MAX_LEVELS);
  c.half = 0.5 * sc->dr, c.delta = sc->delta, c.t_start = sc->t_average_start;
  c.window = sc->window;
  if (!(c.n_levels > 0)) return 0;
  quad_init(self, &c);
  return 1;
}

STATS_ENGINE_ADAPTERS(quad)

static void engine_close(void *self, double t) {
  quad_close(self, t);
}

static size_t engine_bytes(const void *self) {
  const struct quad *q = self;
  return ((size_t)q->cfg.n_levels * (2 * QS_LEN + 2 + QB_LEN * SCAL_LEN) + q->ent_cap +
          q->all_cap * q->rec) *
         sizeof(double);
}

static int engine_write(const void *self, double t_reached, int ncid, char *err, size_t errlen) {
  (void)t_reached;
  return quad_nc_write(self, ncid, err, errlen);
}

const struct stats_engine quad_engine = {.name = "quadrant analysis",
                                         .keys = keys,
                                         .n_keys = sizeof keys / sizeof keys[0],
                                         .size = sizeof(struct quad),
                                         .init_scene = engine_init_scene,
                                         .init = engine_init,
                                         .free = engine_free,
                                         .sample = engine_sample,
                                         .close = engine_close,
                                         .state = engine_state,
                                         .bytes = engine_bytes,
                                         .write = engine_write,
                                         .warnings = NULL,
                                         .log = NULL};
