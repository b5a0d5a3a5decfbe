/** @file stats.c @brief Implementation of stats.h. */
#include "stats.h"
#include "ncutil.h"

#include <math.h>
#include <netcdf.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "moments.h"
#include "ncout.h"
#include "state.h"

void stats_init(struct stats *st, const struct stats_config *cfg) {
  memset(st, 0, sizeof *st);
  st->cfg = *cfg;
  st->t_reached = NAN;
  if (cfg->eulerian) euler_init(&st->eu, &cfg->eul);
  if (cfg->corr.n_levels) corr_init(&st->co, &cfg->corr);
  if (cfg->lagr.n_levels) lagr_init(&st->la, &cfg->lagr);
}

void stats_free(struct stats *st) {
  if (st->cfg.eulerian) euler_free(&st->eu);
  if (st->cfg.corr.n_levels) corr_free(&st->co);
  if (st->cfg.lagr.n_levels) lagr_free(&st->la);
  memset(st, 0, sizeof *st);
}

int stats_wanted(const struct stats *st) {
  return st->cfg.eulerian || st->cfg.corr.n_levels > 0 || st->cfg.lagr.n_levels > 0;
}

void stats_sample(struct stats *st, const struct stats_snapshot *s) {
  if (st->cfg.eulerian) euler_sample(&st->eu, s);
  if (st->cfg.corr.n_levels) corr_sample(&st->co, s);
  if (st->cfg.lagr.n_levels) lagr_sample(&st->la, s);
  st->samples++;
}

void stats_state(struct stats *st, struct state_list *L) {
  state_add(L, "stats/samples", STATE_I64, 0, NULL, &st->samples, NULL);
  if (st->cfg.eulerian) euler_state(&st->eu, L);
  if (st->cfg.corr.n_levels) corr_state(&st->co, L);
  if (st->cfg.lagr.n_levels) lagr_state(&st->la, L);
}

size_t stats_memory(const struct stats *st) {
  const size_t d = sizeof(double);
  size_t b = 0;
  if (st->cfg.eulerian) {
    const size_t nb = (size_t)st->eu.cfg.nb;
    b += st->eu.cap * (WIN_LEN + nb * (MOM_LEN + SCAL_LEN)) * d + euler_work_bytes(&st->eu);
  }
  if (st->cfg.corr.n_levels) {
    const struct corr *c = &st->co;
    const size_t nk = (size_t)c->cfg.nx * (size_t)c->nzh, np = (size_t)c->cfg.nx * c->cfg.nz;
    b += (size_t)c->cfg.n_levels * (nk * CS_LEN + 2) * d + 4 * np * d + 3 * nk * 2 * d +
         (c->ent_cap + c->all_cap) * CORR_ENT * d + c->hits_cap * (4 * d + sizeof(size_t));
  }
  if (st->cfg.lagr.n_levels) {
    const struct lagr *g = &st->la;
    const size_t nl = (size_t)g->cfg.n_levels, ns = (size_t)g->n_slots;
    const size_t nst = (size_t)(g->cfg.n_stations ? g->cfg.n_stations : 1);
    b += nl * g->nlag * LG_LEN * d * (1 + ns) + ns * SL_LEN * d + nl * 3 * SCAL_LEN * d +
         nl * nst * ((size_t)g->cfg.pdf_bins + 3) * d + g->cap * TR_LEN * d +
         g->index_len * sizeof(long) + (g->mine_cap + g->all_cap) * LAGR_REC * d;
  }
  return b;
}

/* The running result: every row with data; closed windows are the batches. */
static void eulerian_result(const struct euler *e, struct euler_result *res) {
  const size_t rows = euler_rows(e);
  int *complete = calloc(rows ? rows : 1, sizeof *complete);
  for (size_t r = 0; r < rows; r++) complete[r] = r < e->nwin;
  euler_finalise(&e->cfg, e->win, e->mom, e->snp, e->pln, complete, 0, rows, res);
  free(complete);
}

