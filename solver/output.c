/** @file output.c @brief Implementation of output.h. */
#include "output.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "error.h"
#include "ncout.h"
#include "timers.h"

static const char *const series_names[] = {"time",    "u_bulk",    "body_force", "kinetic_energy",
                                           "mass",    "max_speed", "min_gamma",  "volume",
                                           "rho_min", "rho_max",   "dt"};
static const char *const series_units[] = {"s", "m/s",   "m/s^2",  "J",      "kg", "m/s",
                                           "1", "m^dim", "kg/m^3", "kg/m^3", "s"};
enum { N_SERIES = sizeof series_names / sizeof series_names[0] };

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
static int open_common(struct output *o, const char *dir, const struct scene *sc,
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
  /* default: one bin of width dr around each particle layer y = j dr (j = 1 .. 2delta/dr-1),
     the thin strips next to the walls joining the first and last bins; with n_bins set:
     uniform bins between the walls */
  const double edge = sc->n_bins > 0 ? 0.0 : 0.5 * sc->dr;
  profile_init(&o->prof, scene_bins(sc), edge, 2.0 * sc->delta - edge);
  series_init(&o->ts, N_SERIES, series_names, series_units);
  o->next_write = sc->write_every > 0.0 ? sc->write_every : INFINITY;
  return CHANSPH_OK;
}

int output_open(struct output *o, const char *dir, const struct scene *sc, int overwrite) {
  memset(o, 0, sizeof *o);
  snprintf(o->dir, sizeof o->dir, "%s", dir);
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
    double *d = realloc(ts->data, (dims[0] ? dims[0] : 1) * (size_t)ts->ncol * sizeof *d);
    if (!d) return NULL;
    ts->data = d, ts->cap = dims[0] ? dims[0] : 1;
  }
  ts->n = dims[0];
  return ts->data;
}

void output_state(struct output *o, struct state_list *L) {
  struct profile *pr = &o->prof;
  const size_t nb[1] = {(size_t)pr->nb};
  state_add(L, "stats/profile/sum_u", STATE_F64, 1, nb, pr->sum_u, "m/s");
  state_add(L, "stats/profile/sum_v", STATE_F64, 1, nb, pr->sum_v, "m/s");
  state_add(L, "stats/profile/sum_w", STATE_F64, 1, nb, pr->sum_w, "m/s");
  state_add(L, "stats/profile/sum_y", STATE_F64, 1, nb, pr->sum_y, "m");
  state_add(L, "stats/profile/count", STATE_I64, 1, nb, pr->count, NULL);
  state_add(L, "stats/profile/n_snapshots", STATE_I64, 0, NULL, &pr->n_snapshots, NULL);
  const size_t dims[2] = {o->ts.n, (size_t)o->ts.ncol};
  struct state_field *f = state_add(L, "stats/series", STATE_F64, 2, dims, o->ts.data, NULL);
  f->reserve = series_reserve, f->owner = &o->ts;
  state_add(L, "output/next_write", STATE_F64, 0, NULL, &o->next_write, "s");
}

