/** @file output.c @brief Implementation of output.h. */
#include "output.h"
#include "alloc.h"

#include <errno.h>
#include <math.h>
#include <mpi.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <omp.h>
#include <time.h>

#include "corr.h"
#include "error.h"
#include "euler.h"
#include "git_commit.h"
#include "lagr.h"
#include "ncout.h"
#include "stats_nc.h"
#include "term_diffusion.h"
#include "timers.h"

/** The `source` attribute of the output files: version and git commit of the build. */
#define CHANSPH_SOURCE "chansph " CHANSPH_VERSION " (git " CHANSPH_GIT_COMMIT ")"

/* The date a file is written, ISO 8601 in UTC (attribute date_created). */
static void date_now(char *buf, size_t n) {
  const time_t now = time(NULL);
  struct tm utc;
  gmtime_r(&now, &utc);
  strftime(buf, n, "%Y-%m-%dT%H:%M:%SZ", &utc);
}

static const char *const series_names[] = {"time",    "u_bulk",    "body_force", "kinetic_energy",
                                           "mass",    "max_speed", "min_gamma",  "volume",
                                           "rho_min", "rho_max",   "dt"};
/* udunits strings; in 2-D the volume is an area, mass and energy are per metre of span */
static const char *const series_units_2d[] = {"s", "m/s", "m/s^2",  "J/m",    "kg/m", "m/s",
                                              "1", "m^2", "kg/m^3", "kg/m^3", "s"};
static const char *const series_units_3d[] = {"s", "m/s", "m/s^2",  "J",      "kg", "m/s",
                                              "1", "m^3", "kg/m^3", "kg/m^3", "s"};
static const char *const series_long_names[] = {
    "simulated time",
    "bulk velocity (volume-weighted mean u of the fluid)",
    "streamwise body acceleration (driving force per unit mass)",
    "kinetic energy of the fluid (per metre of span in 2-D)",
    "mass of the fluid (per metre of span in 2-D)",
    "largest particle speed",
    "smallest wall renormalisation factor gamma",
    "volume of the fluid (sum of m/rho; an area in 2-D)",
    "smallest particle density",
    "largest particle density",
    "time step"};
enum { N_SERIES = sizeof series_names / sizeof series_names[0] };

static int rank0(void) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank == 0;
}

/* Every rank takes rank 0's result of a file operation only rank 0 did. */
static int agree(int rc) {
  CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
  return rc;
}

static int mkdir_p(const char *path) {
  char buf[2048];
  snprintf(buf, sizeof buf, "%s", path);
  for (char *p = buf + 1; *p; p++)
    if (*p == '/') {
      *p = '\0';
      if (mkdir(buf, 0777) && errno != EEXIST) return -1;
      *p = '/';
    }
  if (mkdir(buf, 0777) && errno != EEXIST) return -1;
  return 0;
}

static int exists(const char *dir, const char *name) {
  char path[4096];
  struct stat st;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return stat(path, &st) == 0;
}

/* Shared by output_open and output_reopen: log.txt (mode "w" or "a"), scene.used.ini,
   empty accumulators. */
