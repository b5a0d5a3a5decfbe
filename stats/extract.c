/** @file extract.c @brief Implementation of extract.h. */
#include "extract.h"
#include "alloc.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <netcdf.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "corr.h"
#include "engine.h"
#include "euler.h"
#include "euler_rs.h"
#include "lagr.h"
#include "moments.h"
#include "ncutil.h"
#include "pdf.h"
#include "quad.h"

/** How a profile scales: velocity, stress, pressure, length, or not at all. */
enum unit_class { UC_NONE, UC_VEL, UC_STRESS, UC_PRESSURE, UC_LENGTH, UC_VISC, UC_BUDGET };

static enum unit_class class_of(int k) {
  if (k >= EP_RSB && k < EP_RSB_SE_END) return UC_BUDGET; /* m^2/s^3: u_tau^4/nu */
  if (k >= EP_SE_SF && k < EP_SE_SF_END) return UC_NONE;  /* of skewness and flatness */
  switch (k) {
    case EP_Y:
    case EP_Y_MEAN:
      return UC_LENGTH;
    case EP_U:
    case EP_V:
    case EP_W:
    case EP_SE_U + 0:
    case EP_SE_U + 1:
    case EP_SE_U + 2:
      return UC_VEL;
    case EP_P:
    case EP_SE_U + 3:
      return UC_PRESSURE;
    case EP_NUT:
      return UC_VISC;
    case EP_RHO:
    case EP_SE_U + 4:
    case EP_N:
      return UC_NONE;
    default:
      return k >= EP_SKEW_U && k <= EP_FLAT_W ? UC_NONE : UC_STRESS;
  }
}

static int find_prof(const char *name) {
  for (int k = 0; k < EP_NPROF; k++)
    if (!strcmp(euler_prof_meta[k].name, name)) return k;
  return -1;
}

/* A file's place in a run (global attributes): the runs it holds, the state its first segment
   started from and the state its last one ended in, and the flow it simulated. */
struct origin {
  char from_id[128]; /* init_from_run_id: "" if absent (written before it was recorded) */
  double from_t;     /* init_from_time [s], NaN if absent */
  char *ids;         /* segment_run_ids, else run_id ("" if absent): "; " between runs */
  double end_t;      /* the time its last segment ended (segment_end_time, else t_reached) */
  double steps;      /* the time steps of its segments (steps; summed by a join), NaN if absent */
  char drive[16];    /* drive_mode */
  double dim, lx, lz, dr, force; /* dimension, the box, body_force (force mode: constant) */
};

/* The stored windows of stats.nc and the configuration they were gathered with. */
struct stored {
  struct euler_config cfg;
  size_t rows;
  double *win, *mom, *snp, *pln; /* pln: NULL in a file without the momentum budget */
  double *kin;                   /* NULL in a file without its kinetic flux (before 1.4) */
  double *rsb;                   /* NULL without the Reynolds-stress budget (before 1.6) */
  double *tpl, *tkn;             /* the total of every snapshot: NULL before 1.14 */
  int *complete;
  double t_reached; /* the run's reached time (global attribute t_reached; NaN if absent) */
  struct origin o;  /* what makes it one run's segment */
};

static int get_att(int ncid, const char *name, double *v, const char *path) {
  if (nc_get_att_double(ncid, NC_GLOBAL, name, v) != NC_NOERR) {
    fprintf(stderr, "error: %s: no global attribute '%s' (not a chansph stats.nc?)\n", path, name);
    return 1;
  }
  return 0;
}

/* The optional per-window records `var` of group g (rows x bins = len records of n fields,
   the field count the length of dimension `dim`) into *out; absent: *out stays NULL. A field
   count other than n is an error if strict, else the records are left out. Returns nonzero
   on an error (printed, naming what). */
static int read_records(int g, const char *var, const char *dim, size_t n, size_t len, int strict,
                        const char *path, const char *what, double **out) {
  int v, d;
  size_t have = 0;
  if (nc_inq_varid(g, var, &v) != NC_NOERR) return 0;
  if (nc_inq_dimid(g, dim, &d) || nc_inq_dimlen(g, d, &have) || have != n) {
    fprintf(stderr, "%s: %s: %s (%s) have %zu fields, not %zu%s\n", strict ? "error" : "note", path,
            what, var, have, n, strict ? "" : " (an earlier format): left out");
    return strict;
  }
  *out = mem_alloc(1, len * n * sizeof(double), "chansph extract");
  if (nc_get_var_double(g, v, *out) != NC_NOERR) {
    fprintf(stderr, "error: %s: cannot read the raw windows (%s)\n", path, var);
    return 1;
  }
  return 0;
}

/* Global text attribute name of ncid into buf (len bytes); "" if absent or too long. */
static void get_text(int ncid, const char *name, char *buf, size_t len) {
  size_t n = 0;
  buf[0] = '\0';
  if (nc_inq_attlen(ncid, NC_GLOBAL, name, &n) || n >= len ||
      nc_get_att_text(ncid, NC_GLOBAL, name, buf))
    n = 0;
  buf[n] = '\0';
}

/* Global double attribute name of ncid, or NaN. */
static double get_num(int ncid, const char *name) {
  double v;
  return nc_get_att_double(ncid, NC_GLOBAL, name, &v) == NC_NOERR ? v : NAN;
}

/* The origin of file ncid (t_reached read before). */
static void read_origin(int ncid, struct stored *s) {
  struct origin *o = &s->o;
  get_text(ncid, "init_from_run_id", o->from_id, sizeof o->from_id);
  get_text(ncid, "drive_mode", o->drive, sizeof o->drive);
  o->from_t = get_num(ncid, "init_from_time"), o->end_t = get_num(ncid, "segment_end_time");
  if (isnan(o->end_t)) o->end_t = s->t_reached;
  o->steps = get_num(ncid, "steps");
  o->dim = get_num(ncid, "dimension"), o->lx = get_num(ncid, "lx"), o->lz = get_num(ncid, "lz");
  o->dr = get_num(ncid, "dr"), o->force = get_num(ncid, "body_force");
  size_t n = 0;
  const char *name =
      nc_inq_attlen(ncid, NC_GLOBAL, "segment_run_ids", &n) ? "run_id" : "segment_run_ids";
  if (nc_inq_attlen(ncid, NC_GLOBAL, name, &n)) n = 0;
  o->ids = mem_calloc(n + 1, 1, "chansph extract");
  if (n && nc_get_att_text(ncid, NC_GLOBAL, name, o->ids)) o->ids[0] = '\0';
}