void output_log(struct output *o, const char *fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
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

static void log_progress(struct output *o, struct sim *S, const struct diag *d) {
  const double now = timer_now();
  const double rate = now > o->last_wall
                          ? (double)S->P.n_fluid * (S->step - o->last_step) / (now - o->last_wall)
                          : 0.0;
  const double done = S->t - o->t0, left = S->sc->t_end - S->t;
  const double eta = done > 0.0 ? (now - o->wall0) * left / done : 0.0;
  const long es = (long)fmax(0.0, eta);
  output_log(o,
             "step %8ld  t %.6e  dt %.3e  u_bulk %.6e  force %.6e  max|v| %.4e  rho [%.6g, %.6g]"
             "  min_gamma %.4f  %.3e p-steps/s  ETA %02ld:%02ld:%02ld\n",
             S->step, S->t, S->dt, d->u_bulk, S->fx, d->max_speed, d->rho_min, d->rho_max,
             d->min_gamma, rate, es / 3600, es / 60 % 60, es % 60);
  o->last_wall = now, o->last_step = S->step;
}

static int write_stats(struct output *o, const struct sim *S) {
  const struct scene *sc = S->sc;
  char path[4096], err[4096];
  snprintf(path, sizeof path, "%s/stats.nc", o->dir);
  char drive[16], visc[16];
  snprintf(drive, sizeof drive, "%s", scene_choice("drive.mode", sc->drive_mode));
  snprintf(visc, sizeof visc, "%s", scene_choice("sph.viscous", sc->viscous));
  const struct nc_attr attrs[] = {
      {"dimension", NULL, sc->dim},
      {"delta", NULL, sc->delta},
      {"lx", NULL, sc->lx},
      {"lz", NULL, sc->lz},
      {"dr", NULL, sc->dr},
      {"h", NULL, scene_h(sc)},
      {"nu", NULL, sc->nu},
      {"rho0", NULL, sc->rho0},
      {"c0", NULL, sc->c0},
      {"xi", NULL, scene_xi(sc)},
      {"drive_mode", drive, 0},
      {"viscous", visc, 0},
      {"u_bulk_target", NULL, sc->drive_mode == DRIVE_FLUX ? sc->u_bulk : NAN},
      {"body_force", NULL, S->fx},
      {"t_average_start", NULL, sc->t_average_start},
      {"t_end", NULL, sc->t_end},
      {"t_reached", NULL, S->t},
      {"steps", NULL, (double)S->step},
      {"n_fluid", NULL, (double)S->P.n_fluid},
      {"n_snapshots", NULL, (double)o->prof.n_snapshots},
      {"code_version", CHANSPH_VERSION, 0},
      {"scene", o->scene_text, 0},
  };
  if (ncout_stats(path, &o->prof, &o->ts, attrs, sizeof attrs / sizeof attrs[0], err, sizeof err)) {
    error_input("%s", err);
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

void output_begin(struct output *o, struct sim *S) {
  struct diag d;
  record(o, S, &d);
  o->wall0 = o->last_wall = timer_now();
  o->t0 = S->t, o->last_step = o->step0 = S->step;
  output_log(o,
             "chansph %s: %zu fluid + %zu vertex particles, h = %.6g, dt limits: acoustic "
             "%.3e s, viscous %.3e s; output in %s\n",
             CHANSPH_VERSION, S->P.n_fluid, S->P.n_vertex, S->M.h, S->sc->cfl * S->M.h / S->sc->c0,
             S->sc->c_visc * S->M.h * S->M.h / S->sc->nu, o->dir);
  log_progress(o, S, &d);
}

void output_resume(struct output *o, struct sim *S) {
  timer_reset(); /* the phase report covers this process's steps */
  o->wall0 = o->last_wall = timer_now();
  o->t0 = S->t, o->last_step = o->step0 = S->step;
  output_log(o, "chansph %s: resumed at step %ld, t = %.9g s: %zu fluid + %zu vertex particles\n",
             CHANSPH_VERSION, S->step, S->t, S->P.n_fluid, S->P.n_vertex);
}

void output_step(struct output *o, struct sim *S) {
  const struct scene *sc = S->sc;
  timer_push("output");
  if (S->t >= sc->t_average_start && S->step % sc->stats_every == 0) {
    const struct particles *P = &S->P;
    profile_add(&o->prof, P->n, P->y, P->u, P->v, P->w, P->kind);
  }
  struct diag d;
  int have = 0;
  if (S->step % sc->series_every == 0) record(o, S, &d), have = 1;
  if (S->step % sc->log_every == 0) {
    if (!have) sim_diag(S, &d);
    log_progress(o, S, &d);
  }
  if (S->t >= o->next_write) {
    if (write_stats(o, S)) die("stopping: cannot write statistics");
    while (o->next_write <= S->t) o->next_write += sc->write_every;
  }
  timer_pop();
}

static int write_particles(struct output *o, const struct sim *S) {
  const struct particles *P = &S->P;
  const size_t n = P->n_fluid;
  enum { NC = 10 };
  double *buf = malloc(n * NC * sizeof *buf);
  long long *ids = malloc(n * sizeof *ids);
  if (!buf || !ids) die("out of memory writing particles.nc");
  const double *src[NC] = {P->x, P->y, P->z, P->u, P->v, P->w, P->rho, P->p, P->gam, P->m};
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    const size_t r = (size_t)P->id[a]; /* fluid ids are 0 .. n_fluid-1 */
    ids[r] = P->id[a];
    for (int c = 0; c < NC; c++) buf[(size_t)c * n + r] = src[c][a];
  }
  static const char *const names[NC] = {"x", "y", "z", "u", "v", "w", "rho", "p", "gamma", "mass"};
  static const char *const units[NC] = {"m",   "m",      "m",  "m/s", "m/s",
                                        "m/s", "kg/m^3", "Pa", "1",   "kg"};
  const double *cols[NC];
  for (int c = 0; c < NC; c++) cols[c] = buf + (size_t)c * n;
  const struct nc_attr attrs[] = {
      {"time", NULL, S->t}, {"step", NULL, (double)S->step}, {"scene", o->scene_text, 0}};
  char path[4096], err[4096];
  snprintf(path, sizeof path, "%s/particles.nc", o->dir);
  const int rc =
      ncout_columns(path, "particle", n, NC, names, units, cols, ids, attrs, 3, err, sizeof err);
  free(buf), free(ids);
  if (rc) error_input("%s", err);
  return rc ? CHANSPH_ERR : CHANSPH_OK;
}

int output_finish(struct output *o, struct sim *S) {
  struct diag d;
  if (o->ts.n == 0 || o->ts.data[(o->ts.n - 1) * (size_t)o->ts.ncol] != S->t)
    record(o, S, &d);
  else
    sim_diag(S, &d);
  if (S->step != o->last_step) log_progress(o, S, &d);
  const double wall = timer_now() - o->wall0;
  TRY(write_stats(o, S));
  if (S->sc->particles) TRY(write_particles(o, S));
  output_log(o, "finished: %ld steps, t = %.6g s in %.2f s wall (%.3e particle-steps/s)\n", S->step,
             S->t, wall, wall > 0 ? (double)S->P.n_fluid * (S->step - o->step0) / wall : 0.0);
  timer_report(stdout, wall);
  if (o->log) timer_report(o->log, wall);
  output_log(o, "results: %s/stats.nc%s\n", o->dir, S->sc->particles ? ", particles.nc" : "");
  return CHANSPH_OK;
}

int output_stop(struct output *o, struct sim *S, const char *why) {
  const double wall = timer_now() - o->wall0;
  TRY(write_stats(o, S));
  output_log(o, "stopped at step %ld, t = %.9g s (%s) after %.2f s wall\n", S->step, S->t, why,
             wall);
  timer_report(stdout, wall);
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
  profile_free(&o->prof);
  series_free(&o->ts);
  memset(o, 0, sizeof *o);
}
