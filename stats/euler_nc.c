/**
 * @file euler_nc.c
 * @brief The Eulerian engine's stats.nc writer (root profiles with units and standard errors,
 *        the run's scalars, the raw per-window records in group eulerian) and its table of
 *        operations (engine.h).
 */
#include <math.h>
#include <netcdf.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "engine.h"
#include "euler.h"
#include "euler_rs.h"
#include "moments.h"
#include "ncout.h"
#include "ncutil.h"

#define CK(call) NC_TRY(call, fail)

static int put_att_d(int ncid, int var, const char *name, double v) {
  return nc_put_att_double(ncid, var, name, NC_DOUBLE, 1, &v);
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
  const char *name = c->fold ? "wall-normal bin centre, folded: distance from the nearer wall "
                               "(wall at 0, centre at delta; y > delta mirrored)"
                             : euler_prof_meta[EP_Y].long_name;
  int v, rc = ncout_def(ncid, "y", NC_DOUBLE, 1, &dy, "m", name, &v);
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
    "count", "mean_u", "mean_v", "mean_w", "mean_p", "mean_rho", "mean_y", "mean_nu_t", "mean_k_r",
    "C2_uu", "C2_vv",  "C2_ww",  "C2_uv",  "C2_uw",  "C2_vw",    "M3_u",   "M3_v",      "M3_w",
    "M4_u",  "M4_v",   "M4_w",   "C2_uy",  "C2_vy",  "C2_wy",    "C2_yy"};
static const char *const scal_names[SCAL_LEN] = {"count", "mean", "M2"};
static const char *const plane_names[PL_LEN] = {
    [PL_N] = "snapshots",           [PL_PRESSURE] = "sum_pair_stress",
    [PL_VISCOUS] = "sum_viscous",   [PL_MODEL] = "sum_model",
    [PL_WALL] = "sum_wall",         [PL_DRIVE] = "sum_drive",
    [PL_SOURCE] = "sum_source",     [PL_MU_FIRST] = "momentum_first",
    [PL_MU_LAST] = "momentum_last", [PL_T_FIRST] = "time_first",
    [PL_T_LAST] = "time_last"};
static const char *const kinetic_names[KN_LEN] = {
    [KN_N] = "snapshots",         [KN_SUM] = "sum_kinetic",     [KN_FIRST] = "first_recorded",
    [KN_F] = "first_pair_stress", [KN_F + 1] = "first_viscous", [KN_F + 2] = "first_model",
    [KN_F + 3] = "first_wall",    [KN_F + 4] = "first_drive",   [KN_F_KINETIC] = "first_kinetic"};

int euler_nc_read_moments(int g, int var, size_t records, double *mom) {
  int nd, dims[NC_MAX_VAR_DIMS];
  size_t width = 0;
  if (nc_inq_varndims(g, var, &nd) || nd != 3 || nc_inq_vardimid(g, var, dims) ||
      nc_inq_dimlen(g, dims[2], &width) || (width != MOM_LEN && width != MOM_LEN_1_11))
    return NC_EINVAL;
  const int rc = nc_get_var_double(g, var, mom);
  if (rc == NC_NOERR) euler_widen_moments(mom, records, width);
  return rc;
}

/* The root's profiles on dimension dy and the run's scalars as global attributes; t_reached:
   the time the run reached (NaN: not known), where an incomplete last window ends. */