static int read_stored(const char *path, struct stored *s) {
  memset(s, 0, sizeof *s);
  int ncid, g, rc = nc_open(path, NC_NOWRITE, &ncid);
  if (rc != NC_NOERR) {
    fprintf(stderr, "error: %s: %s\n", path, nc_strerror(rc));
    return 1;
  }
  double fold = 0, area = 0;
  int bad =
      get_att(ncid, "delta", &s->cfg.delta, path) || get_att(ncid, "nu", &s->cfg.nu, path) ||
      get_att(ncid, "rho0", &s->cfg.rho0, path) || get_att(ncid, "bin_lower", &s->cfg.y0, path) ||
      get_att(ncid, "bin_upper", &s->cfg.y1, path) || get_att(ncid, "wall_area", &area, path) ||
      get_att(ncid, "fold", &fold, path) || get_att(ncid, "window_length", &s->cfg.window, path);
  s->cfg.fold = (int)fold, s->cfg.area = area;
  double les = 0.0; /* optional: eddy-viscosity profiles present */
  if (!bad && nc_get_att_double(ncid, NC_GLOBAL, "les", &les) != NC_NOERR) les = 0.0;
  s->cfg.les = les != 0.0;
  if (nc_get_att_double(ncid, NC_GLOBAL, "t_reached", &s->t_reached) != NC_NOERR)
    s->t_reached = NAN;
  read_origin(ncid, s);
  int dy, dw, vw, vm, vs, vc;
  size_t nb = 0;
  if (!bad && (nc_inq_ncid(ncid, "eulerian", &g) || nc_inq_dimid(ncid, "y", &dy) ||
               nc_inq_dimlen(ncid, dy, &nb) || nc_inq_dimid(g, "window", &dw) ||
               nc_inq_dimlen(g, dw, &s->rows) || nc_inq_varid(g, "windows", &vw) ||
               nc_inq_varid(g, "moments", &vm) || nc_inq_varid(g, "snapshot_u", &vs) ||
               nc_inq_varid(g, "window_complete", &vc))) {
    fprintf(stderr, "error: %s: no group 'eulerian' with the raw windows\n", path);
    bad = 1;
  }
  if (!bad) {
    s->cfg.nb = (int)nb;
    const size_t r = s->rows ? s->rows : 1;
    s->win = mem_alloc(1, r * WIN_LEN * sizeof(double), "chansph extract");
    s->mom = mem_alloc(1, r * nb * MOM_LEN * sizeof(double), "chansph extract");
    s->snp = mem_alloc(1, r * nb * SCAL_LEN * sizeof(double), "chansph extract");
    s->complete = mem_alloc(1, r * sizeof(int), "chansph extract");
    if (s->rows &&
        (nc_get_var_double(g, vw, s->win) || euler_nc_read_moments(g, vm, r * nb, s->mom) ||
         nc_get_var_double(g, vs, s->snp) || nc_get_var_int(g, vc, s->complete))) {
      fprintf(stderr, "error: %s: cannot read the raw windows\n", path);
      bad = 1;
    }
    /* the optional records: absent in files of earlier versions (the momentum budget; its
       kinetic flux, before format 1.4, where another field count leaves them out: no
       advective part; the Reynolds-stress budgets, before 1.6, and those of 1.6, whose
       fluctuations were about the bin's mean, not the local mean of 1.7) */
    const size_t len = r * nb;
    bad =
        bad || (s->rows && (read_records(g, "planes", "plane_field", PL_LEN, len, 1, path,
                                         "the momentum-budget records", &s->pln) ||
                            read_records(g, "planes_kinetic", "kinetic_field", KN_LEN, len, 0, path,
                                         "the kinetic-flux records", &s->kin) ||
                            read_records(g, "reynolds_budget", "reynolds_budget_field", RW_LEN, len,
                                         0, path, "the Reynolds-stress budget records", &s->rsb) ||
                            read_records(g, "planes_total", "plane_field", PL_LEN, len, 0, path,
                                         "the total's records", &s->tpl) ||
                            read_records(g, "planes_total_kinetic", "kinetic_field", KN_LEN, len, 0,
                                         path, "the total's kinetic records", &s->tkn)));
    if (!s->tpl || !s->tkn) free(s->tpl), free(s->tkn), s->tpl = s->tkn = NULL;
  }
  CHECK_NC(nc_close(ncid));
  return bad;
}

static void free_stored(struct stored *s) {
  free(s->win), free(s->mom), free(s->snp), free(s->pln), free(s->kin), free(s->rsb), free(s->tpl),
      free(s->tkn), free(s->complete), free(s->o.ids);
}

/* Whether segment b (path pb) was gathered as segment a (pa) was; prints what differs. */
static int same_gathering(const struct stored *a, const struct stored *b, const char *pa,
                          const char *pb) {
  const struct {
    const char *name;
    double x, y;
  } key[] = {{"delta", a->cfg.delta, b->cfg.delta}, {"nu", a->cfg.nu, b->cfg.nu},
             {"rho0", a->cfg.rho0, b->cfg.rho0},    {"bin_lower", a->cfg.y0, b->cfg.y0},
             {"bin_upper", a->cfg.y1, b->cfg.y1},   {"wall_area", a->cfg.area, b->cfg.area},
             {"fold", a->cfg.fold, b->cfg.fold},    {"window_length", a->cfg.window, b->cfg.window},
             {"les", a->cfg.les, b->cfg.les},       {"bins (dimension y)", a->cfg.nb, b->cfg.nb}};
  for (size_t k = 0; k < sizeof key / sizeof key[0]; k++)
    if (key[k].x != key[k].y) {
      fprintf(stderr,
              "error: %s: %s %.9g, but %s has %.9g: not a later segment of the same run "
              "(the same scene continued with init.from)\n",
              pb, key[k].name, key[k].y, pa, key[k].x);
      return 0;
    }
  const struct {
    const char *name;
    int x, y;
  } rec[] = {{"the momentum-budget records (planes)", a->pln != NULL, b->pln != NULL},
             {"the kinetic-flux records (planes_kinetic)", a->kin != NULL, b->kin != NULL}};
  for (size_t k = 0; k < sizeof rec / sizeof rec[0]; k++)
    if (rec[k].x != rec[k].y) {
      fprintf(stderr,
              "error: %s: %s %s, but %s %s them: segments of one format are joined (run "
              "both with one version)\n",
              pb, rec[k].y ? "holds" : "lacks", rec[k].name, pa, rec[k].x ? "holds" : "lacks");
      return 0;
    }
  return 1;
}

/* Whether the flow of b (path pb) is that of a (pa): dimension, box, resolution, drive (in
   force mode the body force); prints what differs. */
static int same_flow(const struct stored *a, const struct stored *b, const char *pa,
                     const char *pb) {
  const struct origin *x = &a->o, *y = &b->o;
  if (strcmp(x->drive, y->drive)) {
    fprintf(stderr,
            "error: %s: drive_mode '%s', but %s has '%s': not the same flow, not joined "
            "(average each run on its own)\n",
            pb, y->drive, pa, x->drive);
    return 0;
  }
  const int force = !strcmp(x->drive, "force");
  const struct {
    const char *name;
    double x, y;
  } key[] = {{"dimension", x->dim, y->dim},
             {"lx", x->lx, y->lx},
             {"lz", x->lz, y->lz},
             {"dr", x->dr, y->dr},
             {"body_force", force ? x->force : 0.0, force ? y->force : 0.0}};
  for (size_t k = 0; k < sizeof key / sizeof key[0]; k++) {
    const double u = key[k].x, v = key[k].y;
    if ((isnan(u) && isnan(v)) || fabs(u - v) <= 1e-12 * fmax(fabs(u), fabs(v))) continue;
    fprintf(stderr,
            "error: %s: %s %.9g, but %s has %.9g: not the same flow, not joined (average each "
            "run on its own)\n",
            pb, key[k].name, v, pa, u);
    return 0;
  }
  return 1;
}

/* The last run of the list ids ("; " between runs). */
static const char *last_id(const char *ids) {
  const char *semi = strrchr(ids, ';');
  return semi ? semi + 2 : ids;
}

/* Whether the list ids holds run id. */
static int holds_id(const char *ids, const char *id, size_t n) {
  for (const char *p = ids; *p;) {
    const char *semi = strchr(p, ';');
    const size_t len = semi ? (size_t)(semi - p) : strlen(p);
    if (len == n && !strncmp(p, id, n)) return 1;
    if (!semi) break;
    p = semi + 2;
  }
  return 0;
}

/* Whether b (path pb) is the continuation of the chain a ends (path pa: its last file): it
   holds no run a holds, and it started (init.from) from the state a's last run ended in.
   force: a segment whose start was not recorded (a file of an earlier version, or a source
   without run_id) is taken on the user's word. Prints why not. */