void stats_progress(const struct stats *st, const struct stats_target *tg,
                    struct stats_progress *p) {
  memset(p, 0, sizeof *p);
  p->rel_u = p->rel_uv = p->worst = p->ratio = p->windows_needed = p->t_reach = NAN;
  if (!st->cfg.eulerian || euler_rows(&st->eu) == 0) return;
  struct euler_result r;
  eulerian_result(&st->eu, &r);
  double se = 0.0, umax = 0.0, uv = 0.0, se_uv = NAN;
  for (int b = 0; b < r.nb; b++) {
    if (isfinite(r.prof[EP_SE_U][b])) se = fmax(se, r.prof[EP_SE_U][b]);
    if (isfinite(r.prof[EP_U][b])) umax = fmax(umax, fabs(r.prof[EP_U][b]));
    if (isfinite(r.prof[EP_UV][b]) && fabs(r.prof[EP_UV][b]) > uv)
      uv = fabs(r.prof[EP_UV][b]), se_uv = r.prof[EP_SE_U + 8][b]; /* stderr of uv */
  }
  p->windows = r.n_batches;
  const double win = st->cfg.eul.window;
  p->ratio = win / r.corr_time;
  if (r.n_batches >= 2) {
    p->rel_u = umax > 0.0 ? se / umax : NAN;
    p->rel_uv = uv > 0.0 ? se_uv / uv : NAN;
    p->worst = tg->profiles == 1   ? p->rel_u
               : tg->profiles == 2 ? p->rel_uv
                                   : fmax(p->rel_u, p->rel_uv);
    if (tg->profiles == 0 && (isnan(p->rel_u) || isnan(p->rel_uv))) p->worst = NAN;
  }
  if (isfinite(p->worst)) {
    const double q = p->worst / tg->rel_stderr;
    p->windows_needed = fmax((double)tg->windows, ceil(r.n_batches * q * q));
    p->t_reach = st->eu.win[WIN_T0] + p->windows_needed * win;
  }
  p->met = r.n_batches >= tg->windows && isfinite(p->worst) && p->worst <= tg->rel_stderr &&
           (tg->corr_ratio <= 0.0 || p->ratio >= tg->corr_ratio);
  euler_result_free(&r);
}

void stats_turbulence(const struct euler_config *c, const struct euler_result *r,
                      struct stats_turb *t) {
  const double ut = r->u_tau > 0.0 ? r->u_tau : r->u_tau_force, ut2 = ut * ut;
  t->uv_peak = t->y_peak = t->r_uv = t->pair_share = t->resolved_share = NAN;
  double rsum = 0.0, best = INFINITY;
  int rn = 0;
  for (int b = 0; b < r->nb; b++) {
    const double y = r->prof[EP_Y_MEAN][b], up = !c->fold && y > c->delta;
    const double yp = (up ? 2.0 * c->delta - y : y) * ut / c->nu;
    const double muv = (up ? 1.0 : -1.0) * r->prof[EP_UV][b]; /* -u'v' towards the centre */
    if (!isfinite(muv) || !(ut2 > 0.0)) continue;
    if (!(muv / ut2 <= t->uv_peak)) t->uv_peak = muv / ut2, t->y_peak = yp;
    const double rms = sqrt(r->prof[EP_UU][b] * r->prof[EP_VV][b]);
    if (yp >= 30.0 && yp <= 100.0 && rms > 0.0) rsum += muv / rms, rn++;
    const double tot = r->prof[EP_TOTAL][b];
    if (r->budget && fabs(yp - 30.0) < best && fabs(tot) > 0.0) { /* the bin nearest y+ = 30 */
      best = fabs(yp - 30.0);
      t->pair_share = r->prof[EP_TAU_PAIR][b] / tot;
      t->resolved_share = r->prof[EP_TAU_REYNOLDS][b] / tot;
    }
  }
  if (rn) t->r_uv = rsum / rn;
}