static int write_profiles(const struct euler *e, const struct euler_result *rp, double t_reached,
                          int ncid, int dy, char *err, size_t errlen) {
  const struct euler_result r = *rp;
  const size_t nb = (size_t)e->cfg.nb;
  int rc = NC_NOERR, vid;
  for (int k = 0; k < EP_NPROF; k++) {
    const int rs = k >= EP_RSB && k < EP_RSB_SE_END, rt = (k - EP_RSB) % RS_NTERM;
    const int model = k == EP_NUT || k == EP_KR || k == EP_TAU_MODEL || k == EP_SE_TAU + 2 ||
                      (rs && rt == RT_MODEL);
    if (k == EP_Y || (model && !e->cfg.les) || (rs && !r.rs_budget)) continue;
    const struct euler_meta *m = &euler_prof_meta[k];
    CK(ncout_def(ncid, m->name, NC_DOUBLE, 1, &dy, m->units, m->long_name, &vid));
    CK(ncout_fill(ncid, vid));
    CK(ncout_put_filled(ncid, vid, NULL, NULL, r.prof[k], nb));
  }
  const struct {
    const char *name;
    double v;
    int integer; /* a count or flag: int64 */
  } scal[] = {
      {"u_tau", r.u_tau, 0},
      {"u_tau_stderr", r.u_tau_stderr, 0},
      {"u_tau_wall", r.u_tau_wall, 0},
      {"u_tau_force", r.u_tau_force, 0},
      {"re_tau", r.re_tau, 0},
      {"correlation_time", r.corr_time, 0},
      {"n_eff_windows", r.n_eff, 0},
      {"short_windows", isfinite(r.corr_time) ? (double)(e->cfg.window < r.corr_time) : NAN, 1},
      {"local_mean", (double)r.local_mean, 1},
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
    if (scal[i].integer && isfinite(scal[i].v)) {
      const long long v = (long long)scal[i].v;
      CK(nc_put_att_longlong(ncid, NC_GLOBAL, scal[i].name, NC_INT64, 1, &v));
    } else if (!scal[i].integer && isfinite(scal[i].v)) { /* not known: absent */
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
  double *mid = mem_alloc(1, 3 * (rows ? rows : 1) * sizeof *mid, "Eulerian statistics"),
         *t0 = mid + rows, *t1 = t0 + rows;
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

/* The field dimensions of the raw records of group g with their labels: fd = window_field,
   moment, snapshot_moment, plane_field, kinetic_field, reynolds_budget_field. */
static int field_axes(int g, int fd[6], char *err, size_t errlen) {
  int rc = NC_NOERR;
  const char *rs_names[RW_LEN];
  for (int k = 0; k < RW_LEN; k++) rs_names[k] = euler_rs_field_name(k);
  const struct {
    const char *dim;
    size_t len;
    const char *long_name;
    const char *const *labels;
  } ax[6] = {
      {"window_field", WIN_LEN, "fields of the window records", window_fields},
      {"moment", MOM_LEN,
       "fields of the moment records: count, means, co-moments C2 (sums of products of "
       "deviations), third and fourth central moments M3, M4 (sums), co-moments of u, v, w and "
       "y with y (from checkpoint format 1.12 on)",
       moment_names},
      {"snapshot_moment", SCAL_LEN,
       "fields of the records of per-snapshot bin means of u: count, mean, M2", scal_names},
      {"plane_field", PL_LEN, "fields of the momentum-budget records", plane_names},
      {"kinetic_field", KN_LEN, "fields of the kinetic-flux records", kinetic_names},
      {"reynolds_budget_field", RW_LEN, "fields of the Reynolds-stress budget records", rs_names}};
  for (int k = 0; k < 6; k++) {
    CK(nc_def_dim(g, ax[k].dim, ax[k].len, &fd[k]));
    CK(ncout_labels(g, ax[k].dim, fd[k], ax[k].long_name, ax[k].labels));
  }
  return NC_NOERR;
fail:
  return rc ? rc : NC_EINVAL;
}

/* The per-bin records of group g (window dw, y dy, their fields fd of field_axes): the moments
   and the budgets' sums of every window. */
static int write_records(const struct euler *e, int g, int dw, int dy, const int *fd, char *err,
                         size_t errlen) {
  int rc = NC_NOERR;
  const int dm = fd[1], ds = fd[2], dp = fd[3], dk = fd[4], dr = fd[5];
  const struct {
    const char *name;
    int field; /* its dimension of fields */
    const double *data;
    const char *long_name;
  } rec[] = {
      {"moments", dm, e->mom,
       "per window and bin: count, means of u v w p rho y nu_t k_r, co-moments uu vv ww uv uw "
       "vw, third and fourth central moments of u v w (sums, not divided by count)"},
      {"snapshot_u", ds, e->snp,
       "per window and bin: count, mean and M2 of the per-snapshot bin means of u"},
      {"planes", dp, e->pln,
       "per window and plane y (bin centre): snapshots with forces, sums over them of the "
       "momentum flux through the plane by the pressure, viscous and eddy-viscous pair forces "
       "and the walls, of the body force it balances and of the momentum source, per unit area "
       "and rho0 [m^2/s^2] (docs/stats-format.md, momentum budget)"},
      {"planes_kinetic", dk, e->kin,
       "per window and bin: snapshots with forces and the sum over them of the particles' "
       "kinetic flux through the bin's planes, -(sum of m u v over the bin) / (rho0 A w) "
       "[m^2/s^2]; then 1 and the window's first snapshot's values of the planes fields "
       "sum_pair_stress .. sum_drive and of the kinetic flux (docs/stats-format.md, momentum "
       "budget)"},
      {"reynolds_budget", dr, e->rsb,
       "per window and bin: the sums behind the Reynolds-stress budgets, all samples and the "
       "window's first apart, weighted by the time since the previous sample: mass, m ub_i A_j "
       "and m A_j of each part of the acceleration, the quantities m (1, u_i, u_i u_j) the "
       "displacements carried in; the state's quantities at the first and last sample and "
       "their times (docs/stats-format.md, Reynolds-stress budgets)"},
      {"planes_total", dp, e->tpl,
       "per window and plane: the planes record of every snapshot (not only those with the "
       "budget's parts) with the flux of all the forces in sum_pair_stress and zero in the "
       "other parts' fields: total_stress_all and momentum_change_all (docs/stats-format.md, "
       "momentum budget)"},
      {"planes_total_kinetic", dk, e->tkn,
       "per window and bin: the planes_kinetic record of every snapshot, with planes_total "
       "(docs/stats-format.md, momentum budget)"}};
  enum { NREC = sizeof rec / sizeof rec[0] };
  int vrec[NREC];
  for (int k = 0; k < NREC; k++) {
    const int d3[3] = {dw, dy, rec[k].field};
    CK(ncout_def(g, rec[k].name, NC_DOUBLE, 3, d3, NULL, rec[k].long_name, &vrec[k]));
  }
  if (euler_rows(e))
    for (int k = 0; k < NREC; k++) CK(nc_put_var_double(g, vrec[k], rec[k].data));
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
  int g, dw, vw, vc, v0, v1;
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
  /* the fields of the records: dimensions with labels (field_axes) */
  int fd[6];
  if ((rc = field_axes(g, fd, err, errlen)) != NC_NOERR) goto fail; /* names its call */
  const int dwf = fd[0];
  CK(def_y(&e->cfg, g, dy, r.prof[EP_Y], lo, hi));
  if ((rc = def_window_axis(e, g, dw, err, errlen)) != NC_NOERR) goto fail; /* names its call */
  CK(ncout_def(g, "window_start", NC_DOUBLE, 1, &dw, "s", "start of the averaging window", &v0));
  CK(ncout_def(g, "window_end", NC_DOUBLE, 1, &dw, "s", "end of the averaging window", &v1));
  CK(ncout_def(g, "window_complete", NC_INT, 1, &dw, "1", "1: closed window, 0: still open", &vc));
  const int d2[2] = {dw, dwf};
  CK(ncout_def(g, "windows", NC_DOUBLE, 2, d2, NULL,
               "per window: t_start [s], t_end [s], snapshots, sum of body force [m/s^2], sums "
               "of tau_w/rho at y=0 and y=2delta [m^2/s^2]",
               &vw));
  for (size_t w = 0; w < rows; w++) {
    const size_t st[1] = {w}, ct[1] = {1};
    const int cpl = w < e->nwin;
    CK(nc_put_vara_double(g, v0, st, ct, &e->win[w * WIN_LEN + WIN_T0]));
    CK(nc_put_vara_double(g, v1, st, ct, &e->win[w * WIN_LEN + WIN_T1]));
    CK(nc_put_vara_int(g, vc, st, ct, &cpl));
  }
  if (rows) {
    CK(nc_put_var_double(g, vw, e->win));
  }
  if ((rc = write_records(e, g, dw, dy, fd, err, errlen)) != NC_NOERR) goto fail; /* names it */
  return NC_NOERR;
fail:
  return rc ? rc : NC_EINVAL;
}

/* t_reached: the time the run reached (NaN: not known); an incomplete last window ends there. */
static int write_eulerian(const struct euler *e, double t_reached, int ncid, char *err,
                          size_t errlen) {
  int rc = NC_NOERR, dy;
  struct euler_result r;
  euler_running_result(e, &r);
  const size_t nb = (size_t)e->cfg.nb;
  double *lo = mem_alloc(1, 2 * nb * sizeof *lo, "Eulerian statistics"), *hi = lo + nb;
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

static const char *const names_stats_method[] = {"bins", "sph", NULL};
static const char *const names_stats_target_profiles[] = {"both", "u_mean", "uv_peak", NULL};

/* The engine's scene keys, section [stats] (docs/scenes.md is generated from them); exported
   by euler.h, since the solver reads the switch, the budget interval, the window, u_tau_ref and
   the convergence target too. */
const struct scene_key_def euler_key_eulerian = {
    .section = "stats",
    .name = "eulerian",
    .type = SCENE_INT,
    .def = "1",
    .lo = 0,
    .hi = 1,
    .unit = "-",
    .help =
        "Eulerian statistics: wall-normal profiles of means, Reynolds stresses, skewness, "
        "flatness with standard errors, friction velocity and shear-stress balance "
        "(docs/stats-format.md); sampled every output.stats_every steps from "
        "output.t_average_start in output.n_bins bins."};
const struct scene_key_def euler_key_budget_every = {
    .section = "stats",
    .name = "budget_every",
    .type = SCENE_INT,
    .def = "5",
    .lo = 1,
    .hi = 1e9,
    .unit = "samples",
    .help =
        "Every how many Eulerian samples also carries the momentum and Reynolds-stress budgets "
        "and the wall shear stress (u_tau_wall): every stats.budget_every x output.stats_every "
        "steps. A budget sample splits the pair forces into their conservative parts, which "
        "costs about one more force pass (docs/performance.md, \"The budgets\"); 1 samples them "
        "with every snapshot (the budget identity of every step needs 1 with output.stats_every "
        "= 1). The momentum closure reads the total stress of every snapshot whatever the interval "
        "(the *_all fields); the parts are averaged over the budget snapshots only, so in a short "
        "run through a transient their sum misses that total by their sampling (the quick-start "
        "with the parts on 18 of 85 snapshots: 0.08 u_tau^2 in the centre bin; "
        "jobs/scenes/quickstart.ini uses 1, one snapshot every 25 steps)."};
const struct scene_key_def euler_key_window = {
    .section = "stats",
    .name = "window",
    .type = SCENE_DOUBLE,
    .def = "0",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .unit = "s",
    .help =
        "Length of an averaging window: stats.nc keeps the sums of every window (re-average a "
        "range with `chansph extract --window`), and the window means are the batch means of "
        "the standard errors, so a window should span several correlation times (the log "
        "reports the estimate). 0 = a tenth of t_end - t_average_start. Fixed once averaging "
        "has begun: a resume keeps the length (also with a new t_end) and refuses a new value."};
const struct scene_key_def euler_key_fold = {
    .section = "stats",
    .name = "fold",
    .type = SCENE_INT,
    .def = "0",
    .lo = 0,
    .hi = 1,
    .unit = "-",
    .help =
        "Fold the upper half onto the lower one (y -> 2 delta - y, v -> -v) before binning; the "
        "bins then cover 0 .. delta."};
const struct scene_key_def euler_key_method = {
    .section = "stats",
    .name = "method",
    .type = SCENE_CHOICE,
    .def = "bins",
    .lo = 0,
    .hi = 0,
    .choices = names_stats_method,
    .unit = "-",
    .help =
        "How particles make the profiles: bin sampling (thesis Eq. 5.54-5.55), or SPH "
        "interpolation (Eq. 5.56) at the bin centres averaged over the plane, each particle "
        "weighted by V_a times the plane integral of the kernel; the means are Eq. 5.56, the "
        "stresses then also hold the mean-shear variation across the kernel (use bins for them)."};
const struct scene_key_def euler_key_u_tau_ref = {
    .section = "stats",
    .name = "u_tau_ref",
    .type = SCENE_DOUBLE,
    .def = "0",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .unit = "m/s",
    .help =
        "Friction velocity that places the y+ levels of the correlations and Lagrangian releases "
        "(y = y+ nu / u_tau_ref); 0 = sqrt(delta drive.force), the force-balance value."};
const struct scene_key_def euler_key_target_stderr = {
    .section = "stats",
    .name = "target_stderr",
    .type = SCENE_DOUBLE,
    .def = "0",
    .lo = 0,
    .hi = 1,
    .unit = "-",
    .help =
        "Convergence target: once the standard errors relative to their profile (max "
        "stderr(u_mean) / max |u_mean|, and stderr of -u'v' at its peak / the peak) are below "
        "this, with at least target_windows complete windows of at least target_corr_ratio "
        "correlation times, the run ends itself (checkpoint, stats.nc, exit 0). Checked when a "
        "window closes; every convergence line of the log gives the projected simulated and wall "
        "time to reach it. Needs stats.eulerian = 1. A resumed run that met it stays finished "
        "unless a target key changes. 0 = off."};
const struct scene_key_def euler_key_target_profiles = {
    .section = "stats",
    .name = "target_profiles",
    .type = SCENE_CHOICE,
    .def = "both",
    .lo = 0,
    .hi = 0,
    .choices = names_stats_target_profiles,
    .unit = "-",
    .help =
        "Profiles of the convergence target: u_mean and the -u'v' peak, or one of them (a laminar "
        "flow has no -u'v' to converge)."};
const struct scene_key_def euler_key_target_corr_ratio = {
    .section = "stats",
    .name = "target_corr_ratio",
    .type = SCENE_DOUBLE,
    .def = "5",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .unit = "-",
    .help =
        "Convergence target: smallest window length / correlation time for the standard errors "
        "to count (shorter windows make them too small); 0 = no requirement."};
const struct scene_key_def euler_key_target_windows = {
    .section = "stats",
    .name = "target_windows",
    .type = SCENE_INT,
    .def = "4",
    .lo = 2,
    .hi = 1e9,
    .unit = "-",
    .help =
        "Convergence target: fewest complete windows (batches) for the standard errors to count."};
static const struct scene_key_def *const keys[] = {
    &euler_key_eulerian,      &euler_key_budget_every,    &euler_key_window,
    &euler_key_fold,          &euler_key_method,          &euler_key_u_tau_ref,
    &euler_key_target_stderr, &euler_key_target_profiles, &euler_key_target_corr_ratio,
    &euler_key_target_windows};

/* The configuration from the scene: default bins are of width dr around each particle layer
   y = j dr (j = 1 .. 2delta/dr-1), the thin strips next to the walls joining the first and last
   bins; folded, the layers 1 .. delta/dr; with output.n_bins set: uniform bins between the
   walls (folded: between the wall and the centre). */
static void config_of(const struct stats_scene *sc, struct euler_config *e) {
  memset(e, 0, sizeof *e);
  const int fold = stats_scene_int(sc, &euler_key_fold);
  e->fold = fold, e->delta = sc->delta, e->nu = sc->nu, e->rho0 = sc->rho0;
  e->area = sc->dim == 3 ? sc->lx * sc->lz : sc->lx;
  e->wall_layer = 0.5 * sc->dr;
  e->t_start = sc->t_average_start;
  e->les = sc->les;
  e->method = stats_scene_int(sc, &euler_key_method), e->h = sc->h, e->dim = sc->dim;
  e->window = sc->window;
  if (sc->bins_uniform) {
    e->nb = sc->bins, e->y0 = 0.0, e->y1 = (fold ? 1.0 : 2.0) * sc->delta;
  } else if (fold) {
    e->nb = (int)floor(sc->delta / sc->dr + 0.5), e->y0 = 0.5 * sc->dr;
    e->y1 = e->y0 + e->nb * sc->dr;
  } else {
    e->nb = sc->bins, e->y0 = 0.5 * sc->dr, e->y1 = 2.0 * sc->delta - 0.5 * sc->dr;
  }
}

/* The engine's table of operations (engine.h). */
static int init_scene(void *self, const struct stats_scene *sc) {
  if (!stats_scene_int(sc, &euler_key_eulerian)) return 0;
  struct euler_config cfg;
  config_of(sc, &cfg);
  euler_init(self, &cfg);
  return 1;
}

double euler_scene_window(const struct stats_scene *sc) {
  struct euler_config cfg;
  config_of(sc, &cfg);
  return cfg.window;
}

/* The per-column partials of a sample, and the per-window records of the whole run (the
   first 8 rows at once, then doubled as windows close: at least the run's windows), twice: the
   accumulators and the stats.nc image built in memory when it is written. */
static double estimate(const struct stats_scene *sc) {
  if (!stats_scene_int(sc, &euler_key_eulerian)) return 0.0;
  struct euler_config cfg;
  config_of(sc, &cfg);
  const double windows = ceil((sc->t_end - sc->t_average_start) / cfg.window - 1e-9) + 1.0;
  const double rows = fmax(8.0, windows);
  const double row = WIN_LEN + (double)cfg.nb * (MOM_LEN + SCAL_LEN + PL_LEN + KN_LEN + RW_LEN);
  return (double)euler_sample_bytes(cfg.nb, sc->columns) + 2.0 * rows * row * sizeof(double);
}

static void init(void *self, const void *cfg) {
  euler_init(self, cfg);
}

static void release(void *self) {
  euler_free(self);
}

static void sample(void *self, const struct stats_snapshot *s) {
  euler_sample(self, s);
}

static void close_open(void *self, double t) {
  euler_close(self, t);
}

static void state(void *self, struct state_list *L) {
  euler_state(self, L);
}

static size_t bytes(const void *self) {
  const struct euler *e = self;
  const size_t nb = (size_t)e->cfg.nb;
  return e->cap * (WIN_LEN + nb * (MOM_LEN + SCAL_LEN + PL_LEN + KN_LEN + RW_LEN)) *
             sizeof(double) +
         euler_work_bytes(e);
}

static int write(const void *self, double t_reached, int ncid, char *err, size_t errlen) {
  return write_eulerian(self, t_reached, ncid, err, errlen);
}

static void log_lines(const void *self, char *buf, size_t len) {
  euler_log(self, buf, len);
}

const struct stats_engine euler_engine = {.name = "Eulerian profiles",
                                          .keys = keys,
                                          .n_keys = sizeof keys / sizeof keys[0],
                                          .size = sizeof(struct euler),
                                          .init_scene = init_scene,
                                          .estimate = estimate,
                                          .init = init,
                                          .free = release,
                                          .sample = sample,
                                          .close = close_open,
                                          .state = state,
                                          .bytes = bytes,
                                          .write = write,
                                          .warnings = NULL,
                                          .log = log_lines};