static int continues(const struct stored *a, const struct stored *b, const char *pa, const char *pb,
                     int force) {
  const struct origin *x = &a->o, *y = &b->o;
  for (const char *p = y->ids; *p;) { /* a run in both: the same segment twice */
    const char *semi = strchr(p, ';');
    const size_t n = semi ? (size_t)(semi - p) : strlen(p);
    if (holds_id(x->ids, p, n)) {
      fprintf(stderr,
              "error: %s: holds the statistics of run %.*s, which the files before it hold "
              "already (%s: the same file twice, a copy of it, or a segment a joined file "
              "holds): give each segment once, in order\n",
              pb, (int)n, p, pa);
      return 0;
    }
    if (!semi) break;
    p = semi + 2;
  }
  const char *end_id = last_id(x->ids);
  if (!strcmp(y->from_id, "none")) {
    fprintf(stderr,
            "error: %s: started from the scene's initial condition, not from the final state of "
            "%s: an independent run, not its continuation (continue a run with init.from = its "
            "final particles.nc)\n",
            pb, pa);
    return 0;
  }
  if (!y->from_id[0] || !strcmp(y->from_id, "unknown") || isnan(y->from_t)) {
    if (force) return 1;
    fprintf(stderr,
            "error: %s: does not record the state it started from (%s): extract cannot check "
            "that it continues %s (run %s, t = %.9g); if it was started with init.from = that "
            "run's final particles.nc, join them with --force\n",
            pb, y->from_id[0] ? "its init.from file has no run_id" : "written before chansph did",
            pa, end_id, x->end_t);
    return 0;
  }
  if (strcmp(y->from_id, end_id) && holds_id(x->ids, y->from_id, strlen(y->from_id))) {
    fprintf(stderr,
            "error: %s: started from the state of run %s at t = %.9g, an earlier segment than "
            "the last of %s (run %s): the segments overlap in time (two continuations of one "
            "state are two runs; join one of them)\n",
            pb, y->from_id, y->from_t, pa, end_id);
    return 0;
  }
  if (strcmp(y->from_id, end_id)) {
    fprintf(stderr,
            "error: %s: started from the state of run %s at t = %.9g, but %s ends with run %s: "
            "not its continuation (segments out of order, or of another run; give them in "
            "the order they ran)\n",
            pb, y->from_id, y->from_t, pa, end_id);
    return 0;
  }
  if (!(fabs(y->from_t - x->end_t) <= 1e-9 * fmax(1.0, fabs(x->end_t)))) {
    fprintf(stderr,
            "error: %s: started from the state of run %s at t = %.9g, but the statistics of %s "
            "end at t = %.9g: the segments %s in time (continue from the final state; two "
            "continuations of one state are two runs)\n",
            pb, end_id, y->from_t, pa, x->end_t, y->from_t < x->end_t ? "overlap" : "leave a gap");
    return 0;
  }
  return 1;
}

/* Append the rows of b (rows_b of len doubles) to *a (rows_a rows); *a stays NULL if NULL. */
static void append_rows(double **a, size_t rows_a, const double *b, size_t rows_b, size_t len) {
  if (!*a) return;
  *a = mem_realloc(*a, (rows_a + rows_b) * len, sizeof(double), "chansph extract");
  memcpy(*a + rows_a * len, b, rows_b * len * sizeof(double));
}

/* Shift by offset the times of rows r0 .. r1-1 of s: the windows' bounds, and the times of the
   first and last budget snapshot that the momentum and Reynolds-stress budgets keep (their
   rates of change divide by the span between them; rows without a snapshot keep zeros). */
static void shift_times(struct stored *s, size_t r0, size_t r1, double offset) {
  const size_t nb = (size_t)s->cfg.nb;
  for (size_t r = r0; r < r1; r++) {
    s->win[r * WIN_LEN + WIN_T0] += offset, s->win[r * WIN_LEN + WIN_T1] += offset;
    for (size_t b = 0; b < nb; b++) {
      double *P = s->pln ? s->pln + (r * nb + b) * PL_LEN : NULL;
      double *W = s->rsb ? s->rsb + (r * nb + b) * RW_LEN : NULL;
      double *T = s->tpl ? s->tpl + (r * nb + b) * PL_LEN : NULL;
      if (P && P[PL_N] > 0.0) P[PL_T_FIRST] += offset, P[PL_T_LAST] += offset;
      if (T && T[PL_N] > 0.0) T[PL_T_FIRST] += offset, T[PL_T_LAST] += offset;
      if (W && W[RW_SUM + RB_N] > 0.0) W[RW_T_FIRST] += offset, W[RW_T_LAST] += offset;
    }
  }
}

/* The segments seg[0..n-1] (paths) of one run, each started from the final state of the one
   before (init.from), joined into seg[0] as the windows of one run: each segment's times
   shifted by the sum of the reached times of those before it (each starts at t = 0). The
   others are freed. Nonzero on an input error (printed, naming the file). */
static int join_stored(struct stored *seg, int n, char *const *paths, int force) {
  struct stored *s = &seg[0];
  double offset = 0.0;
  int bad = 0;
  for (int k = 1; k < n; k++) {
    const struct stored *b = &seg[k];
    offset += seg[k - 1].t_reached;
    if (!isfinite(seg[k - 1].t_reached)) {
      fprintf(stderr, "error: %s: no attribute t_reached: cannot place the next segment\n",
              paths[k - 1]);
      bad = 1;
    }
    if (bad || !same_flow(s, b, paths[0], paths[k]) ||
        !continues(s, b, paths[k - 1], paths[k], force) ||
        !same_gathering(s, b, paths[0], paths[k])) {
      bad = 1;
      break;
    }
    /* the open last window of the segment before: whole if the segment ran to its end (the
       snapshot that would have closed it is the next segment's first); else left out */
    if (s->rows && !s->complete[s->rows - 1]) {
      const double *last = s->win + (s->rows - 1) * WIN_LEN;
      if (last[WIN_T1] <= offset + 1e-6 * s->cfg.window)
        s->complete[s->rows - 1] = 1;
      else
        fprintf(stderr,
                "note: %s: its last window (t = %.9g .. %.9g) is open, the segment ended at "
                "%.9g: left out of the averages (end a segment at a window boundary)\n",
                paths[k - 1], last[WIN_T0], last[WIN_T1], offset);
    }
    if (s->rsb && !b->rsb) {
      fprintf(stderr,
              "note: %s: no Reynolds-stress budget records of this format: the joined "
              "range has none\n",
              paths[k]);
      free(s->rsb), s->rsb = NULL;
    }
    if (s->tpl && !b->tpl) {
      fprintf(stderr,
              "note: %s: no records of the total of every snapshot (before format 1.14): the "
              "joined range takes its total from the budget snapshots' parts\n",
              paths[k]);
      free(s->tpl), free(s->tkn), s->tpl = s->tkn = NULL;
    }
    const size_t nb = (size_t)s->cfg.nb, ra = s->rows, rb = b->rows;
    append_rows(&s->win, ra, b->win, rb, WIN_LEN);
    append_rows(&s->mom, ra, b->mom, rb, nb * MOM_LEN);
    append_rows(&s->snp, ra, b->snp, rb, nb * SCAL_LEN);
    append_rows(&s->pln, ra, b->pln, rb, nb * PL_LEN);
    append_rows(&s->kin, ra, b->kin, rb, nb * KN_LEN);
    append_rows(&s->rsb, ra, b->rsb, rb, nb * RW_LEN);
    append_rows(&s->tpl, ra, b->tpl, rb, nb * PL_LEN);
    append_rows(&s->tkn, ra, b->tkn, rb, nb * KN_LEN);
    shift_times(s, ra, ra + rb, offset);
    s->complete = mem_realloc(s->complete, ra + rb, sizeof(int), "chansph extract");
    memcpy(s->complete + ra, b->complete, rb * sizeof(int));
    s->rows = ra + rb, s->t_reached = offset + b->t_reached;
    const size_t la = strlen(s->o.ids), lb = strlen(b->o.ids);
    s->o.ids = mem_realloc(s->o.ids, la + lb + 3, 1, "chansph extract");
    memcpy(s->o.ids + la, "; ", 2), memcpy(s->o.ids + la + 2, b->o.ids, lb + 1);
    s->o.end_t = b->o.end_t, s->o.steps += b->o.steps;
  }
  for (int k = 1; k < n; k++) free_stored(&seg[k]);
  return bad;
}

/* A time of --window between text and stop: empty gives dflt; anything but one finite number
   is an error (nonzero). */