void stats_convergence_line(const struct stats *st, char *buf, size_t len) {
  buf[0] = '\0';
  if (!st->cfg.eulerian || euler_rows(&st->eu) == 0) return;
  struct euler_result r;
  eulerian_result(&st->eu, &r);
  double se = 0.0, umax = 0.0;
  for (int b = 0; b < r.nb; b++) {
    if (isfinite(r.prof[EP_SE_U][b])) se = fmax(se, r.prof[EP_SE_U][b]);
    if (isfinite(r.prof[EP_U][b])) umax = fmax(umax, fabs(r.prof[EP_U][b]));
  }
  const double win = st->cfg.eul.window;
  snprintf(buf, len,
           "stats: %d complete windows of %.4g s, %.0f snapshots; correlation time %.3g s "
           "(window/corr %.3g); max stderr(u_mean) %.3g m/s (%.3g%% of max u_mean); "
           "u_tau wall %.6g force %.6g; stress balance error %.3g%s\n",
           r.n_batches, win, r.snapshots, r.corr_time, win / r.corr_time, se,
           umax > 0 ? 100 * se / umax : NAN, r.u_tau_wall, r.u_tau_force, r.balance_error,
           r.n_batches < 2           ? " (fewer than 2 windows: no error bars yet)"
           : win < 5.0 * r.corr_time ? " (windows shorter than 5 correlation times: error bars "
                                       "too small; increase stats.window)"
                                     : "");
  /* is it turbulent? the -u'v' peak and R_uv of the last window, the budget's split at y+ 30 */
  struct stats_turb all, last;
  stats_turbulence(&st->cfg.eul, &r, &all);
  euler_result_free(&r);
  const struct euler *e = &st->eu;
  const size_t rows = euler_rows(e), r0 = e->nwin > 0 ? e->nwin - 1 : 0; /* last complete */
  int *complete = mem_alloc(rows, sizeof(int), "Eulerian statistics");
  for (size_t w = 0; w < rows; w++) complete[w] = w < e->nwin;
  euler_finalise(&e->cfg, e->win, e->mom, e->snp, e->pln, complete, r0, r0 + 1, &r);
  stats_turbulence(&st->cfg.eul, &r, &last);
  euler_result_free(&r);
  free(complete);
  const size_t used = strlen(buf);
  if (used > 0 && used < len) buf[used - 1] = ';';
  snprintf(buf + used, len - used,
           " turbulence (last window): -u'v'+ peak %.3g at y+ %.3g, R_uv(30<y+<100) %.3g; "
           "average -u'v'+ peak %.3g; stress at y+ 30: resolved %.0f%%, pair (numerical) "
           "%.0f%%\n",
           last.uv_peak, last.y_peak, last.r_uv, all.uv_peak, 100.0 * all.resolved_share,
           100.0 * all.pair_share);
}

#define CK(call) NC_TRY(call, fail)

static int put_att_d(int ncid, int var, const char *name, double v) {
  return nc_put_att_double(ncid, var, name, NC_DOUBLE, 1, &v);
}

int stats_warnings(const struct stats *st, char *buf, size_t len) {
  buf[0] = '\0';
  return st->cfg.lagr.n_levels ? lagr_warnings(&st->la, buf, len) : 0;
}

/* The limits of the wall-normal bins: uniform between cfg->y0 and y1, the first reaching down to
   the wall and the last up to the other wall (the centre when folded), as the samples outside
   [y0, y1] go to the end bins. */
static void bin_bounds(const struct euler_config *c, double *lo, double *hi) {
  const double w = (c->y1 - c->y0) / c->nb;
  for (int b = 0; b < c->nb; b++) {
    lo[b] = b == 0 ? 0.0 : c->y0 + b * w;
    hi[b] = b == c->nb - 1 ? (c->fold ? 1.0 : 2.0) * c->delta : c->y0 + (b + 1) * w;
  }
}

/* The bin coordinate y (centres, with bounds) on dimension dy of group ncid. */
static int def_y(const struct euler_config *c, int ncid, int dy, const double *centre,
                 const double *lo, const double *hi) {
  int v, rc = ncout_def(ncid, "y", NC_DOUBLE, 1, &dy, "m", euler_prof_meta[EP_Y].long_name, &v);
  if (rc == NC_NOERR) rc = nc_put_att_text(ncid, v, "axis", 1, "Y");
  if (rc == NC_NOERR)
    rc =
        ncout_bounds(ncid, "y", v, dy, "m", "wall-normal limits of the bin", lo, hi, (size_t)c->nb);
  if (rc == NC_NOERR) rc = nc_put_var_double(ncid, v, centre);
  return rc;
}