static int open_files(struct output *o, const char *dir, const struct scene *sc,
                      const char *log_mode) {
  char path[4096];
  snprintf(path, sizeof path, "%s/log.txt", dir);
  o->log = fopen(path, log_mode);
  if (!o->log) {
    error_input("%s: cannot open for writing (%s)", path, strerror(errno));
    return CHANSPH_ERR;
  }
  o->scene_text = scene_text(sc);
  snprintf(path, sizeof path, "%s/scene.used.ini", dir);
  FILE *f = fopen(path, "w");
  if (!f ||
      fprintf(f, "; resolved scene of %s (defaults included)\n%s", sc->path, o->scene_text) < 0 ||
      fclose(f)) {
    error_input("%s: cannot write (%s)", path, strerror(errno));
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

void output_stats_scene(const struct scene *sc, struct stats_scene *view) {
  const double u_tau_ref = scene_stats_num(sc, &euler_key_u_tau_ref);
  int n_keys = 0;
  const struct scene_key_def *const *defs = scene_stats_defs(&n_keys);
  *view =
      (struct stats_scene){.dim = sc->dim,
                           .delta = sc->delta,
                           .lx = sc->lx,
                           .lz = sc->lz,
                           .dr = sc->dr,
                           .h = scene_h(sc),
                           .nu = sc->nu,
                           .rho0 = sc->rho0,
                           .les = sc->les != LES_NONE,
                           .u_tau = u_tau_ref > 0.0 ? u_tau_ref : sqrt(sc->delta * fabs(sc->force)),
                           .t_average_start = sc->t_average_start,
                           .t_end = sc->t_end,
                           .window = stats_window_length(scene_stats_num(sc, &euler_key_window),
                                                         sc->t_average_start, sc->t_end),
                           .bins = scene_bins(sc),
                           .bins_uniform = sc->n_bins > 0,
                           .columns = nbr_columns(sc),
                           .n_keys = n_keys,
                           .key_def = defs,
                           .key_value = sc->stats_keys};
}

/* Shared by output_open and output_reopen: the files (rank 0), the engines (every rank). */
static int open_common(struct output *o, const char *dir, const struct scene *sc,
                       const char *log_mode) {
  if (agree(rank0() ? open_files(o, dir, sc, log_mode) : CHANSPH_OK)) return CHANSPH_ERR;
  if (!o->scene_text) o->scene_text = scene_text(sc);
  struct stats_scene view;
  output_stats_scene(sc, &view);
  stats_init(&o->st, &view);
  const struct euler *eu = stats_find(&o->st, &euler_engine);
  o->window_len = eu ? eu->cfg.window : NAN;
  series_init(&o->ts, N_SERIES, series_names, sc->dim == 2 ? series_units_2d : series_units_3d,
              series_long_names);
  o->next_write = sc->write_every > 0.0 ? sc->write_every : INFINITY;
  return CHANSPH_OK;
}

void output_stats_bytes(const struct scene *sc, double *eulerian, double *corr, double *lagr) {
  struct stats_scene view;
  output_stats_scene(sc, &view);
  *eulerian = euler_engine.estimate(&view);
  *corr = corr_engine.estimate(&view);
  *lagr = lagr_engine.estimate(&view);
}

/* The checks and the directory of output_open (rank 0). */
static int make_dir(const char *dir, int overwrite) {
  static const char *const results[] = {"stats.nc", "log.txt", "particles.nc"};
  for (size_t i = 0; i < sizeof results / sizeof results[0] && !overwrite; i++)
    if (exists(dir, results[i])) {
      error_input(
          "%s/%s: the output directory already holds results of a run; choose "
          "another --out DIR or pass --overwrite",
          dir, results[i]);
      return CHANSPH_ERR;
    }
  if (mkdir_p(dir)) {
    error_input("%s: cannot create the output directory (%s)", dir, strerror(errno));
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

int output_open(struct output *o, const char *dir, const struct scene *sc, int overwrite) {
  memset(o, 0, sizeof *o);
  snprintf(o->dir, sizeof o->dir, "%s", dir);
  if (agree(rank0() ? make_dir(dir, overwrite) : CHANSPH_OK)) return CHANSPH_ERR;
  return open_common(o, dir, sc, "w");
}

int output_reopen(struct output *o, const char *dir, const struct scene *sc) {
  memset(o, 0, sizeof *o);
  snprintf(o->dir, sizeof o->dir, "%s", dir);
  return open_common(o, dir, sc, "a");
}

/* The time series grows during a run: make room for the stored rows. */
static void *series_reserve(void *owner, int rank, const size_t *dims) {
  struct series *ts = owner;
  if (rank != 2 || dims[1] != (size_t)ts->ncol) return NULL;
  if (dims[0] > ts->cap) {
    double *d =
        mem_realloc(ts->data, dims[0] ? dims[0] : 1, (size_t)ts->ncol * sizeof *d, "time series");
    ts->data = d, ts->cap = dims[0] ? dims[0] : 1;
  }
  ts->n = dims[0];
  return ts->data;
}

void output_state(struct output *o, struct state_list *L) {
  stats_state(&o->st, L); /* every engine's accumulators (stats/...) */
  const size_t dims[2] = {o->ts.n, (size_t)o->ts.ncol};
  struct state_field *f = state_add(L, "stats/series", STATE_F64, 2, dims, o->ts.data, NULL);
  f->reserve = series_reserve, f->owner = &o->ts;
  state_add(L, "output/next_write", STATE_F64, 0, NULL, &o->next_write, "s");
  /* format 1.5; before it, a resume takes the length from the checkpoint's scene */
  state_add(L, "output/window_length", STATE_F64, 0, NULL, &o->window_len, "s")->optional = 1;
  /* format 1.5; before it, a run that ended at its target resumed as one that had not */
  state_add(L, "output/converged", STATE_I32, 0, NULL, &o->converged, NULL)->optional = 1;
  /* format 1.12: the statistics an earlier resume from an older checkpoint left incomplete */
  if (!o->resumed_without) o->resumed_without = mem_calloc(1, 1, "output");
  state_add(L, "output/resumed_without", STATE_TEXT, 0, NULL, &o->resumed_without, NULL)->optional =
      1;
}

double output_stats_window(const struct output *o, const struct scene *sc) {
  if (!sc) {
    const struct euler *eu = stats_find(&o->st, &euler_engine);
    return eu ? eu->cfg.window : NAN;
  }
  struct stats_scene view;
  output_stats_scene(sc, &view);
  return euler_scene_window(&view);
}

void output_set_window(struct output *o, double len) {
  o->window_len = len;
  struct euler *eu = stats_find(&o->st, &euler_engine);
  if (eu) eu->cfg.window = len;
}

void output_log(struct output *o, const char *fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (!rank0()) return;
  fputs(buf, stdout);
  fflush(stdout);
  if (o->log) fputs(buf, o->log), fflush(o->log);
}

static void record(struct output *o, struct sim *S, struct diag *d) {
  sim_diag(S, d);
  const double row[N_SERIES] = {S->t,       d->u_bulk,    S->fx,        d->kinetic_energy,
                                d->mass,    d->max_speed, d->min_gamma, d->volume,
                                d->rho_min, d->rho_max,   S->dt};
  series_add(&o->ts, row);
}

/* The last step of this process: time.max_steps (a step number) or the command line's
   --max-steps (steps of this process), whichever comes first; 0 if neither is set. */
static long end_step(const struct output *o, const struct sim *S) {
  long end = S->sc->max_steps > 0 ? S->sc->max_steps : 0;
  if (o->max_steps > 0 && (end == 0 || o->step0 + o->max_steps < end))
    end = o->step0 + o->max_steps;
  return end;
}

/* Format seconds as hh:mm:ss into buf ("--:--:--" when not known). */
static const char *hms(double s, char *buf, size_t size) {
  if (!(s >= 0.0) || s > 3.6e8) {
    snprintf(buf, size, "--:--:--");
    return buf;
  }
  const long es = (long)s;
  snprintf(buf, size, "%02ld:%02ld:%02ld", es / 3600, es / 60 % 60, es % 60);
  return buf;
}

/* The fraction of this process's run done (by simulated time or by steps, whichever is ahead)
   and the projected wall time to its end (NaN before the first step). */
static double progress_left(const struct output *o, const struct sim *S, double now, double *frac) {
  const double done = S->t - o->t0, span = S->sc->t_end - o->t0;
  *frac = span > 0.0 ? done / span : 0.0;
  const long steps = S->step - o->step0, end = end_step(o, S);
  if (end > 0 && end > o->step0) *frac = fmax(*frac, (double)steps / (double)(end - o->step0));
  *frac = fmin(1.0, fmax(0.0, *frac));
  if (steps <= 0 || !(*frac > 0.0)) return NAN;
  return (now - o->wall0) * (1.0 - *frac) / *frac;
}

static void log_progress(struct output *o, struct sim *S, const struct diag *d) {
  const double now = timer_now();
  const double rate = now > o->last_wall
                          ? (double)S->P.n_fluid * (S->step - o->last_step) / (now - o->last_wall)
                          : 0.0;
  double frac;
  const double eta = progress_left(o, S, now, &frac);
  char el[32], et[32];
  /* eddy turnovers t u_tau/delta, u_tau of the body force: sqrt(|f| delta) */
  const double delta = S->sc->delta, turnovers = S->t * sqrt(fabs(S->fx) / delta);
  output_log(o,
             "step %8ld  t %.6e  dt %.3e  u_bulk %.6e  force %.6e  max|v| %.4e  rho [%.6g, %.6g]"
             "  min_gamma %.4f  %.3e p-steps/s  turnovers %.4g  elapsed %s  %5.1f%%  ETA %s\n",
             S->step, S->t, S->dt, d->u_bulk, S->fx, d->max_speed, d->rho_min, d->rho_max,
             d->min_gamma, rate, turnovers, hms(now - o->wall0, el, sizeof el), 100.0 * frac,
             hms(eta, et, sizeof et));
  if (d->reflections > o->reflections) /* new ones since the last log line */
    output_log(o, "  wall reflections since this job began: %ld (sph.wall_collision = reflect)\n",
               d->reflections);
  o->reflections = d->reflections;
  o->last_wall = now, o->last_step = S->step;
}

/* The scene's convergence target; 0 if there is none. */
static int target_of(const struct scene *sc, struct euler_target *tg) {
  const double rel = scene_stats_num(sc, &euler_key_target_stderr);
  if (!(rel > 0.0) || !scene_stats_num(sc, &euler_key_eulerian)) return 0;
  tg->rel_stderr = rel, tg->profiles = (int)scene_stats_num(sc, &euler_key_target_profiles);
  tg->corr_ratio = scene_stats_num(sc, &euler_key_target_corr_ratio);
  tg->windows = (int)scene_stats_num(sc, &euler_key_target_windows);
  return 1;
}

/* Where the standard errors stand against the target, and the projected simulated and wall
   time to reach it (this process's wall time per simulated second). */
static void log_target(struct output *o, const struct sim *S, const struct euler_progress *p) {
  const struct scene *sc = S->sc;
  static const char *const which[3] = {"u_mean and the -u'v' peak", "u_mean", "the -u'v' peak"};
  struct euler_target tg = {0};
  target_of(sc, &tg);
  char proj[320];
  const double done = S->t - o->t0, rate = done > 0.0 ? (timer_now() - o->wall0) / done : NAN;
  if (p->met) {
    snprintf(proj, sizeof proj, "target met");
  } else if (tg.corr_ratio > 0.0 && !(p->ratio >= tg.corr_ratio)) {
    snprintf(proj, sizeof proj,
             "windows too short to count: window/correlation time %.3g < %g (increase "
             "stats.window)",
             p->ratio, tg.corr_ratio);
  } else if (!isfinite(p->t_reach)) {
    snprintf(proj, sizeof proj, "projection after 2 complete windows");
  } else {
    const double more = fmax(0.0, p->t_reach - S->t), wall = more * rate;
    const long w = isfinite(wall) ? (long)wall : 0;
    snprintf(proj, sizeof proj,
             "projected: %.0f windows, t = %.6g s (%.4g s more simulated, about %02ld:%02ld:%02ld "
             "wall)%s",
             p->windows_needed, p->t_reach, more, w / 3600, w / 60 % 60, w % 60,
             p->t_reach > sc->t_end ? " beyond t_end: raise time.t_end" : "");
  }
  output_log(o,
             "target: relative stderr %g of %s: u_mean %.3g, -u'v' peak %.3g after %d "
             "windows; %s\n",
             tg.rel_stderr, which[tg.profiles], p->rel_u, p->rel_uv, p->windows, proj);
}

/* Settings that would silently give nothing: say so at the start. */
static void warn_settings(struct output *o, const struct sim *S) {
  const struct scene *sc = S->sc;
  const double every = sc->snap_every;
  if (every > 0.0 && floor(sc->t_end / every) == floor(S->t / every))
    output_log(o,
               "warning: snapshots.every = %g s is longer than the rest of the run (t = %.6g .. "
               "t_end = %g s): no snapshot will be written\n",
               every, S->t, sc->t_end);
}

/* The provenance attributes of every netCDF file a run writes (CF: source, history,
   date_created; the run's ranks, threads, identity and scene). */
// clang-format off
#define PROVENANCE_ATTRS(o, S, date)                                                   \
  {"source", CHANSPH_SOURCE, 0, 0},                                                   \
  {"history", (o)->history ? (o)->history : "", 0, 0},                                \
  {"date_created", (date), 0, 0},                                                     \
  {"ranks", NULL, (double)(S)->dd.size, 1},                                           \
  {"threads", NULL, (double)omp_get_max_threads(), 1},                                \
  {"run_id", (o)->run_id, 0, 0},                                                      \
  {"scene", (o)->scene_text, 0, 0}
// clang-format on

static int write_stats(struct output *o, const struct sim *S) {
  const struct scene *sc = S->sc;
  char path[4096], err[4096];
  snprintf(path, sizeof path, "%s/stats.nc", o->dir);
  char drive[16], visc[16];
  snprintf(drive, sizeof drive, "%s", scene_choice("drive.mode", sc->drive_mode));
  snprintf(visc, sizeof visc, "%s", scene_choice("sph.viscous", sc->viscous));
  char date[32];
  date_now(date, sizeof date);
  const struct nc_attr attrs[] = {
      {"dimension", NULL, sc->dim, 1},
      {"delta", NULL, sc->delta, 0},
      {"lx", NULL, sc->lx, 0},
      {"lz", NULL, sc->lz, 0},
      {"dr", NULL, sc->dr, 0},
      {"h", NULL, scene_h(sc), 0},
      {"nu", NULL, sc->nu, 0},
      {"rho0", NULL, sc->rho0, 0},
      {"c0", NULL, sc->c0, 0},
      {"xi", NULL, scene_xi(sc), 0},
      {"drive_mode", drive, 0, 0},
      {"viscous", visc, 0, 0},
      {"u_bulk_target", NULL, sc->drive_mode == DRIVE_FLUX ? sc->u_bulk : NAN, 0},
      {"body_force", NULL, S->fx, 0},
      {"init_from_run_id", S->init_run_id ? S->init_run_id : "unknown", 0, 0},
      {"init_from_time", NULL, S->init_time, 0},
      {"t_average_start", NULL, sc->t_average_start, 0},
      {"t_end", NULL, sc->t_end, 0},
      {"t_reached", NULL, S->t, 0},
      {"steps", NULL, (double)S->step, 1},
      {"n_fluid", NULL, (double)S->P.n_fluid, 1},
      {"n_snapshots", NULL, (double)o->st.samples, 1},
      {"code_version", CHANSPH_VERSION, 0, 0},
      {"resumed_without", o->resumed_without && o->resumed_without[0] ? o->resumed_without : NULL,
       NAN, 0},
      PROVENANCE_ATTRS(o, S, date),
  };
  int rc = CHANSPH_OK;
  o->st.t_reached = S->t; /* an incomplete last window ends here, not at its nominal end */
  if (rank0() &&
      stats_nc_file(path, &o->st, &o->ts, attrs, sizeof attrs / sizeof attrs[0], err, sizeof err)) {
    error_input("%s", err);
    rc = CHANSPH_ERR;
  }
  return agree(rc);
}

/* The decomposition at the start: Px x Pz blocks, their sizes and the ghosts per rank against
   the owned particles' cells (the halo's volume: what the exchange moves). */
static void log_blocks(struct output *o, const struct sim *S) {
  const struct dd *d = &S->dd;
  const int R = NBR_REACH, hx = d->px > 1 ? R : 0, hz = d->pz > 1 ? R : 0;
  const double nxo = (double)d->ncol / d->px, nzo = (double)d->nplane / d->pz;
  const double ghosts = 2.0 * hx * nzo + 2.0 * hz * (nxo + 2.0 * hx);
  output_log(o,
             "decomposition: %d MPI ranks as %d x %d blocks (x by z) of %d-%d columns and %d-%d "
             "planes of the %d x %d cell pencils; halo %.0f pencils a rank, ghosts / owned "
             "%.2f (run.ranks)\n",
             d->size, d->px, d->pz, d->ncol / d->px, (d->ncol + d->px - 1) / d->px,
             d->nplane / d->pz, (d->nplane + d->pz - 1) / d->pz, d->ncol, d->nplane, ghosts,
             ghosts / (nxo * nzo));
}

/* The measured start-up memory: the peak resident memory of the ranks once the particles are
   built (or read) and distributed, the part of it the start-up added (above the process's peak
   before sim_create: binary, MPI, libraries), and that part per owned + ghost particle. */
static void log_memory(struct output *o, const struct sim *S) {
  const double peak = mem_peak_resident(), local = (double)(S->P.n + S->P.n_ghost);
  const double x[3] = {peak, peak - S->rss_before,
                       (peak - S->rss_before) / (local > 0 ? local : 1)};
  double mx[3], sum[3];
  CHECK_MPI(MPI_Allreduce(x, mx, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD));
  CHECK_MPI(MPI_Allreduce(x, sum, 3, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD));
  const int n = S->dd.size;
  output_log(o,
             "memory: start-up peak resident %.1f MB a rank (mean of %d; max %.1f MB), of which "
             "the start-up %.1f MB (mean; max %.1f MB), %.0f bytes per owned + ghost particle "
             "(mean; max %.0f)\n",
             sum[0] / n / 1e6, n, mx[0] / 1e6, sum[1] / n / 1e6, mx[1] / 1e6, sum[2] / n, mx[2]);
}

void output_begin(struct output *o, struct sim *S) {
  struct diag d;
  record(o, S, &d);
  timer_reset(); /* the phase report covers the steps, as after a resume (not the set-up) */
  o->wall0 = o->last_wall = timer_now();
  o->t0 = S->t, o->last_step = o->step0 = S->step;
  output_log(o,
             "chansph %s: %zu fluid + %zu vertex particles, h = %.6g, dt limits: acoustic "
             "%.3e s, viscous %.3e s, volume diffusion %.3e s; output in %s\n",
             CHANSPH_VERSION, S->P.n_fluid, S->P.n_vertex, S->M.h, S->sc->cfl * S->M.h / S->sc->c0,
             S->sc->c_visc * S->M.h * S->M.h / S->sc->nu,
             diffusion_dt_limit(&S->M, S->sc->c_diffusion), o->dir);
  output_log(o,
             "memory: the large allocations need at least %.4g GB per rank (checked before "
             "the start against 80%% of the machine's memory)\n",
             sim_memory_estimate(S->sc) / 1e9);
  log_memory(o, S);
  if (S->dd.size > 1) log_blocks(o, S);
  warn_settings(o, S);
  log_progress(o, S, &d);
}

void output_resume(struct output *o, struct sim *S) {
  timer_reset(); /* the phase report covers this process's steps */
  o->wall0 = o->last_wall = timer_now();
  o->t0 = S->t, o->last_step = o->step0 = S->step;
  output_log(o, "chansph %s: resumed at step %ld, t = %.9g s: %zu fluid + %zu vertex particles\n",
             CHANSPH_VERSION, S->step, S->t, S->P.n_fluid, S->P.n_vertex);
  log_memory(o, S);
  if (S->dd.size > 1) log_blocks(o, S); /* the decomposition may differ from the last job's */
  warn_settings(o, S);
}

/* The statistics engines sample the state of this step. */
static int sample_due(const struct output *o, const struct sim *S) {
  const struct scene *sc = S->sc;
  return stats_wanted(&o->st) && S->t >= sc->t_average_start && S->step % sc->stats_every == 0;
}

int output_takes_state(const struct output *o, const struct sim *S) {
  return sample_due(o, S) || S->step % S->sc->series_every == 0 || S->t >= o->next_write;
}

void output_sample(struct output *o, struct sim *S) {
  if (!sample_due(o, S)) return;
  const struct scene *sc = S->sc;
  timer_push("stats");
  const struct particles *P = &S->P;
  /* the engine merges per global column in a fixed order: rank-independent results */
  if (P->n > o->col_cap) {
    free(o->col);
    o->col_cap = P->n + P->n / 2;
    o->col = mem_alloc(1, o->col_cap * sizeof *o->col, "output");
    if (!o->col) die("out of memory for the statistics snapshot");
  }
  for (size_t a = 0; a < P->n; a++) o->col[a] = nbr_pencil(&S->nb, P->x[a], P->z[a]);
  const struct stats_snapshot snap = {
      .n = P->n,
      .x = P->x,
      .y = P->y,
      .z = P->z,
      .u = P->u,
      .v = P->v,
      .w = P->w,
      .p = P->p,
      .rho = P->rho,
      .nu_t = P->nur,
      .k_r = P->kr,
      .m = P->m,
      .ax = P->ax,
      .ay = P->ay,
      .az = P->az,
      .sx = P->sx_live ? P->sx : NULL,
      .sx_noise = P->sx_live ? P->sxn : NULL,
      .id = P->id,
      .skip = P->kind,
      .t = S->t,
      .fx = S->fx,
      .dt = S->dt,
      .shift_dy = P->shift_dy,
      .step = S->step,
      .wall_fx = {P->sx_live ? S->wall_fx[0] : NAN, P->sx_live ? S->wall_fx[1] : NAN},
      .col = o->col,
      .ncol = S->dd.ncol,
      .nplane = S->dd.nplane,
      .col0 = S->nb.ix0,
      .col1 = S->nb.ix0 + S->nb.nxo,
      .plane0 = S->nb.iz0,
      .plane1 = S->nb.iz0 + S->nb.nzo,
      .comm = MPI_COMM_WORLD,
      .comm_x = S->dd.comm_x,
      .comm_z = S->dd.comm_z};
  stats_sample(&o->st, &snap);
  timer_pop();
  struct euler_target tg;
  const struct euler *eu = stats_find(&o->st, &euler_engine); /* the target is on its profiles */
  if (target_of(sc, &tg) && eu->nwin != o->target_nwin) {     /* a window closed */
    o->target_nwin = eu->nwin;
    struct euler_progress p;
    euler_target_progress(eu, &tg, &p);
    if (agree(p.met)) {
      char line[1024];
      stats_convergence_line(&o->st, line, sizeof line);
      output_log(o, "%s", line);
      log_target(o, S, &p);
      output_log(o,
                 "converged: the statistics meet stats.target_stderr = %g at step %ld, t = "
                 "%.9g s; the run ends here\n",
                 tg.rel_stderr, S->step, S->t);
      o->converged = 1;
    }
  }
}

/* The log line of a load rebalance of the decomposition (dd_balance), once per rebalance. */
static void log_rebalance(struct output *o, const struct sim *S) {
  if (S->dd.rebalances == o->rebalances) return;
  const struct dd *dd = &S->dd;
  char cols[256] = "", planes[256] = "";
  for (int r = 0, k = 0; r < dd->px && k < (int)sizeof cols - 16; r++)
    k += snprintf(cols + k, sizeof cols - (size_t)k, "%s%d", r ? " " : "",
                  dd->fx[r + 1] - dd->fx[r]);
  for (int r = 0, k = 0; r < dd->pz && k < (int)sizeof planes - 16; r++)
    k += snprintf(planes + k, sizeof planes - (size_t)k, "%s%d", r ? " " : "",
                  dd->fz[r + 1] - dd->fz[r]);
  output_log(o,
             "load balance: step %ld, imbalance %.3f (max / mean particles per rank): "
             "columns per block column now %s, planes per block row %s\n",
             S->step, dd->imbalance, cols, planes);
  o->rebalances = dd->rebalances;
}

int output_step(struct output *o, struct sim *S) {
  const struct scene *sc = S->sc;
  timer_push("output");
  log_rebalance(o, S);
  struct diag d;
  int have = 0;
  if (S->step % sc->series_every == 0) record(o, S, &d), have = 1;
  /* and the first step of this process, so that a short run shows its ETA at once */
  if (S->step % sc->log_every == 0 || S->step == o->step0 + 1) {
    if (!have) sim_diag(S, &d);
    log_progress(o, S, &d);
  }
  struct euler_target tg;
  struct euler_progress prog;
  if (S->t >= o->next_write) {
    char line[1024];
    stats_convergence_line(&o->st, line, sizeof line);
    output_log(o, "%s", line);
    if (line[0] && target_of(sc, &tg) && !o->converged)
      euler_target_progress(stats_find(&o->st, &euler_engine), &tg, &prog), log_target(o, S, &prog);
    if (write_stats(o, S)) {
      timer_pop();
      return CHANSPH_ERR;
    }
    while (o->next_write <= S->t) o->next_write += sc->write_every;
  }
  timer_pop();
  return CHANSPH_OK;
}

static int write_particles(struct output *o, struct sim *S) {
  const struct particles *P = &S->P;
  sim_output_fields(S); /* output.q_criterion */
  const size_t n = P->n_fluid;
  enum { NC_MAX = 32 };
  const double *src[NC_MAX];
  const char *names[NC_MAX], *long_names[NC_MAX], *units[NC_MAX];
  int NC = 0; /* the PF_WRITE fields of the table (part.h), in its order */
  for (int i = 0; i < part_n_fields && NC < NC_MAX; i++) {
    const struct part_field *f = &part_fields[i];
    if (!(f->roles & PF_WRITE) || !part_field_ptr(P, f)) continue;
    src[NC] = part_field_ptr(P, f), names[NC] = f->name, long_names[NC] = f->long_name;
    units[NC++] = f->off == offsetof(struct particles, m) && S->sc->dim == 2 ? "kg/m" : f->units;
  }
  /* each rank the rows of its id block, by id; on several ranks they write the file together
     (ncout_columns_par: no gather on one rank), on one the serial writer */
  size_t lo, hi;
  dd_id_block(S->dd.rank, S->dd.size, n, &lo, &hi);
  const size_t nb = hi - lo, m = nb ? nb : 1;
  double *buf = mem_alloc(1, m * (size_t)NC * sizeof *buf, "output");
  dd_block_fluid(&S->dd, P, NC, src, lo, hi, buf);
  long long *ids = mem_alloc(1, m * sizeof *ids, "output");
  for (size_t r = 0; r < nb; r++) ids[r] = (long long)(lo + r);
  const double *cols[NC_MAX];
  for (int c = 0; c < NC; c++) cols[c] = buf + (size_t)c * nb;
  char date[32];
  date_now(date, sizeof date);
  const struct nc_attr attrs[] = {
      {"time", NULL, S->t, 0}, {"step", NULL, (double)S->step, 1}, PROVENANCE_ATTRS(o, S, date)};
  const struct ncout_table t = {.title = "chansph particle state",
                                .dim = "particle",
                                .n = n,
                                .ncol = NC,
                                .names = names,
                                .long_names = long_names,
                                .units = units,
                                .attrs = attrs,
                                .nattrs = (int)(sizeof attrs / sizeof attrs[0])};
  char path[4096], err[4096];
  snprintf(path, sizeof path, "%s/particles.nc", o->dir);
  const int rc = S->dd.size > 1 ? ncout_columns_par(path, &t, lo, nb, cols, ids, err, sizeof err)
                                : ncout_columns(path, &t, cols, ids, err, sizeof err);
  if (rc && rank0()) error_input("%s", err); /* the ranks agree on the outcome and message */
  free(ids), free(buf);
  return agree(rc ? CHANSPH_ERR : CHANSPH_OK);
}

/* Cost of the decomposition over the run (collective). */
static void log_decomposition(struct output *o, struct sim *S, double wall) {
  const struct dd *d = &S->dd;
  if (d->size == 1) return;
  double x[3] = {d->seconds, d->bytes, (double)d->migrated}, mx[3], sum[3];
  CHECK_MPI(MPI_Allreduce(x, mx, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD));
  CHECK_MPI(MPI_Allreduce(x, sum, 3, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD));
  output_log(o,
             "decomposition: %d ranks (%d x %d blocks), %d x %d cell pencils; halo exchange and "
             "migration %.3f s "
             "(max over ranks, %.1f%% of the wall time); %.2f MB sent in all; %.0f particles "
             "migrated; %ld re-partitions (last imbalance %.3f)\n",
             d->size, d->px, d->pz, d->ncol, d->nplane, mx[0],
             wall > 0 ? 100.0 * mx[0] / wall : 0.0, sum[1] / 1048576.0, sum[2], d->rebalances,
             d->imbalance);
  /* per rank and step (docs/parallel_model.py's b G and m): bytes sent, messages, ghosts */
  const double ns = d->halos > 0 ? (double)d->halos : 1.0;
  double y[4] = {d->bytes / ns, (double)d->messages / ns, d->ghosts / ns, (double)S->P.n}, my[4],
         sy[4];
  CHECK_MPI(MPI_Allreduce(y, my, 4, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD));
  CHECK_MPI(MPI_Allreduce(y, sy, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD));
  const double P = d->size;
  output_log(o,
             "halo per rank and step (mean, max over ranks; %ld steps): %.1f kB, %.1f kB sent in "
             "%.1f, %.1f messages; %.0f, %.0f ghosts; ghosts / owned %.3f\n",
             d->halos, sy[0] / P / 1e3, my[0] / 1e3, sy[1] / P, my[1], sy[2] / P, my[2],
             sy[3] > 0 ? sy[2] / sy[3] : 0.0);
}

int output_finish(struct output *o, struct sim *S) {
  struct diag d;
  if (o->ts.n == 0 || o->ts.data[(o->ts.n - 1) * (size_t)o->ts.ncol] != S->t)
    record(o, S, &d);
  else
    sim_diag(S, &d);
  if (S->step != o->last_step) log_progress(o, S, &d);
  const double wall = timer_now() - o->wall0;
  /* the run ends: a window whose end it has reached is complete (t_end at a window boundary),
     as the next snapshot would have made it; a resume continues with the same records */
  stats_close(&o->st, S->t);
  char line[1024];
  stats_convergence_line(&o->st, line, sizeof line);
  output_log(o, "%s", line);
  struct euler_target tg;
  struct euler_progress prog;
  if (line[0] && target_of(S->sc, &tg) && !o->converged)
    euler_target_progress(stats_find(&o->st, &euler_engine), &tg, &prog), log_target(o, S, &prog);
  output_log(o, "statistics engine: %.3f MB (%lld snapshots)\n", stats_memory(&o->st) / 1048576.0,
             (long long)o->st.samples);
  char warnings[4096];
  if (rank0() && stats_warnings(&o->st, warnings, sizeof warnings))
    for (char *l = strtok(warnings, "\n"); l; l = strtok(NULL, "\n")) output_log(o, "%s\n", l);
  TRY(write_stats(o, S));
  if (S->sc->particles) TRY(write_particles(o, S));
  log_decomposition(o, S, wall);
  output_log(o, "finished: %ld steps, t = %.6g s in %.2f s wall (%.3e particle-steps/s)\n", S->step,
             S->t, wall, wall > 0 ? (double)S->P.n_fluid * (S->step - o->step0) / wall : 0.0);
  if (rank0()) timer_report(stdout, wall);
  if (o->log) timer_report(o->log, wall);
  output_log(o, "results: %s/stats.nc%s\n", o->dir,
             S->sc->particles ? ", particles.nc, snapshots/particles.xdmf (the final state, for "
                                "ParaView)"
                              : "");
  return CHANSPH_OK;
}

int output_stop(struct output *o, struct sim *S, const char *why) {
  const double wall = timer_now() - o->wall0;
  stats_close(&o->st, S->t); /* as at the end (output_finish) */
  TRY(write_stats(o, S));
  output_log(o, "stopped at step %ld, t = %.9g s (%s) after %.2f s wall\n", S->step, S->t, why,
             wall);
  if (rank0()) timer_report(stdout, wall);
  if (o->log) timer_report(o->log, wall);
  return CHANSPH_OK;
}

void output_fail(struct output *o, struct sim *S, const struct health_report *rep) {
  (void)S;
  error_input("%s", rep->what);
  if (o->log) fprintf(o->log, "error: %s\n", rep->what), fflush(o->log);
  error_input("run stopped; files written before this step are kept");
}

void output_close(struct output *o) {
  if (o->log) fclose(o->log);
  free(o->scene_text);
  free(o->history);
  free(o->resumed_without);
  free(o->col);
  stats_free(&o->st);
  series_free(&o->ts);
  memset(o, 0, sizeof *o);
}