static int parse_time(const char *text, const char *stop, double dflt, double *t) {
  if (text == stop) {
    *t = dflt;
    return 0;
  }
  char *end;
  errno = 0;
  *t = strtod(text, &end);
  return end != stop || errno || !isfinite(*t);
}

static void usage(FILE *f) {
  fprintf(f,
          "usage: chansph extract STATS.nc [LATER.nc ...] [--var a,b,...] [--units wall|outer] "
          "[--format csv|tsv] [--window T0:T1] [--pdfs] [--nc OUT.nc] [--force]\n"
          "  LATER.nc ...: the stats.nc of later segments of the same run, each started from the "
          "final\n"
          "    state of the one before (init.from, e.g. on another machine): their windows are "
          "joined\n"
          "    on one time axis (each segment's times shifted by the reached times of those "
          "before it);\n"
          "    refused (exit 1): a segment twice, out of order, overlapping or leaving a gap, "
          "from rest,\n"
          "    another flow (dimension, box, dr, drive, body force) or gathered otherwise\n"
          "  --force: join a segment that does not record the state it started from (a file "
          "of an earlier\n"
          "    version) on your word that it continued the one before; the other checks stay\n"
          "  variables: u_mean v_mean w_mean p_mean rho_mean uu vv ww uv uw vw u_rms v_rms "
          "w_rms\n"
          "  u_skewness ... w_flatness viscous_stress total_stress total_stress_expected "
          "n_samples y_mean nu_t_mean k_r_mean (LES)\n"
          "  (standard errors are printed next to the variables that have them)\n"
          "  --pdfs: the one-point PDFs of group pdfs instead (rows y_plus, component, bin in "
          "units of the rms, pdf, pdf_stderr; the moments in the header)\n"
          "  --nc OUT.nc: write the windows of --window as a stats.nc instead (the root "
          "profiles and\n"
          "    attributes averaged over them and their raw group eulerian; group correlations "
          "re-averaged\n"
          "    over its windows in the range, or copied whole from a file without its window "
          "records;\n"
          "    the other groups left out; of joined segments, over the whole range, groups "
          "lagrangian and\n"
          "    quadrants pooled over the segments' completed releases and windows):\n"
          "    what `chansph compare` and `extract` read, e.g. a long run's developed range\n");
}

/* The most segments extract joins. */
enum { EXTRACT_MAX_SEGMENTS = 64 };

/* The options of one extract command. */
struct extract_args {
  const char *path, *vars, *units, *fmt; /* path: the first of paths */
  char *paths[EXTRACT_MAX_SEGMENTS];     /* the segments of one run, in order */
  int npaths;
  double t0, t1;      /* --window */
  int pdfs;           /* --pdfs */
  int force;          /* --force: join segments whose start was not recorded */
  const char *nc_out; /* --nc: write the range as a stats.nc instead of a table */
};

/* What follows the first file's name in messages: the later segments, if any. */
static const char *later_segments(const struct extract_args *a) {
  return a->npaths > 1 ? " and its later segments" : "";
}

/* More than EXTRACT_MAX_SEGMENTS files (the first left over: path); 1. */
static int too_many(const char *path) {
  fprintf(stderr,
          "error: %s: more than %d files: extract joins at most %d segments at once (join them "
          "in groups with --nc, then join the joined files)\n",
          path, EXTRACT_MAX_SEGMENTS, EXTRACT_MAX_SEGMENTS);
  return 1;
}

/* Parse the command line (argv[0]: the command name); 1: input error, -1: --help printed. */
static int extract_parse(int argc, char **argv, struct extract_args *a) {
  static const struct option opts[] = {{"help", no_argument, NULL, 'h'},
                                       {"var", required_argument, NULL, 'v'},
                                       {"units", required_argument, NULL, 'u'},
                                       {"format", required_argument, NULL, 'f'},
                                       {"window", required_argument, NULL, 'w'},
                                       {"pdfs", no_argument, NULL, 'p'},
                                       {"nc", required_argument, NULL, 'n'},
                                       {"force", no_argument, NULL, 'F'},
                                       {NULL, 0, NULL, 0}};
  *a = (struct extract_args){.vars = "u_mean,u_rms,v_rms,w_rms,uv",
                             .units = "wall",
                             .fmt = "csv",
                             .t0 = -INFINITY,
                             .t1 = INFINITY};
  opterr = 0, optind = 1; /* "-": positional arguments in order (code 1); ':' missing value */
  for (;;) {
    const int at = optind, code = getopt_long(argc, argv, "-:h", opts, NULL);
    if (code == -1) break;
    if (code == 'h') {
      usage(stdout);
      return -1;
    }
    if (code == 'p' || code == 'F') {
      *(code == 'p' ? &a->pdfs : &a->force) = 1;
    } else if (code == 'n') {
      a->nc_out = optarg;
    } else if (code == 'v' || code == 'u' || code == 'f') {
      *(code == 'v' ? &a->vars : code == 'u' ? &a->units : &a->fmt) = optarg;
    } else if (code == 'w') {
      const char *w = optarg, *colon = strchr(w, ':');
      if (!colon || parse_time(w, colon, -INFINITY, &a->t0) ||
          parse_time(colon + 1, colon + strlen(colon), INFINITY, &a->t1) || a->t0 > a->t1) {
        fprintf(stderr,
                "error: --window %s: expected T0:T1, two times in seconds with T0 <= T1 (either "
                "may be empty: from the first or to the last window)\n",
                w);
        return 1;
      }
    } else if (code == 1 && a->npaths < EXTRACT_MAX_SEGMENTS) {
      a->paths[a->npaths++] = optarg;
    } else if (code == 1) {
      return too_many(optarg);
    } else {
      fprintf(stderr, "error: unexpected argument '%s'\n", code == 1 ? optarg : argv[at]);
      usage(stderr);
      return 1;
    }
  }
  while (optind < argc && a->npaths < EXTRACT_MAX_SEGMENTS) /* after "--" */
    a->paths[a->npaths++] = argv[optind++];
  if (optind < argc) return too_many(argv[optind]);
  a->path = a->npaths ? a->paths[0] : NULL;
  if (a->pdfs && a->npaths > 1) {
    fprintf(stderr, "error: --pdfs reads one stats.nc, not the %d given\n", a->npaths);
    return 1;
  }
  if (!a->path || optind < argc || (strcmp(a->units, "wall") && strcmp(a->units, "outer")) ||
      (strcmp(a->fmt, "csv") && strcmp(a->fmt, "tsv"))) {
    usage(stderr);
    return 1;
  }
  return 0;
}

/* The columns of --var: profile index and whether it is printed as an rms; -1 on error. */
static int extract_columns(const char *vars, int *cols, int *rms, int max) {
  int nc = 0;
  char *list = strdup(vars);
  for (char *tok = strtok(list, ","); tok && nc < max; tok = strtok(NULL, ",")) {
    int k = find_prof(tok), is_rms = 0;
    if (k < 0 && strlen(tok) == 5 && !strcmp(tok + 1, "_rms") && strchr("uvw", tok[0]))
      k = EP_UU + (tok[0] - 'u'), is_rms = 1;
    if (k < 0) {
      fprintf(stderr, "error: unknown variable '%s'\n", tok);
      usage(stderr);
      free(list);
      return -1;
    }
    cols[nc] = k, rms[nc++] = is_rms;
  }
  free(list);
  return nc;
}

/* The factor that takes profile k to wall units (wall) or outer units. */
static double extract_scale(int k, int wall, const struct euler_config *cfg, double ut) {
  if (!wall) return class_of(k) == UC_LENGTH ? 1.0 / cfg->delta : 1.0;
  switch (class_of(k)) {
    case UC_VEL:
      return 1.0 / ut;
    case UC_STRESS:
      return 1.0 / (ut * ut);
    case UC_PRESSURE:
      return 1.0 / (cfg->rho0 * ut * ut);
    case UC_LENGTH:
      return ut / cfg->nu;
    case UC_VISC:
      return 1.0 / cfg->nu;
    case UC_BUDGET:
      return cfg->nu / (ut * ut * ut * ut);
    case UC_NONE:
      break;
  }
  return 1.0;
}