static const char *const window_fields[WIN_LEN] = {
    [WIN_T0] = "t_start",     [WIN_T1] = "t_end",           [WIN_NSNAP] = "snapshots",
    [WIN_SUM_FX] = "sum_f_x", [WIN_SUM_TW0] = "sum_tau_w0", [WIN_SUM_TW1] = "sum_tau_w1"};
static const char *const moment_names[MOM_LEN] = {
    "count",     "mean_u",   "mean_v", "mean_w", "mean_p", "mean_rho", "mean_y",
    "mean_nu_t", "mean_k_r", "C2_uu",  "C2_vv",  "C2_ww",  "C2_uv",    "C2_uw",
    "C2_vw",     "M3_u",     "M3_v",   "M3_w",   "M4_u",   "M4_v",     "M4_w"};
static const char *const scal_names[SCAL_LEN] = {"count", "mean", "M2"};
static const char *const plane_names[PL_LEN] = {
    [PL_N] = "snapshots",           [PL_PRESSURE] = "sum_pair_stress",
    [PL_VISCOUS] = "sum_viscous",   [PL_MODEL] = "sum_model",
    [PL_WALL] = "sum_wall",         [PL_DRIVE] = "sum_drive",
    [PL_SOURCE] = "sum_source",     [PL_MU_FIRST] = "momentum_first",
    [PL_MU_LAST] = "momentum_last", [PL_T_FIRST] = "time_first",
    [PL_T_LAST] = "time_last"};

/* The root's profiles on dimension dy and the run's scalars as global attributes; t_reached:
   the time the run reached (NaN: not known), where an incomplete last window ends. */
static int write_profiles(const struct euler *e, const struct euler_result *rp, double t_reached,
                          int ncid, int dy, char *err, size_t errlen) {
  const struct euler_result r = *rp;
  const size_t nb = (size_t)e->cfg.nb;
  int rc = NC_NOERR, vid;
  for (int k = 0; k < EP_NPROF; k++) {
    const int model = k == EP_NUT || k == EP_KR || k == EP_TAU_MODEL || k == EP_SE_TAU + 2;
    if (k == EP_Y || (model && !e->cfg.les)) continue;
    const struct euler_meta *m = &euler_prof_meta[k];
    CK(ncout_def(ncid, m->name, NC_DOUBLE, 1, &dy, m->units, m->long_name, &vid));
    CK(ncout_fill(ncid, vid));
    CK(ncout_put_filled(ncid, vid, NULL, NULL, r.prof[k], nb));
  }
  const struct {
    const char *name;
    double v;
    int integer; /* a count or flag: int64 */
  } scal[] = {{"u_tau", r.u_tau, 0},
              {"u_tau_stderr", r.u_tau_stderr, 0},
              {"u_tau_wall", r.u_tau_wall, 0},
              {"u_tau_force", r.u_tau_force, 0},
              {"re_tau", r.re_tau, 0},
              {"correlation_time", r.corr_time, 0},
              {"stress_balance_error", r.balance_error, 0},
              {"average_start", r.t0, 0},
              {"average_end", isnan(t_reached) ? r.t1 : fmin(r.t1, t_reached), 0},
              {"n_windows", (double)r.n_batches, 1},
              {"window_length", e->cfg.window, 0},
              {"bin_lower", e->cfg.y0, 0},
              {"bin_upper", e->cfg.y1, 0},
              {"wall_area", e->cfg.area, 0},
              {"fold", (double)e->cfg.fold, 1},
              {"les", (double)e->cfg.les, 1}};
  for (size_t i = 0; i < sizeof scal / sizeof scal[0]; i++)
    if (scal[i].integer) {
      const long long v = (long long)scal[i].v;
      CK(nc_put_att_longlong(ncid, NC_GLOBAL, scal[i].name, NC_INT64, 1, &v));
    } else {
      CK(put_att_d(ncid, NC_GLOBAL, scal[i].name, scal[i].v));
    }
  return NC_NOERR;
fail:
  return rc ? rc : NC_EINVAL;
}