/* The profile of the standard error of profile k, or -1. */
static int stderr_of(int k) {
  if (k >= EP_SKEW_U && k <= EP_FLAT_W) return EP_SE_SF + (k - EP_SKEW_U);
  return k >= EP_U && k <= EP_VW ? EP_SE_U + (k - EP_U) : -1;
}

/* The header lines and the column names. */
static void extract_header(const struct extract_args *a, const struct stored *s,
                           const struct euler_result *res, size_t r0, size_t r1, const int *cols,
                           const int *rms, int nc) {
  const int wall = !strcmp(a->units, "wall");
  const char sep = !strcmp(a->fmt, "csv") ? ',' : '\t';
  /* a run that stopped inside its last window reached t_reached, not the window's end */
  const double t_last = isnan(s->t_reached) ? res->t1 : fmin(res->t1, s->t_reached);
  printf(
      "# chansph extract %s%s: windows %zu..%zu, t = %.9g .. %.9g s, %.0f snapshots, %d "
      "batches\n",
      a->path, later_segments(a), r0, r1 - 1, res->t0, t_last, res->snapshots, res->n_batches);
  printf(
      "# u_tau = %.9g m/s (wall shear %.9g, force balance %.9g, stderr %.3g), Re_tau = %.6g, "
      "correlation time %.4g s, stress balance error %.4g\n",
      res->u_tau, res->u_tau_wall, res->u_tau_force, res->u_tau_stderr, res->re_tau, res->corr_time,
      res->balance_error);
  printf("# units: %s\n", wall ? "wall (y+ = y u_tau/nu, velocities/u_tau, stresses/u_tau^2, "
                                 "p/(rho0 u_tau^2), nu_t/nu, budgets rsb_* / (u_tau^4/nu))"
                               : "outer (y/delta; values in SI units)");
  printf("%s%c%s", "y", sep, wall ? "y_plus" : "y_over_delta");
  for (int c = 0; c < nc; c++) {
    const char *name = euler_prof_meta[cols[c]].name;
    char rname[16];
    if (rms[c]) snprintf(rname, sizeof rname, "%c_rms", name[0]), name = rname;
    printf("%c%s", sep, name);
    if (stderr_of(cols[c]) >= 0) printf("%c%s_stderr", sep, name);
  }
  printf("\n");
}

/* One row per bin: y, y+ or y/delta, then each column (and its standard error). */
static void extract_rows(const struct extract_args *a, const struct stored *s,
                         const struct euler_result *res, const int *cols, const int *rms, int nc) {
  const int wall = !strcmp(a->units, "wall");
  const char sep = !strcmp(a->fmt, "csv") ? ',' : '\t';
  const double ut = res->u_tau;
  for (int b = 0; b < res->nb; b++) {
    const double y = res->prof[EP_Y_MEAN][b];
    printf("%.9g%c%.9g", y, sep, wall ? y * ut / s->cfg.nu : y / s->cfg.delta);
    for (int c = 0; c < nc; c++) {
      const int k = cols[c], se = stderr_of(k);
      const double scale = extract_scale(k, wall, &s->cfg, ut);
      double v = res->prof[k][b] * scale, e = se >= 0 ? res->prof[se][b] * scale : NAN;
      if (rms[c]) { /* rms and its standard error by the delta method */
        const double r = sqrt(res->prof[k][b]) * (wall ? 1.0 / ut : 1.0);
        e = r > 0 ? 0.5 * e / r : NAN, v = r;
      }
      printf("%c%.9g", sep, v);
      if (se >= 0) printf("%c%.9g", sep, e);
    }
    printf("\n");
  }
}

/* The rows r0 .. r1-1 of the windows (rows of len doubles, nominal start and end first) wholly
   inside --window (with a relative tolerance for the nominal bounds); 1 if there is none. */
static int window_range(const struct extract_args *a, const double *win, size_t len, size_t rows,
                        double window, size_t *r0, size_t *r1) {
  const double tol = 1e-9 * window;
  *r0 = rows, *r1 = 0;
  for (size_t r = 0; r < rows; r++) {
    const double w0 = win[r * len], w1 = win[r * len + 1];
    if (w0 >= a->t0 - tol && w1 <= a->t1 + tol) *r0 = r < *r0 ? r : *r0, *r1 = r + 1;
  }
  return *r1 <= *r0;
}

/* The PDF table of rows r0 .. r1-1: the moments as header lines, then one row per level,
   component and bin. */
static void extract_pdf_table(const struct extract_args *a, const struct pdf *p, size_t r0,
                              size_t r1) {
  struct pdf_result r;
  pdf_finalise(p, r0, r1, &r);
  const char sep = !strcmp(a->fmt, "csv") ? ',' : '\t';
  static const char comp[PDF_COMP] = {'u', 'v', 'w'};
  printf(
      "# chansph extract --pdfs %s: windows %zu..%zu, t = %.9g .. %.9g s, %.0f snapshots, %d "
      "batches; pdf of (u_i - <u_i>) / u_i,rms over +-%g rms\n",
      a->path, r0, r1 - 1, r.t0, r.t1, r.snapshots, r.n_batches, p->cfg.range);
  for (int l = 0; l < p->cfg.n_levels; l++)
    for (int c = 0; c < PDF_COMP; c++) {
      const double *m = r.mom + (l * PDF_COMP + c) * 4, *e = r.mom_err + (l * PDF_COMP + c) * 4;
      printf(
          "# y+ %g %c: %.0f samples, mean %.6g +- %.3g m/s, rms %.6g +- %.3g m/s, skewness "
          "%.4g +- %.3g, flatness %.4g +- %.3g, outside %.3g, clipped %.3g\n",
          p->cfg.y_plus[l], comp[c], r.n[l], m[0], e[0], m[1], e[1], m[2], e[2], m[3], e[3],
          r.outside[l * PDF_COMP + c], r.clipped[l * PDF_COMP + c]);
    }
  printf("y_plus%ccomponent%cx%cpdf%cpdf_stderr\n", sep, sep, sep, sep);
  for (int l = 0; l < p->cfg.n_levels; l++)
    for (int c = 0; c < PDF_COMP; c++)
      for (int j = 0; j < p->cfg.bins; j++) {
        const size_t k = ((size_t)l * PDF_COMP + (size_t)c) * (size_t)p->cfg.bins + (size_t)j;
        printf("%.9g%c%c%c%.9g%c%.9g%c%.9g\n", p->cfg.y_plus[l], sep, comp[c], sep,
               r.bin_centres[j], sep, r.p[k], sep, r.p_err[k]);
      }
  pdf_result_free(&r);
}

/* chansph extract --pdfs: the group pdfs re-averaged over the windows of --window. */
static int extract_pdfs(const struct extract_args *a) {
  int ncid, rc = nc_open(a->path, NC_NOWRITE, &ncid);
  char err[256];
  struct pdf p;
  if (rc != NC_NOERR) {
    fprintf(stderr, "error: %s: %s\n", a->path, nc_strerror(rc));
    return 1;
  }
  rc = pdf_nc_read(&p, ncid, err, sizeof err);
  CHECK_NC(nc_close(ncid));
  if (rc) {
    fprintf(stderr, "error: %s: %s\n", a->path, err);
    return 1;
  }
  size_t r0, r1;
  const int none = window_range(a, p.win, PW_LEN, pdf_rows(&p), p.cfg.window, &r0, &r1);
  if (none)
    fprintf(stderr, "error: %s: no averaging window of group pdfs lies inside %g:%g\n", a->path,
            a->t0, a->t1);
  else
    extract_pdf_table(a, &p, r0, r1);
  pdf_free(&p);
  return none;
}

/* The global attributes the Eulerian engine writes for its averaged range (euler_nc.c), which
   --nc must not copy from the whole run. */
static const char *const range_attrs[] = {
    "u_tau",           "u_tau_stderr",     "u_tau_wall",           "u_tau_force",
    "re_tau",          "correlation_time", "stress_balance_error", "average_start",
    "average_end",     "n_windows",        "n_snapshots",          "t_reached",
    "segment_run_ids", "segment_end_time"};

/* Copy the global attributes of file in to out, less those of range_attrs. */
static int copy_run_attrs(int in, int out) {
  int n, rc = nc_inq_natts(in, &n);
  for (int i = 0; rc == NC_NOERR && i < n; i++) {
    char name[NC_MAX_NAME + 1];
    if ((rc = nc_inq_attname(in, NC_GLOBAL, i, name)) != NC_NOERR) break;
    int skip = 0;
    for (size_t k = 0; k < sizeof range_attrs / sizeof range_attrs[0]; k++)
      skip |= !strcmp(name, range_attrs[k]);
    if (!skip) rc = nc_copy_att(in, NC_GLOBAL, name, out, NC_GLOBAL);
  }
  return rc;
}

/* Copy variable v of group gi (its dimensions defined in go by name) with its attributes and
   values to group go. */
static int copy_var(int gi, int v, int go) {
  char name[NC_MAX_NAME + 1], dn[NC_MAX_NAME + 1];
  nc_type t;
  int nd, dims[NC_MAX_VAR_DIMS], na, w, rc = nc_inq_var(gi, v, name, &t, &nd, dims, &na);
  size_t n = 1, len, size = 0;
  for (int i = 0; rc == NC_NOERR && i < nd; i++)
    if ((rc = nc_inq_dim(gi, dims[i], dn, &len)) == NC_NOERR)
      rc = nc_inq_dimid(go, dn, &dims[i]), n *= len;
  if (rc == NC_NOERR) rc = nc_def_var(go, name, t, nd, dims, &w);
  for (int i = 0; rc == NC_NOERR && i < na; i++)
    if ((rc = nc_inq_attname(gi, v, i, dn)) == NC_NOERR) rc = nc_copy_att(gi, v, dn, go, w);
  if (rc == NC_NOERR) rc = nc_inq_type(gi, t, NULL, &size);
  void *buf = rc == NC_NOERR && n
                  ? mem_alloc(n, t == NC_STRING ? sizeof(char *) : size, "chansph extract")
                  : NULL;
  if (buf && (rc = nc_get_var(gi, v, buf)) == NC_NOERR) rc = nc_put_var(go, w, buf);
  if (buf && t == NC_STRING) nc_free_string(n, buf);
  free(buf);
  return rc;
}

/* Copy group name of file in, dimensions, attributes and variables, to file out (a file whose
   group was written before the window records: extract cannot restrict it to a range). */
static int copy_group(int in, int out, const char *name) {
  int gi, go, nd, nv, na, dims[NC_MAX_DIMS], *vars = NULL, rc = nc_inq_ncid(in, name, &gi);
  if (rc == NC_NOERR) rc = nc_def_grp(out, name, &go);
  if (rc == NC_NOERR) rc = nc_inq_dimids(gi, &nd, dims, 0);
  for (int i = 0; rc == NC_NOERR && i < nd; i++) {
    char dn[NC_MAX_NAME + 1];
    size_t len;
    int d;
    if ((rc = nc_inq_dim(gi, dims[i], dn, &len)) == NC_NOERR) rc = nc_def_dim(go, dn, len, &d);
  }
  if (rc == NC_NOERR) rc = nc_inq_natts(gi, &na);
  for (int i = 0; rc == NC_NOERR && i < na; i++) {
    char an[NC_MAX_NAME + 1];
    if ((rc = nc_inq_attname(gi, NC_GLOBAL, i, an)) == NC_NOERR)
      rc = nc_copy_att(gi, NC_GLOBAL, an, go, NC_GLOBAL);
  }
  if (rc == NC_NOERR) rc = nc_inq_varids(gi, &nv, NULL);
  if (rc == NC_NOERR) vars = mem_alloc((size_t)nv + 1, sizeof(int), "chansph extract");
  if (rc == NC_NOERR) rc = nc_inq_varids(gi, &nv, vars);
  for (int i = 0; rc == NC_NOERR && i < nv; i++) rc = copy_var(gi, vars[i], go);
  free(vars);
  return rc;
}

/* Group correlations of --nc: how it goes to the range file. */
struct corr_range {
  int have; /* 0: no group; 1: window records, rows q0 .. q1-1 re-averaged; 2: copied whole */
  struct corr c;
  size_t q0, q1;
};

/* Read group correlations of file in (a.path) and choose the rows of --window; nonzero on an
   input error (printed, naming the file). */
static int corr_prepare(const struct extract_args *a, int in, struct corr_range *k) {
  char err[256] = "";
  memset(k, 0, sizeof *k);
  const int rc = corr_nc_read(&k->c, in, err, sizeof err);
  if (rc == 1) return 0; /* the engine was off */
  if (rc == 2) {
    fprintf(stderr,
            "note: %s: %s (written before stats.nc held them): group correlations is copied "
            "whole, the run's average, not restricted to --window\n",
            a->path, err);
    k->have = 2;
    return 0;
  }
  if (rc) {
    fprintf(stderr, "error: %s: %s\n", a->path, err);
    return 1;
  }
  k->have = 1;
  if (window_range(a, k->c.win, CW_LEN, corr_rows(&k->c), k->c.cfg.window, &k->q0, &k->q1)) {
    fprintf(stderr, "error: %s: no averaging window of group correlations lies inside %g:%g\n",
            a->path, a->t0, a->t1);
    corr_free(&k->c);
    return 1;
  }
  for (size_t r = k->q0; r < k->q1; r++)
    if (k->c.win[r * CW_LEN + CW_PARTIAL] != 0.0)
      fprintf(stderr,
              "note: %s: correlations window %zu holds only the snapshots after a resume from a "
              "checkpoint without window records (the earlier ones are in no window)\n",
              a->path, r);
  return 0;
}

/* Write group correlations of k to file out (in: the input file); a netCDF status. */
static int corr_output(struct corr_range *k, int in, int out, char *err, size_t errlen) {
  int rc = NC_NOERR;
  if (k->have == 1) rc = corr_nc_write_range(&k->c, k->q0, k->q1, out, err, errlen);
  if (k->have == 2 && (rc = copy_group(in, out, "correlations")) != NC_NOERR)
    snprintf(err, errlen, "copying group correlations");
  if (k->have == 1) corr_free(&k->c);
  k->have = 0;
  return rc;
}

/* The global attribute segments of a joined file: the files joined, in order. */
static int put_segments(const struct extract_args *a, int out) {
  size_t len = 1;
  for (int k = 0; k < a->npaths; k++) len += strlen(a->paths[k]) + 2;
  char *text = mem_alloc(len, 1, "chansph extract");
  text[0] = '\0';
  for (int k = 0; k < a->npaths; k++) strcat(strcat(text, k ? "; " : ""), a->paths[k]);
  const int rc = nc_put_att_text(out, NC_GLOBAL, "segments", strlen(text), text);
  free(text);
  return rc;
}

/* The runs a file of several holds, and, if its range runs to the end (r1 = rows), the time
   its last one ended: what a later segment must continue (segment_run_ids, segment_end_time);
   if it holds them whole, their time steps summed (steps). */
static int put_origin(const struct stored *s, size_t r0, size_t r1, int out) {
  if (!strchr(s->o.ids, ';')) return NC_NOERR; /* one run: run_id and t_reached say it */
  int rc = nc_put_att_text(out, NC_GLOBAL, "segment_run_ids", strlen(s->o.ids), s->o.ids);
  if (rc == NC_NOERR && r1 == s->rows && isfinite(s->o.end_t))
    rc = nc_put_att_double(out, NC_GLOBAL, "segment_end_time", NC_DOUBLE, 1, &s->o.end_t);
  const long long steps = (long long)s->o.steps; /* a join copied the first segment's */
  if (rc == NC_NOERR && r0 == 0 && r1 == s->rows && isfinite(s->o.steps))
    rc = nc_put_att_longlong(out, NC_GLOBAL, "steps", NC_INT64, 1, &steps);
  return rc;
}