/* The coordinate variable of the windows: their middle times, with start and end as bounds. */
static int def_window_axis(const struct euler *e, int g, int dw, char *err, size_t errlen) {
  const size_t rows = euler_rows(e);
  int rc = NC_NOERR;
  double *mid = malloc(3 * (rows ? rows : 1) * sizeof *mid), *t0 = mid + rows, *t1 = t0 + rows;
  if (!mid) CK(NC_ENOMEM);
  for (size_t w = 0; w < rows; w++) {
    t0[w] = e->win[w * WIN_LEN + WIN_T0], t1[w] = e->win[w * WIN_LEN + WIN_T1];
    mid[w] = 0.5 * (t0[w] + t1[w]);
  }
  int vt;
  rc = ncout_def(g, "window", NC_DOUBLE, 1, &dw, "s", "middle of the averaging window", &vt);
  if (rc == NC_NOERR)
    rc =
        ncout_bounds(g, "window", vt, dw, "s", "nominal start and end of the window", t0, t1, rows);
  if (rc == NC_NOERR && rows) rc = nc_put_var_double(g, vt, mid);
  free(mid);
  CK(rc);
  return NC_NOERR;
fail:
  return rc ? rc : NC_EINVAL;
}

/* The group eulerian: the raw per-window records (the complete accumulator state, which
   chansph extract re-averages), with a coordinate variable for every dimension. */
static int write_raw_windows(const struct euler *e, const struct euler_result *rp, int ncid,
                             const double *lo, const double *hi, char *err, size_t errlen) {
  const struct euler_result r = *rp;
  const size_t nb = (size_t)e->cfg.nb, rows = euler_rows(e);
  int rc = NC_NOERR, dy;
  int g, dw, dwf, dm, ds, dp, vw, vm, vs, vp, vc, v0, v1;
  CK(nc_def_grp(ncid, "eulerian", &g));
  static const char desc[] =
      "raw per-window moment records of the wall-normal bins; re-average any range of windows "
      "with chansph extract --window T0:T1 (docs/stats-format.md)";
  CK(nc_put_att_text(g, NC_GLOBAL, "description", strlen(desc), desc));
  /* every dimension of the group has its coordinate variable here, so that xarray's
     open_dataset(group="eulerian") has labelled axes: the bins again (a dimension y of the
     group, the same as the root's), the windows by their middle time (bounds: start, end) and
     the fields of the records by name */
  CK(nc_def_dim(g, "window", rows, &dw));
  CK(nc_def_dim(g, "y", nb, &dy));
  CK(nc_def_dim(g, "window_field", WIN_LEN, &dwf));
  CK(nc_def_dim(g, "moment", MOM_LEN, &dm));
  CK(nc_def_dim(g, "snapshot_moment", SCAL_LEN, &ds));
  CK(nc_def_dim(g, "plane_field", PL_LEN, &dp));
  CK(def_y(&e->cfg, g, dy, r.prof[EP_Y], lo, hi));
  if ((rc = def_window_axis(e, g, dw, err, errlen)) != NC_NOERR) goto fail; /* names its call */
  CK(ncout_labels(g, "window_field", dwf, "fields of the window records", window_fields));
  CK(ncout_labels(g, "moment", dm,
                  "fields of the moment records: count, means, co-moments C2 (sums of products "
                  "of deviations), third and fourth central moments M3, M4 (sums)",
                  moment_names));
  CK(ncout_labels(g, "snapshot_moment", ds,
                  "fields of the records of per-snapshot bin means of u: count, mean, M2",
                  scal_names));
  CK(ncout_labels(g, "plane_field", dp, "fields of the momentum-budget records", plane_names));
  CK(ncout_def(g, "window_start", NC_DOUBLE, 1, &dw, "s", "start of the averaging window", &v0));
  CK(ncout_def(g, "window_end", NC_DOUBLE, 1, &dw, "s", "end of the averaging window", &v1));
  CK(ncout_def(g, "window_complete", NC_INT, 1, &dw, "1", "1: closed window, 0: still open", &vc));
  const int d2[2] = {dw, dwf}, d3m[3] = {dw, dy, dm}, d3s[3] = {dw, dy, ds}, d3p[3] = {dw, dy, dp};
  CK(ncout_def(g, "windows", NC_DOUBLE, 2, d2, NULL,
               "per window: t_start [s], t_end [s], snapshots, sum of body force [m/s^2], sums "
               "of tau_w/rho at y=0 and y=2delta [m^2/s^2]",
               &vw));
  CK(ncout_def(g, "moments", NC_DOUBLE, 3, d3m, NULL,
               "per window and bin: count, means of u v w p rho y nu_t k_r, co-moments uu vv ww "
               "uv uw vw, third and fourth central moments of u v w (sums, not divided by count)",
               &vm));
  CK(ncout_def(g, "snapshot_u", NC_DOUBLE, 3, d3s, NULL,
               "per window and bin: count, mean and M2 of the per-snapshot bin means of u", &vs));
  CK(ncout_def(g, "planes", NC_DOUBLE, 3, d3p, NULL,
               "per window and plane y (bin centre): snapshots with forces, sums over them of the "
               "momentum flux through the plane by the pressure, viscous and eddy-viscous pair "
               "forces and the walls, of the body force it balances and of the momentum source, "
               "per unit area and rho0 [m^2/s^2] (docs/stats-format.md, momentum budget)",
               &vp));
  for (size_t w = 0; w < rows; w++) {
    const size_t st[1] = {w}, ct[1] = {1};
    const int cpl = w < e->nwin;
    CK(nc_put_vara_double(g, v0, st, ct, &e->win[w * WIN_LEN + WIN_T0]));
    CK(nc_put_vara_double(g, v1, st, ct, &e->win[w * WIN_LEN + WIN_T1]));
    CK(nc_put_vara_int(g, vc, st, ct, &cpl));
  }
  if (rows) {
    CK(nc_put_var_double(g, vw, e->win));
    CK(nc_put_var_double(g, vm, e->mom));
    CK(nc_put_var_double(g, vs, e->snp));
    CK(nc_put_var_double(g, vp, e->pln));
  }
  return NC_NOERR;
fail:
  return rc ? rc : NC_EINVAL;
}