/* Whether any segment of a join holds group name (else the engine was off: no note). */
static int any_segment_has(const struct extract_args *a, const char *name) {
  int have = 0;
  for (int k = 0; k < a->npaths && !have; k++) {
    int ncid, g;
    if (nc_open(a->paths[k], NC_NOWRITE, &ncid) != NC_NOERR) continue;
    have = nc_inq_ncid(ncid, name, &g) == NC_NOERR;
    nc_close(ncid);
  }
  return have;
}

/* Why group name of segment k is left out of the joined file: r as the engines' readers return
   it (1: no group; else why says), differ: 1 if its configuration differs from the first
   segment's (why says how). Silent if no segment holds the group. */
static void left_out(const struct extract_args *a, int k, const char *name, int r, int differ,
                     const char *why) {
  if (!any_segment_has(a, name)) return;
  if (differ)
    fprintf(stderr, "note: %s: group %s gathered otherwise than in %s (%s): left out of %s\n",
            a->paths[k], name, a->paths[0], why, a->nc_out);
  else
    fprintf(stderr, "note: %s: %s: group %s left out of %s\n", a->paths[k],
            r == 1 ? "no group (the engine was off)" : why, name, a->nc_out);
}

/* Open segment k of a join; its reached time into *t (NaN if absent). Nonzero if unreadable. */
static int open_segment(const struct extract_args *a, int k, int *ncid, double *t) {
  if (nc_open(a->paths[k], NC_NOWRITE, ncid) != NC_NOERR) return 1;
  *t = get_num(*ncid, "t_reached");
  return 0;
}

/* Group lagrangian of the joined segments (--nc): the completed releases of all segments
   pooled as one run's (lagr_join: sums added, per-release Welford records merged, the history
   of T_L concatenated on the joined time axis, each segment's times shifted by the reached
   times of those before it, as join_stored shifts the windows), written by the engine's own
   writer, so that the values and *_stderr come from the code of a run. A segment without the
   group, without its raw records (an earlier version) or configured otherwise: a note, and
   the group is left out. *joined: 1 if written. A netCDF status (err: the failing call). */
static int join_lagrangian(const struct extract_args *a, int out, int *joined, char *err,
                           size_t errlen) {
  struct lagr g, b;
  char why[256] = "";
  double offset = 0.0, t = NAN;
  int k = 0, r = 0, differ = 0, ncid;
  *joined = 0;
  memset(&g, 0, sizeof g), memset(&b, 0, sizeof b);
  for (; k < a->npaths; k++) {
    if (open_segment(a, k, &ncid, &t)) {
      r = -1, snprintf(why, sizeof why, "cannot open it");
      break;
    }
    r = lagr_nc_read(k ? &b : &g, ncid, why, sizeof why);
    nc_close(ncid);
    if (!r && k) r = differ = lagr_join(&g, &b, offset, why, sizeof why);
    lagr_free(&b);
    if (r) break; /* k: the segment that left the group out */
    offset += t;
  }
  int rc = NC_NOERR;
  if (r) {
    left_out(a, k, "lagrangian", r, differ, why);
  } else {
    rc = lagr_nc_write(&g, out, err, errlen);
    *joined = rc == NC_NOERR;
    fprintf(stderr,
            "note: group lagrangian: the %.0f releases completed within the segments pooled; "
            "a release in flight at the end of a segment before the last is in none (its "
            "samples are lost)\n",
            g.releases);
  }
  lagr_free(&g);
  return rc;
}

/* Group quadrants of the joined segments (--nc): the sums and samples of all segments added,
   the Welford records of their complete averaging windows merged (quad_join), written by the
   engine's own writer. The window open at a segment's end is in its sums, not a batch (its
   sums are not in stats.nc). Left out as group lagrangian (join_lagrangian). */
static int join_quadrants(const struct extract_args *a, int out, int *joined, char *err,
                          size_t errlen) {
  struct quad q, b;
  char why[256] = "";
  double t;
  int k = 0, r = 0, differ = 0, ncid;
  *joined = 0;
  memset(&q, 0, sizeof q), memset(&b, 0, sizeof b);
  for (; k < a->npaths; k++) {
    if (open_segment(a, k, &ncid, &t)) {
      r = -1, snprintf(why, sizeof why, "cannot open it");
      break;
    }
    r = quad_nc_read(k ? &b : &q, ncid, why, sizeof why);
    nc_close(ncid);
    if (!r && k) r = differ = quad_join(&q, &b, why, sizeof why);
    quad_free(&b);
    if (r) break; /* k: the segment that left the group out */
  }
  int rc = NC_NOERR;
  if (r)
    left_out(a, k, "quadrants", r, differ, why);
  else
    rc = quad_nc_write(&q, out, err, errlen), *joined = rc == NC_NOERR;
  quad_free(&q);
  return rc;
}

/* The groups of several segments joined (--nc) besides eulerian: lagrangian and quadrants
   pooled over all segments if the range is whole (whole: they have no windows to restrict to
   --window), then a note of the groups joined. A netCDF status. */
static int join_groups(const struct extract_args *a, int whole, int out, char *err, size_t errlen) {
  char groups[64] = "eulerian";
  int rc = NC_NOERR, joined = 0;
  if (!whole && (any_segment_has(a, "lagrangian") || any_segment_has(a, "quadrants")))
    fprintf(stderr,
            "note: --window restricts the joined range: groups lagrangian and quadrants (they "
            "have no window records) are left out\n");
  if (whole && (rc = join_lagrangian(a, out, &joined, err, errlen)) == NC_NOERR && joined)
    strcat(groups, ", lagrangian");
  if (whole && rc == NC_NOERR && (rc = join_quadrants(a, out, &joined, err, errlen)) == NC_NOERR &&
      joined)
    strcat(groups, ", quadrants");
  fprintf(stderr, "note: %d segments joined: group%s %s (the other groups are left out)\n",
          a->npaths, strchr(groups, ',') ? "s" : "", groups);
  return rc;
}

/* The windows r0 .. r1-1 of s as the state of an engine that gathered only them (its last row
   open if that window is), written by the engine's own writer to a.nc_out (through a
   temporary file, renamed when complete). */
static int write_range(const struct extract_args *a, const struct stored *s, size_t r0, size_t r1) {
  if (!s->pln || !s->kin) {
    fprintf(stderr, "error: %s: --nc needs the budget records of format 1.4 or later\n", a->path);
    return 1;
  }
  const size_t nb = (size_t)s->cfg.nb, n = r1 - r0;
  struct euler e = {.cfg = s->cfg, .nwin = s->complete[r1 - 1] ? n : n - 1, .cap = n + 1};
  struct {
    double **to;
    const double *from;
    size_t len;
  } rec[] = {{&e.win, s->win, WIN_LEN},       {&e.mom, s->mom, nb * MOM_LEN},
             {&e.snp, s->snp, nb * SCAL_LEN}, {&e.pln, s->pln, nb * PL_LEN},
             {&e.kin, s->kin, nb * KN_LEN},   {&e.rsb, s->rsb, nb * RW_LEN},
             {&e.tpl, s->tpl, nb * PL_LEN},   {&e.tkn, s->tkn, nb * KN_LEN}};
  double snaps = 0.0;
  for (size_t r = r0; r < r1; r++) snaps += s->win[r * WIN_LEN + WIN_NSNAP];
  for (size_t k = 0; k < sizeof rec / sizeof rec[0]; k++) {
    *rec[k].to = mem_calloc(e.cap * rec[k].len, sizeof(double), "chansph extract");
    if (rec[k].from) /* no Reynolds-stress budget records (an earlier format): none sampled */
      memcpy(*rec[k].to, rec[k].from + r0 * rec[k].len, n * rec[k].len * sizeof(double));
  }
  char tmp[4096], err[512] = "";
  snprintf(tmp, sizeof tmp, "%s.tmp", a->nc_out);
  const double t_end = r1 == s->rows ? s->t_reached : s->win[(r1 - 1) * WIN_LEN + WIN_T1];
  const long long ns = (long long)snaps;
  struct corr_range k = {0};
  int in = -1, out = -1, rc = nc_open(a->path, NC_NOWRITE, &in);
  if (a->npaths == 1 && rc == NC_NOERR && corr_prepare(a, in, &k)) {
    nc_close(in), euler_free(&e);
    return 1;
  }
  if (rc == NC_NOERR) rc = nc_create(tmp, NC_NETCDF4 | NC_CLOBBER, &out);
  if (rc == NC_NOERR) rc = copy_run_attrs(in, out);
  if (rc == NC_NOERR && isfinite(t_end))
    rc = nc_put_att_double(out, NC_GLOBAL, "t_reached", NC_DOUBLE, 1, &t_end);
  if (rc == NC_NOERR) rc = nc_put_att_longlong(out, NC_GLOBAL, "n_snapshots", NC_INT64, 1, &ns);
  if (rc == NC_NOERR && a->npaths > 1) rc = put_segments(a, out);
  if (rc == NC_NOERR) rc = put_origin(s, r0, r1, out);
  if (rc == NC_NOERR) rc = euler_engine.write(&e, t_end, out, err, sizeof err);
  if (rc == NC_NOERR && a->npaths > 1)
    rc = join_groups(a, r0 == 0 && r1 == s->rows, out, err, sizeof err);
  if (rc == NC_NOERR) rc = corr_output(&k, in, out, err, sizeof err);
  if (k.have == 1) corr_free(&k.c);
  if (out >= 0 && nc_close(out) != NC_NOERR && rc == NC_NOERR) rc = NC_EHDFERR;
  if (in >= 0) nc_close(in);
  euler_free(&e);
  if (rc == NC_NOERR && rename(tmp, a->nc_out) == 0) {
    printf("chansph extract: %s%s: windows %zu..%zu (t = %.9g .. %.9g s, %.0f snapshots) -> %s\n",
           a->path, later_segments(a), r0, r1 - 1, s->win[r0 * WIN_LEN + WIN_T0], t_end, snaps,
           a->nc_out);
    if (k.q1 > k.q0)
      printf("chansph extract: %s: group correlations re-averaged over its windows %zu..%zu\n",
             a->path, k.q0, k.q1 - 1);
    return 0;
  }
  fprintf(stderr, "error: %s: cannot write %s: %s%s%s\n", a->path, a->nc_out,
          rc == NC_NOERR ? strerror(errno) : nc_strerror(rc), err[0] ? ": " : "", err);
  unlink(tmp);
  return 1;
}

/* Whether --nc OUT may be written: it does not exist, or it is an earlier output of extract,
   not one of the files read (by inode: a copy is another file, a link the same), nor a run's
   file (particles.nc, a snapshot, a run's own stats.nc) or a foreign file. Nonzero: refused,
   printed, nothing touched. */
static int out_refused(const struct extract_args *a) {
  struct stat so, si;
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", a->nc_out);
  char *slash = strrchr(dir, '/');
  if (slash) /* its directory must exist (netCDF reports a missing one as "Permission denied") */
    *(slash == dir ? slash + 1 : slash) = '\0';
  const int missing = slash && stat(dir, &si) != 0;
  if (slash && (missing || !S_ISDIR(si.st_mode))) {
    fprintf(stderr, "error: --nc %s: the directory %s %s: create it first, or write elsewhere\n",
            a->nc_out, dir, missing ? "does not exist" : "is not a directory");
    return 1;
  }
  if (stat(a->nc_out, &so) != 0) return 0; /* a new file */
  for (int k = 0; k < a->npaths; k++)
    if (stat(a->paths[k], &si) == 0 && si.st_dev == so.st_dev && si.st_ino == so.st_ino) {
      fprintf(stderr,
              "error: --nc %s is the input %s (the same file): extract never replaces what it "
              "reads; write to another name\n",
              a->nc_out, a->paths[k]);
      return 1;
    }
  int ncid, g, d;
  const char *why = NULL;
  if (nc_open(a->nc_out, NC_NOWRITE, &ncid) != NC_NOERR) {
    why = "not a netCDF file";
  } else {
    if (nc_inq_dimid(ncid, "particle", &d) == NC_NOERR)
      why = "a run's particle state (dimension 'particle': particles.nc or a snapshot)";
    else if (nc_inq_ncid(ncid, "eulerian", &g) != NC_NOERR)
      why = "not a stats.nc (no group 'eulerian')";
    CHECK_NC(nc_close(ncid));
  }
  snprintf(dir, sizeof dir, "%s", a->nc_out);
  slash = strrchr(dir, '/');
  snprintf(slash ? slash + 1 : dir, sizeof dir - (size_t)(slash ? slash + 1 - dir : 0), "run_id");
  const char *base = strrchr(a->nc_out, '/');
  if (!why && !strcmp(base ? base + 1 : a->nc_out, "stats.nc") && stat(dir, &si) == 0)
    why = "a run's own stats.nc (its directory holds run_id)";
  if (why)
    fprintf(stderr,
            "error: --nc %s exists and is %s: extract replaces only a file it wrote; remove it "
            "or write to another name\n",
            a->nc_out, why);
  return why != NULL;
}

int extract_main(int argc, char **argv) {
  struct extract_args a;
  const int prc = extract_parse(argc, argv, &a);
  if (prc) return prc < 0 ? 0 : 1;
  if (a.pdfs) return extract_pdfs(&a);
  if (a.nc_out && out_refused(&a)) return 1;
  struct stored seg[EXTRACT_MAX_SEGMENTS], s;
  int bad = 0, n = 0;
  for (; n < a.npaths && !bad; n++) bad = read_stored(a.paths[n], &seg[n]);
  if (bad) {
    while (n--) free_stored(&seg[n]);
    return 1;
  }
  bad = join_stored(seg, n, a.paths, a.force), s = seg[0];
  if (bad) {
    free_stored(&s);
    return 1;
  }
  size_t r0, r1;
  if (window_range(&a, s.win, WIN_LEN, s.rows, s.cfg.window, &r0, &r1)) {
    fprintf(stderr, "error: %s: no averaging window lies inside %g:%g\n", a.path, a.t0, a.t1);
    free_stored(&s);
    return 1;
  }
  if (a.nc_out) {
    const int rc = write_range(&a, &s, r0, r1);
    free_stored(&s);
    return rc;
  }
  int cols[64], rms[64];
  const int nc = extract_columns(a.vars, cols, rms, 64);
  if (nc < 0) {
    free_stored(&s);
    return 1;
  }
  struct euler_result res;
  euler_finalise(&s.cfg, s.win, s.mom, s.snp, s.pln, s.kin, s.rsb, s.tpl, s.tkn, s.complete, r0, r1,
                 &res);
  extract_header(&a, &s, &res, r0, r1, cols, rms, nc);
  extract_rows(&a, &s, &res, cols, rms, nc);
  euler_result_free(&res);
  free_stored(&s);
  return 0;
}

int compare_main(int argc, char **argv, const char *stats_dir) {
  char script[4096];
  snprintf(script, sizeof script, "%s/compare.py", stats_dir);
  /* CHANSPH_PYTHON: a python3 with numpy, netCDF4 and matplotlib (a path, or a name looked up
     in PATH); the Debian one by default */
  const char *env = getenv("CHANSPH_PYTHON");
  const char *py = env && env[0] ? env : "/usr/bin/python3";
  char **args = mem_calloc((size_t)argc + 3, sizeof *args, "chansph extract");
  if (!args) return 1;
  args[0] = (char *)py, args[1] = script;
  for (int i = 0; i < argc; i++) args[2 + i] = argv[i];
  execvp(py, args);
  fprintf(stderr,
          "error: cannot start %s for chansph compare (%s); set CHANSPH_PYTHON to a python3 with "
          "numpy, netCDF4 and matplotlib\n",
          py, strerror(errno));
  free(args);
  return 1;
}