/* t_reached: the time the run reached (NaN: not known); an incomplete last window ends there. */
static int write_eulerian(const struct euler *e, double t_reached, int ncid, char *err,
                          size_t errlen) {
  int rc = NC_NOERR, dy;
  struct euler_result r;
  eulerian_result(e, &r);
  const size_t nb = (size_t)e->cfg.nb;
  double *lo = malloc(2 * nb * sizeof *lo), *hi = lo + nb;
  if (!lo) return NC_ENOMEM;
  bin_bounds(&e->cfg, lo, hi);
  CK(nc_def_dim(ncid, "y", nb, &dy));
  CK(def_y(&e->cfg, ncid, dy, r.prof[EP_Y], lo, hi));
  /* each names its own failing call in err */
  if ((rc = write_profiles(e, &r, t_reached, ncid, dy, err, errlen)) != NC_NOERR ||
      (rc = write_raw_windows(e, &r, ncid, lo, hi, err, errlen)) != NC_NOERR)
    goto fail;
  euler_result_free(&r);
  free(lo);
  return NC_NOERR;
fail:
  euler_result_free(&r);
  free(lo);
  return rc ? rc : NC_EINVAL;
}

int stats_nc_write(const struct stats *st, int ncid, char *err, size_t errlen) {
  if (st->cfg.eulerian) {
    const int rc = write_eulerian(&st->eu, st->t_reached, ncid, err, errlen);
    if (rc) return rc;
  }
  if (st->cfg.corr.n_levels) {
    const int rc = corr_nc_write(&st->co, ncid, err, errlen);
    if (rc) return rc;
  }
  if (st->cfg.lagr.n_levels) {
    const int rc = lagr_nc_write(&st->la, ncid, err, errlen);
    if (rc) return rc;
  }
  return NC_NOERR;
}
