/** @file init.c @brief Implementation of init.h. */
#include "init.h"
#include "alloc.h"

#include <Random123/philox.h>
#include <limits.h>
#include <math.h>
#include <mpi.h>
#include <netcdf.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dd.h"
#include "dns_lm180.h"
#include "error.h"
#include "kernel.h"
#include "ncutil.h"
#include "walllaw.h"

double init_noise(long seed, long long id, int stream) {
  philox4x64_ctr_t c = {{(uint64_t)id, (uint64_t)stream, 0x636861u, 0}};
  philox4x64_key_t k = {{(uint64_t)seed, 0x7370683132333435u}};
  const philox4x64_ctr_t r = philox4x64(c, k);
  return (double)(r.v[0] >> 11) * 0x1.0p-52 - 1.0; /* 53 random bits -> [-1, 1) */
}

/** Bulk velocity of the Reichardt profile of a friction velocity, midpoint rule in y+. */
static double reichardt_bulk(const struct wall_law_def *L, double ut, double nu, double delta) {
  enum { N = 4000 };
  double s = 0.0;
  for (int i = 0; i < N; i++) {
    const double y = (i + 0.5) * delta / N;
    s += wall_law_uplus(L, y * ut / nu);
  }
  return ut * s / N;
}

double init_reichardt_utau(const struct scene *sc) {
  if (sc->drive_mode == DRIVE_FORCE) return sqrt(fabs(sc->force) * sc->delta);
  const struct wall_law_def L = wall_law_make(WALL_LAW_REICHARDT, sc->kappa, sc->log_b);
  const double target = fabs(sc->u_bulk);
  double lo = 0.0, hi = sqrt(3.0 * sc->nu * target / sc->delta); /* the laminar u_tau */
  while (reichardt_bulk(&L, hi, sc->nu, sc->delta) < target) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; it++) {
    const double mid = 0.5 * (lo + hi);
    if (reichardt_bulk(&L, mid, sc->nu, sc->delta) < target)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

/** Mean velocity at height y. */
static double mean_u(const struct scene *sc, const struct wall_law_def *L, double ut, double y) {
  const double yw = fmin(y, 2.0 * sc->delta - y);
  if (sc->init_profile == INIT_LAMINAR) {
    double f = sc->force;
    if (sc->drive_mode == DRIVE_FLUX) f = 3.0 * sc->nu * sc->u_bulk / (sc->delta * sc->delta);
    return f * y * (2.0 * sc->delta - y) / (2.0 * sc->nu);
  }
  if (sc->init_profile == INIT_REICHARDT) {
    const double sign =
        sc->drive_mode == DRIVE_FLUX ? (sc->u_bulk < 0 ? -1.0 : 1.0) : (sc->force < 0 ? -1.0 : 1.0);
    return sign * ut * wall_law_uplus(L, yw * ut / sc->nu);
  }
  return 0.0;
}

/* ---- start from an earlier run (particles.nc) ---- */

/** Value of key in [section] of a scene text, or NAN. */
static double scene_text_value(const char *text, const char *section, const char *key) {
  char head[64];
  snprintf(head, sizeof head, "[%s]", section);
  const char *s = strstr(text, head);
  if (!s) return NAN;
  for (const char *l = strchr(s, '\n'); l && l[1] && l[1] != '['; l = strchr(l + 1, '\n')) {
    const size_t n = strlen(key);
    if (!strncmp(l + 1, key, n) && (l[1 + n] == ' ' || l[1 + n] == '=')) {
      const char *eq = strchr(l + 1, '=');
      return eq ? strtod(eq + 1, NULL) : NAN;
    }
  }
  return NAN;
}

/* The particles of init.from this rank holds: after reading, its slice first .. first+n-1 of
   the file's total (in file order); after the exchange, the ones its particles need. */
struct source {
  size_t n, first, total;
  double *col[8]; /* x y z u v w rho mass */
  long long *id;
  double lx, ly, lz, h;
  int dim;
  int packed; /* variables that were CF-packed (unpacked when read) */
};

/** The variables of particles.nc that init.from reads, in the order of source.col, then id. */
static const char *const source_names[9] = {"x", "y", "z", "u", "v", "w", "rho", "mass", "id"};

static void source_free(struct source *src) {
  for (int c = 0; c < 8; c++) free(src->col[c]);
  free(src->id);
}

/** Whether variable vid is 1-D over dimension dimid (a longer or 2-D variable would overflow
    the column of dimid's length it is read into). */
static int source_var_ok(int nc, int vid, int dimid) {
  int nd = 0, d = -1;
  return !nc_inq_varndims(nc, vid, &nd) && nd == 1 && !nc_inq_vardimid(nc, vid, &d) && d == dimid;
}

/** Variable vid (name) of file path as values: CF packing (scale_factor, add_offset, as NCO's
    ncpdq writes it) applied to the n raw values col (particles first ..); a value equal to its
    _FillValue or missing_value is missing: *miss (if none yet) becomes the error text and
    *at the particle's index in the file. *packed is set if it was packed. */
static int unpack_column(int nc, int vid, const char *path, const char *name, double *col, size_t n,
                         size_t first, int *packed, char *miss, size_t nmiss, size_t *at) {
  double scale = 1.0, offset = 0.0, fill[2];
  const int has_scale = !nc_get_att_double(nc, vid, "scale_factor", &scale);
  const int has_offset = !nc_get_att_double(nc, vid, "add_offset", &offset);
  const int has_fill[2] = {!nc_get_att_double(nc, vid, "_FillValue", &fill[0]),
                           !nc_get_att_double(nc, vid, "missing_value", &fill[1])};
  if (!has_scale) scale = 1.0;
  if (!has_offset) offset = 0.0;
  *packed = has_scale || has_offset;
  if (!isfinite(scale) || !isfinite(offset)) {
    error_input(
        "%s (init.from): variable '%s' has a packing scale_factor %g, add_offset %g that "
        "is not finite",
        path, name, scale, offset);
    return CHANSPH_ERR;
  }
  for (size_t b = 0; b < n; b++) {
    for (int k = 0; k < 2; k++)
      if (has_fill[k] && col[b] == fill[k] && !miss[0]) {
        snprintf(miss, nmiss,
                 "%s (init.from): variable '%s' is missing at index %zu (its %s): not a "
                 "usable initial state",
                 path, name, first + b, k ? "missing_value" : "_FillValue");
        *at = first + b;
      }
    col[b] = col[b] * scale + offset;
  }
  return CHANSPH_OK;
}

/* ---- the source read in slices, one per rank, and sent to the ranks that need it ---- */

/** The fluid particles of a freshly built part: the first slots (part_create_part). */
static size_t local_fluid(const struct particles *P) {
  size_t a = 0;
  while (a < P->n && P->kind[a] == KIND_FLUID) a++;
  return a;
}

/** The ranks agree on the first error in the file (smallest key over the ranks; LONG_MAX:
    none here), whose text the rank that found it gives rank 0 to print. Collective. */
static int first_error(const struct init_owner *own, long key, const char *text) {
  if (own->size == 1) {
    if (key == LONG_MAX) return CHANSPH_OK;
    error_input("%s", text);
    return CHANSPH_ERR;
  }
  struct {
    long key;
    int rank;
  } in = {key, own->rank}, out;
  CHECK_MPI(MPI_Allreduce(&in, &out, 1, MPI_LONG_INT, MPI_MINLOC, MPI_COMM_WORLD));
  if (out.key == LONG_MAX) return CHANSPH_OK;
  char buf[2048] = "";
  if (own->rank == out.rank) snprintf(buf, sizeof buf, "%s", text);
  CHECK_MPI(MPI_Bcast(buf, sizeof buf, MPI_CHAR, out.rank, MPI_COMM_WORLD));
  error_input("%s", buf);
  return CHANSPH_ERR;
}

/** Whether every rank says ok. Collective. */
static int all_ok(const struct init_owner *own, int ok) {
  if (own->size > 1)
    CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD));
  return ok;
}

/** Send record a (R doubles) to rank dest[a] (several records may go to one rank), in the
    order given; returns what arrives (part_alloc), *got records. Collective. */
static double *send_records(const struct init_owner *own, const int *dest, size_t n,
                            const double *rec, size_t R, size_t *got) {
  if (own->size > 1) return dd_exchange(own->size, dest, n, rec, R, got);
  double *buf = part_alloc("init_records", (n ? n : 1) * R * sizeof(double));
  memcpy(buf, rec, n * R * sizeof(double));
  *got = n;
  return buf;
}

static int cmp_first(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/** Read the 'scene' attribute and this rank's slice of the columns of particles.nc into src
    (rank r of size: the particles r total / size .. (r+1) total / size - 1). */
static int read_columns(const char *path, struct source *src, char **text,
                        const struct init_owner *own) {
  int nc, rc, dimid, vid;
  if ((rc = nc_open(path, NC_NOWRITE, &nc))) {
    error_input("%s (init.from): cannot open: %s", path, nc_strerror(rc));
    return CHANSPH_ERR;
  }
  size_t n = 0, alen = 0;
  int ok = !nc_inq_dimid(nc, "particle", &dimid) && !nc_inq_dimlen(nc, dimid, &n) &&
           !nc_inq_attlen(nc, NC_GLOBAL, "scene", &alen);
  if (ok) {
    *text = mem_calloc(alen + 1, 1, "initial state");
    ok = *text && !nc_get_att_text(nc, NC_GLOBAL, "scene", *text);
  }
  src->total = n;
  dd_id_block(own->rank, own->size, n, &src->first, &n); /* the particle files' blocks */
  n -= src->first, src->n = n;
  const size_t start[1] = {src->first}, count[1] = {n};
  char miss[1024] = "";
  size_t at = 0;
  long key = LONG_MAX; /* the first missing value: by variable, then by index */
  for (int c = 0; ok && c < 9; c++) {
    if (!nc_inq_varid(nc, source_names[c], &vid) && !source_var_ok(nc, vid, dimid)) {
      error_input("%s (init.from): variable '%s' is not 1-D over dimension 'particle' (%zu)", path,
                  source_names[c], n);
      ok = 0;
      break;
    }
    if (c < 8) {
      src->col[c] = mem_alloc(1, (n ? n : 1) * sizeof(double), "initial state");
      ok = src->col[c] && !nc_inq_varid(nc, source_names[c], &vid) &&
           (!n || !nc_get_vara_double(nc, vid, start, count, src->col[c]));
      int packed = 0;
      if (ok && unpack_column(nc, vid, path, source_names[c], src->col[c], n, src->first, &packed,
                              miss, sizeof miss, &at)) {
        CHECK_NC(nc_close(nc));
        free(*text), source_free(src);
        *text = NULL;
        return CHANSPH_ERR;
      }
      src->packed += packed;
      if (miss[0] && key == LONG_MAX) key = (long)((size_t)c * src->total + at);
    } else if (!nc_inq_varid(nc, "id", &vid) && (!nc_inq_att(nc, vid, "scale_factor", NULL, NULL) ||
                                                 !nc_inq_att(nc, vid, "add_offset", NULL, NULL))) {
      error_input(
          "%s (init.from): variable 'id' is packed (scale_factor, add_offset): the ids "
          "must be stored exactly (unpack the file, e.g. ncpdq -U)",
          path);
      CHECK_NC(nc_close(nc));
      free(*text), source_free(src);
      *text = NULL;
      return CHANSPH_ERR;
    } else {
      src->id = mem_alloc(1, (n ? n : 1) * sizeof(long long), "initial state");
      ok = src->id && !nc_inq_varid(nc, "id", &vid) &&
           (!n || !nc_get_vara_longlong(nc, vid, start, count, src->id));
    }
    if (!ok)
      error_input("%s (init.from): variable '%s' missing or unreadable", path, source_names[c]);
  }
  CHECK_NC(nc_close(nc));
  if (!all_ok(own, ok)) { /* a rank could not read its slice */
    error_input(
        "%s (init.from): not a chansph particles.nc (needs dimension 'particle', "
        "variables x y z u v w rho mass id over it and the 'scene' attribute)",
        path);
    free(*text), source_free(src);
    *text = NULL;
    return CHANSPH_ERR;
  }
  if (first_error(own, key, miss)) {
    free(*text), source_free(src);
    *text = NULL;
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

/** Index of the first particle of src whose values are not a usable state (not finite, rho
    or mass not positive, position outside the box), or src->n; *what names the check. */
static size_t source_bad_particle(const struct source *src, const char **what, int *col) {
  for (size_t b = 0; b < src->n; b++) {
    for (int c = 0; c < 8; c++)
      if (!isfinite(src->col[c][b])) {
        *what = "is not finite", *col = c;
        return b;
      }
    const double x = src->col[0][b], y = src->col[1][b], z = src->col[2][b];
    *what = "is outside", *col = 0;
    if (!(x >= 0.0 && x < src->lx)) return b;
    *col = 1;
    if (!(y > 0.0 && y < src->ly)) return b;
    *col = 2;
    if (src->dim == 3 && !(z >= 0.0 && z < src->lz)) return b;
    *what = "is not positive";
    for (*col = 6; *col < 8; (*col)++)
      if (!(src->col[*col][b] > 0.0)) return b;
  }
  return src->n;
}

/** Refuse a source that is not a state of the box: no particles, ids not a permutation of
    0..n-1, a value not finite, rho or mass not positive, a position outside the box. Each
    rank checks its slice; the ids go to the ranks of their id blocks to find repeats; the
    first failure in file order is reported. Collective. */
static int check_source(const char *path, const struct source *src, const struct init_owner *own) {
  if (src->total == 0) {
    error_input("%s (init.from): no particles: not a usable initial state", path);
    return CHANSPH_ERR;
  }
  const char *what = "";
  int c = 0;
  const size_t b = source_bad_particle(src, &what, &c);
  char text[2048] = "";
  if (b < src->n) {
    char box[96] = "";
    if (c < 3 && src->dim == 3)
      snprintf(box, sizeof box, " the box [0, %g) x (0, %g) x [0, %g)", src->lx, src->ly, src->lz);
    else if (c < 3)
      snprintf(box, sizeof box, " the box [0, %g) x (0, %g)", src->lx, src->ly);
    snprintf(text, sizeof text,
             "%s (init.from): variable '%s' of particle id %lld %s%s (%g): not a usable "
             "initial state",
             path, source_names[c], src->id[b], what, box, src->col[c][b]);
  }
  TRY(first_error(own, b < src->n ? (long)(src->first + b) : LONG_MAX, text));
  /* the first index (file order) whose id is out of range or was seen at a smaller index */
  const size_t N = src->total;
  long key = LONG_MAX;
  long long bad_id = 0;
  int *dest = mem_alloc(1, (src->n ? src->n : 1) * sizeof *dest, "initial state");
  double *rec = mem_alloc(1, (src->n ? 2 * src->n : 1) * sizeof *rec, "initial state");
  size_t m = 0;
  for (size_t k = 0; k < src->n; k++) {
    const long long id = src->id[k];
    if (id < 0 || (unsigned long long)id >= N) {
      if (key == LONG_MAX) key = (long)(src->first + k), bad_id = id;
      continue;
    }
    dest[m] = dd_id_owner(id, own->size, N), rec[2 * m] = (double)(src->first + k),
    rec[2 * m + 1] = (double)id, m++;
  }
  size_t got;
  double *in = send_records(own, dest, m, rec, 2, &got);
  free(dest), free(rec);
  size_t lo, hi;
  dd_id_block(own->rank, own->size, N, &lo, &hi);
  double *first = mem_alloc(1, (hi > lo ? hi - lo : 1) * sizeof *first, "initial state");
  for (size_t i = lo; i < hi; i++) first[i - lo] = -1.0;
  for (size_t k = 0; k < got; k++) { /* the smallest index of each id; a larger one repeats it */
    const double at = in[2 * k];
    const size_t id = (size_t)in[2 * k + 1];
    double *f = &first[id - lo];
    const double later = *f < 0.0 ? -1.0 : fmax(*f, at);
    if (*f < 0.0 || at < *f) *f = at;
    if (later >= 0.0 && (long)later < key) key = (long)later, bad_id = (long long)id;
  }
  part_free(in), free(first);
  snprintf(text, sizeof text,
           "%s (init.from): particle id %lld %s: the ids must be 0..%zu, each once", path, bad_id,
           bad_id < 0 || (unsigned long long)bad_id >= N ? "out of range" : "repeated", N - 1);
  return first_error(own, key, text);
}

static int read_source(const char *path, const struct scene *sc, struct source *src,
                       const struct init_owner *own) {
  memset(src, 0, sizeof *src);
  char *text = NULL;
  TRY(read_columns(path, src, &text, own));
  const double dim = scene_text_value(text, "domain", "dimension");
  const double delta = scene_text_value(text, "domain", "delta");
  const double lx = scene_text_value(text, "domain", "lx");
  const double lz = scene_text_value(text, "domain", "lz");
  const double dr = scene_text_value(text, "domain", "dr");
  const double hdr = scene_text_value(text, "sph", "h_over_dr");
  free(text);
  const double tol = 1e-9 * sc->lx;
  if (dim != sc->dim || fabs(delta - sc->delta) > tol || fabs(lx - sc->lx) > tol ||
      (sc->dim == 3 && fabs(lz - sc->lz) > tol) || !(dr > 0.0) || !(hdr > 0.0)) {
    error_input(
        "%s (init.from): its domain (dimension %g, delta %g, lx %g, lz %g) differs from "
        "this scene's (dimension %d, delta %g, lx %g, lz %g)",
        path, dim, delta, lx, lz, sc->dim, sc->delta, sc->lx, sc->lz);
    source_free(src);
    return CHANSPH_ERR;
  }
  src->dim = sc->dim, src->lx = lx, src->ly = 2.0 * delta, src->lz = sc->dim == 3 ? lz : 1.0;
  src->h = hdr * dr;
  if (check_source(path, src, own) != CHANSPH_OK) {
    source_free(src);
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

static inline double wrap(double d, double l) {
  return d - l * floor(d / l + 0.5);
}

/** Solve A x = R (m <= 4 unknowns, 3 right-hand sides) by Gaussian elimination with partial
    pivoting; out[f] = x[0] of right-hand side f. Returns 1 if A is (nearly) singular. */
static int solve_small(int m, double A[4][4], double R[4][3], double out[3]) {
  double scale = 0.0;
  for (int r = 0; r < m; r++) scale = fmax(scale, fabs(A[r][r]));
  for (int col = 0; col < m; col++) {
    int piv = col;
    for (int r = col + 1; r < m; r++)
      if (fabs(A[r][col]) > fabs(A[piv][col])) piv = r;
    if (!(fabs(A[piv][col]) > 1e-12 * scale)) return 1;
    for (int cc = 0; cc < m; cc++) {
      const double t = A[col][cc];
      A[col][cc] = A[piv][cc], A[piv][cc] = t;
    }
    for (int f = 0; f < 3; f++) {
      const double t = R[col][f];
      R[col][f] = R[piv][f], R[piv][f] = t;
    }
    for (int r = col + 1; r < m; r++) {
      const double l = A[r][col] / A[col][col];
      for (int cc = col; cc < m; cc++) A[r][cc] -= l * A[col][cc];
      for (int f = 0; f < 3; f++) R[r][f] -= l * R[col][f];
    }
  }
  for (int f = 0; f < 3; f++) {
    double x[4] = {0, 0, 0, 0};
    for (int r = m - 1; r >= 0; r--) {
      double t = R[r][f];
      for (int cc = r + 1; cc < m; cc++) t -= A[r][cc] * x[cc];
      x[r] = t / A[r][r];
    }
    out[f] = x[0];
  }
  return 0;
}

/* The interpolation's cells: of size 2 h of the source or larger, nx x ny x nz. */
static void source_cells(const struct source *src, int *nx, int *ny, int *nz) {
  const double cell = 2.0 * src->h;
  *nx = (int)fmax(1.0, floor(src->lx / cell)), *ny = (int)fmax(1.0, floor(src->ly / cell));
  *nz = src->dim == 3 ? (int)fmax(1.0, floor(src->lz / cell)) : 1;
}

/* The cell column (x, z) of a source particle at x, z (wrapped into the box), as interpolate
   sorts it. */
static void source_column(const struct source *src, int nx, int nz, double x, double z, int *ix,
                          int *iz) {
  const double xb = x - src->lx * floor(x / src->lx);
  const double zb = src->dim == 3 ? z - src->lz * floor(z / src->lz) : 0.0;
  *ix = (int)fmin(nx - 1, fmax(0, floor(xb / src->lx * nx)));
  *iz = (int)fmin(nz - 1, fmax(0, floor(zb / src->lz * nz)));
}

/** Interpolation of the source velocity onto the first nf particles of P (fluid; linear moving
    least squares with the source's kernel). src holds every source particle of the cells
    around them, in file order. */
static void interpolate(const struct source *src, struct particles *P, size_t nf) {
  int nx, ny, nz;
  source_cells(src, &nx, &ny, &nz);
  const size_t ncell = (size_t)nx * ny * nz;
  size_t *start = mem_calloc(ncell + 1, sizeof *start, "initial state"),
         *fill = mem_alloc(1, ncell * sizeof *fill, "initial state");
  size_t *order = mem_alloc(1, (src->n ? src->n : 1) * sizeof *order, "initial state");
  int *cellof = mem_alloc(1, (src->n ? src->n : 1) * sizeof *cellof, "initial state");
  const double *sx = src->col[0], *sy = src->col[1], *sz = src->col[2];
#define CELL_OF(X, Y, Z)                                         \
  (((int)fmin(nz - 1, fmax(0, floor((Z) / src->lz * nz))) * ny + \
    (int)fmin(ny - 1, fmax(0, floor((Y) / src->ly * ny)))) *     \
       nx +                                                      \
   (int)fmin(nx - 1, fmax(0, floor((X) / src->lx * nx))))
  for (size_t b = 0; b < src->n; b++) {
    const double xb = sx[b] - src->lx * floor(sx[b] / src->lx);
    const double zb = src->dim == 3 ? sz[b] - src->lz * floor(sz[b] / src->lz) : 0.0;
    cellof[b] = CELL_OF(xb, sy[b], zb);
    start[cellof[b] + 1]++;
  }
  for (size_t c = 0; c < ncell; c++) start[c + 1] += start[c];
  memcpy(fill, start, ncell * sizeof *fill);
  for (size_t b = 0; b < src->n; b++) order[fill[cellof[b]]++] = b; /* by file order */
  const struct kernel K = kernel_make(src->dim, src->h);
  const int rz = src->dim == 3 ? 1 : 0;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < nf; a++) {
    const double xa = P->x[a], ya = P->y[a], za = P->z[a];
    const int cx = (int)fmin(nx - 1, floor(xa / src->lx * nx));
    const int cy = (int)fmin(ny - 1, floor(ya / src->ly * ny));
    const int cz = src->dim == 3 ? (int)fmin(nz - 1, floor(za / src->lz * nz)) : 0;
    /* linear moving least squares: fit v(r) = c0 + c . (r_b - r_a) with kernel weights, so
       that linear fields (and the near-wall profile) are interpolated exactly; Shepard (c0
       alone) if the fit is singular */
    const int m = src->dim + 1;
    double A[4][4] = {{0}}, R[4][3] = {{0}};
    for (int k = -rz; k <= rz; k++)
      for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++) {
          if (cy + j < 0 || cy + j >= ny) continue;
          if ((nx < 3 && i != 0) || (src->dim == 3 && nz < 3 && k != 0)) continue;
          const int ix = (cx + i + nx) % nx, iz = src->dim == 3 ? (cz + k + nz) % nz : 0;
          const size_t c = ((size_t)iz * ny + cy + j) * nx + ix;
          for (size_t q = start[c]; q < start[c + 1]; q++) {
            const size_t b = order[q];
            const double dx = wrap(sx[b] - xa, src->lx), dy = sy[b] - ya;
            const double dz = src->dim == 3 ? wrap(sz[b] - za, src->lz) : 0.0;
            const double wv =
                src->col[7][b] / src->col[6][b] * kernel_w(&K, sqrt(dx * dx + dy * dy + dz * dz));
            const double basis[4] = {1.0, dx, dy, dz};
            for (int r = 0; r < m; r++) {
              for (int cc = 0; cc < m; cc++) A[r][cc] += wv * basis[r] * basis[cc];
              for (int f = 0; f < 3; f++) R[r][f] += wv * basis[r] * src->col[3 + f][b];
            }
          }
        }
    double out[3];
    if (A[0][0] > 0.0 && solve_small(m, A, R, out) == 0) {
      P->u[a] = out[0], P->v[a] = out[1], P->w[a] = src->dim == 3 ? out[2] : 0.0;
    } else {
      const double s0 = A[0][0] > 0.0 ? 1.0 / A[0][0] : 0.0;
      P->u[a] = R[0][0] * s0, P->v[a] = R[0][1] * s0, P->w[a] = src->dim == 3 ? R[0][2] * s0 : 0.0;
    }
  }
#undef CELL_OF
  free(start), free(fill), free(order), free(cellof);
}

/** A malloc'd copy of text. */
static char *text_copy(const char *text) {
  char *c = mem_alloc(strlen(text) + 1, 1, "initial state");
  return strcpy(c, text);
}

void init_origin(const char *path, char **run_id, double *time) {
  int nc;
  size_t len = 0;
  *time = NAN;
  char *id = NULL;
  if (!path || !path[0] || nc_open(path, NC_NOWRITE, &nc) != NC_NOERR) {
    *run_id = text_copy(path && !path[0] ? "none" : "unknown"); /* read_columns reports errors */
    return;
  }
  if (nc_get_att_double(nc, NC_GLOBAL, "time", time) != NC_NOERR) *time = NAN;
  if (!nc_inq_attlen(nc, NC_GLOBAL, "run_id", &len) && len > 0 && len < 256) {
    id = mem_calloc(len + 1, 1, "initial state");
    if (nc_get_att_text(nc, NC_GLOBAL, "run_id", id) != NC_NOERR) free(id), id = NULL;
  }
  CHECK_NC(nc_close(nc));
  *run_id = id ? id : text_copy("unknown");
}

double init_source_bytes(const struct scene *sc, int ranks, double *count) {
  int nc, d;
  size_t n = 0;
  *count = 0.0;
  if (!sc->init_from[0] || nc_open(sc->init_from, NC_NOWRITE, &nc) != NC_NOERR) return 0.0;
  if (nc_inq_dimid(nc, "particle", &d) || nc_inq_dimlen(nc, d, &n)) n = 0;
  CHECK_NC(nc_close(nc));
  *count = (double)n;
  /* this rank's slice: x y z u v w rho mass and id (8 bytes each), the records sent and
     received for the id check (2 x 2 x 8) and for the owners (2 x 9 x 8), the id check's
     first indices (8) */
  return (double)n / (ranks > 0 ? ranks : 1) * (9.0 * 8.0 + 32.0 + 144.0 + 8.0);
}

/** The mean of the densities of the fluid particles of every rank, the same on any number of
    ranks: each density is split into its integer part and its fraction in units of 2^-64,
    summed as integers (exact, in any order), and rounded once. */
static double mean_density(const struct particles *P, size_t nf, const struct init_owner *own) {
  long long whole = 0;
  unsigned long long part[2] = {0, 0}; /* the fractions' sum in units of 2^-32 and 2^-64 */
  for (size_t a = 0; a < nf; a++) {
    const double ip = floor(P->rho[a]);
    const unsigned long long f = (unsigned long long)ldexp(P->rho[a] - ip, 64); /* < 2^64 */
    whole += (long long)ip;
    part[0] += f >> 32, part[1] += f & 0xffffffffULL;
  }
  unsigned long long n = nf;
  if (own->size > 1) {
    CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &whole, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD));
    CHECK_MPI(
        MPI_Allreduce(MPI_IN_PLACE, part, 2, MPI_UNSIGNED_LONG_LONG, MPI_SUM, MPI_COMM_WORLD));
    CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, MPI_COMM_WORLD));
  }
  const long double sum =
      (long double)whole + ldexpl((long double)part[0], -32) + ldexpl((long double)part[1], -64);
  return (double)(sum / (long double)n);
}

/** init.density = rho0: shift every fluid particle's density by one constant so that their
    mean is rho0 (mean_density: the same on every rank), removing the mean overpressure of a
    developed state (docs/validation/scheme_ab.md). */
static void shift_density(const struct scene *sc, struct particles *P, size_t nf,
                          const struct init_owner *own) {
  const double shift = sc->rho0 - mean_density(P, nf, own);
  for (size_t a = 0; a < nf; a++) P->rho[a] += shift;
  msg("init: densities shifted by %.6g kg/m^3 to the mean rho0 = %.6g (init.density = rho0)\n",
      shift, sc->rho0);
}

/** Same resolution: each source particle goes to the rank owning its position and becomes the
    fluid particle of its id there (in id order, as the lattice it replaces); the vertices stay. */
static void place_state(struct source *src, const struct scene *sc, struct particles *P, size_t nf,
                        const struct init_owner *own) {
  enum { R = 8 }; /* id x y z u v w rho */
  int *dest = mem_alloc(1, (src->n ? src->n : 1) * sizeof *dest, "initial state");
  double *rec = mem_alloc(1, (src->n ? src->n : 1) * R * sizeof *rec, "initial state");
  for (size_t b = 0; b < src->n; b++) {
    double *r = rec + b * R;
    r[0] = (double)src->id[b]; /* ids below 2^53 are exact */
    for (int c = 0; c < 7; c++) r[1 + c] = src->col[c][b];
    dest[b] = own->owner ? own->owner(own->ctx, r[1], r[3]) : 0;
  }
  source_free(src);
  size_t got;
  double *in = send_records(own, dest, src->n, rec, R, &got);
  free(dest), free(rec);
  qsort(in, got, R * sizeof(double), cmp_first); /* by id */
  /* the vertices after the new fluid particles */
  const size_t nv = P->n - nf;
  if (got + nv > P->cap) part_reserve(P, got + nv);
  part_move(P, got, nf, nv);
  P->n = got + nv;
  const double mass = sc->rho0 * pow(sc->dr, sc->dim);
  for (size_t a = 0; a < got; a++) {
    const double *r = in + a * R;
    P->id[a] = (int64_t)r[0], P->kind[a] = KIND_FLUID, P->m[a] = mass, P->gam[a] = 1.0;
    P->x[a] = r[1], P->y[a] = r[2], P->z[a] = r[3];
    P->u[a] = r[4], P->v[a] = r[5], P->w[a] = r[6], P->rho[a] = r[7];
  }
  part_free(in);
}

/** In range lo .. hi of a periodic index of period n. */
static int in_periodic(int c, int lo, int hi, int n) {
  if (hi - lo + 1 >= n) return 1;
  return (c >= lo && c <= hi) || (c + n >= lo && c + n <= hi) || (c - n >= lo && c - n <= hi);
}

/** Another resolution: each rank receives the source particles of the cells around its fluid
    particles' cells (a source particle may go to several ranks), in file order. */
static void gather_cells(struct source *src, const struct particles *P, size_t nf,
                         const struct init_owner *own) {
  int nx, ny, nz;
  source_cells(src, &nx, &ny, &nz);
  int box[4] = {INT_MAX, INT_MIN, INT_MAX, INT_MIN}; /* this rank's cells +- 1: x lo hi, z lo hi */
  for (size_t a = 0; a < nf; a++) {
    int ix, iz;
    source_column(src, nx, nz, P->x[a], P->z[a], &ix, &iz);
    box[0] = ix - 1 < box[0] ? ix - 1 : box[0], box[1] = ix + 1 > box[1] ? ix + 1 : box[1];
    box[2] = iz - 1 < box[2] ? iz - 1 : box[2], box[3] = iz + 1 > box[3] ? iz + 1 : box[3];
  }
  int *boxes = mem_alloc(4 * (size_t)own->size, sizeof *boxes, "initial state");
  if (own->size > 1)
    CHECK_MPI(MPI_Allgather(box, 4, MPI_INT, boxes, 4, MPI_INT, MPI_COMM_WORLD));
  else
    memcpy(boxes, box, sizeof box);
  enum { R = 9 }; /* index x y z u v w rho mass */
  size_t m = 0, cap = src->n ? src->n : 1;
  int *dest = mem_alloc(1, cap * sizeof *dest, "initial state");
  double *rec = mem_alloc(1, cap * R * sizeof *rec, "initial state");
  for (size_t b = 0; b < src->n; b++) {
    int ix, iz;
    source_column(src, nx, nz, src->col[0][b], src->col[2][b], &ix, &iz);
    for (int r = 0; r < own->size; r++) {
      const int *q = boxes + 4 * r;
      if (q[0] > q[1] || !in_periodic(ix, q[0], q[1], nx) || !in_periodic(iz, q[2], q[3], nz))
        continue;
      if (m == cap) {
        cap *= 2;
        dest = mem_realloc(dest, cap, sizeof *dest, "initial state");
        rec = mem_realloc(rec, cap * R, sizeof *rec, "initial state");
      }
      rec[m * R] = (double)(src->first + b);
      for (int c = 0; c < 8; c++) rec[m * R + 1 + c] = src->col[c][b];
      dest[m++] = r;
    }
  }
  free(boxes);
  size_t got;
  double *in = send_records(own, dest, m, rec, R, &got);
  free(dest), free(rec);
  qsort(in, got, R * sizeof(double), cmp_first); /* file order */
  for (int c = 0; c < 8; c++) {
    free(src->col[c]);
    src->col[c] = mem_alloc(1, (got ? got : 1) * sizeof(double), "initial state");
    for (size_t k = 0; k < got; k++) src->col[c][k] = in[k * R + 1 + c];
  }
  free(src->id), src->id = NULL;
  src->n = got;
  part_free(in);
}

static int from_file(const struct scene *sc, struct particles *P, size_t nf,
                     const struct init_owner *own) {
  struct source src;
  TRY(read_source(sc->init_from, sc, &src, own));
  if (src.packed)
    msg("init: %d variables of %s were CF-packed (scale_factor, add_offset): unpacked to the "
        "packing's precision\n",
        src.packed, sc->init_from);
  if (src.total == P->n_fluid) { /* same resolution: the state itself, by id */
    place_state(&src, sc, P, nf, own);
    msg("init: positions, velocities and densities of %zu particles from %s\n", src.total,
        sc->init_from);
    nf = local_fluid(P);
    if (sc->init_density == INIT_DENSITY_RHO0) shift_density(sc, P, nf, own);
  } else {
    gather_cells(&src, P, nf, own);
    interpolate(&src, P, nf);
    msg("init: velocity interpolated from %zu particles of %s onto %zu particles\n", src.total,
        sc->init_from, P->n_fluid);
    source_free(&src);
  }
  return CHANSPH_OK;
}

/* ---- synthetic-eddy start-up (Jarrin et al. 2006; docs/theory.md) ---- */

void init_dns180(double yplus, double out[5]) {
  const int n = DNS_LM180_N;
  const double yp = fmax(0.0, yplus);
  if (yp >= dns_lm180[n - 1][0]) {
    for (int c = 0; c < 5; c++) out[c] = dns_lm180[n - 1][c + 1];
    return;
  }
  int i = 0;
  while (i < n - 2 && dns_lm180[i + 1][0] <= yp) i++;
  const double t = (yp - dns_lm180[i][0]) / (dns_lm180[i + 1][0] - dns_lm180[i][0]);
  for (int c = 0; c < 5; c++)
    out[c] = dns_lm180[i][c + 1] + t * (dns_lm180[i + 1][c + 1] - dns_lm180[i][c + 1]);
}

double init_sem_count(const struct scene *sc) {
  const double sig = sc->init_eddy_size * sc->delta;
  const double vol = sc->lx * (2.0 * sc->delta + 2.0 * sig) * sc->lz;
  return sc->init_eddies > 0 ? (double)sc->init_eddies
                             : fmax(1.0, floor(vol / (sig * sig * sig) + 0.5));
}

double init_bytes(const struct scene *sc) {
  if (sc->init_from[0] || sc->init_profile != INIT_SYNTHETIC) return 0.0;
  /* positions and signs, the order by cell and the cell of each eddy (init_sem_make) */
  return init_sem_count(sc) * (6.0 * sizeof(double) + sizeof(size_t) + sizeof(int));
}

int init_sem_make(struct init_sem *E, const struct scene *sc) {
  memset(E, 0, sizeof *E);
  const double sig = sc->init_eddy_size * sc->delta;
  E->sigma = sig, E->lx = sc->lx, E->lz = sc->lz, E->y0 = -sig;
  E->ly = 2.0 * sc->delta + 2.0 * sig;
  const double vol = E->lx * E->ly * E->lz;
  E->n = (size_t)init_sem_count(sc);
  E->scale = sqrt(vol / (sig * sig * sig) / (double)E->n);
  /* cells of width w >= sigma, no more cells than about 4 per eddy (w grows for a few eddies
     in a large box); fewer than 3 along a periodic direction: one cell (the nearest image is
     then the only one within sigma, as sigma <= l/2) */
  double w = sig;
  while (floor(E->lx / w) * floor(E->ly / w) * floor(E->lz / w) > 4.0 * (double)E->n + 64.0)
    w *= 1.25;
  E->nx = (int)floor(E->lx / w), E->ny = (int)fmax(1.0, floor(E->ly / w));
  E->nz = (int)floor(E->lz / w);
  if (E->nx < 3) E->nx = 1;
  if (E->nz < 3) E->nz = 1;
  const size_t ncell = (size_t)E->nx * E->ny * E->nz;
  E->pos = mem_alloc(1, E->n * 3 * sizeof(double), "initial state");
  E->eps = mem_alloc(1, E->n * 3 * sizeof(double), "initial state");
  E->start = mem_calloc(ncell + 1, sizeof(size_t), "initial state");
  E->order = mem_alloc(1, E->n * sizeof(size_t), "initial state");
  size_t *fill = mem_alloc(1, ncell * sizeof(size_t), "initial state");
  int *cellof = mem_alloc(1, E->n * sizeof(int), "initial state");
  if (!E->pos || !E->eps || !E->start || !E->order || !fill || !cellof)
    die("out of memory for %zu synthetic eddies", E->n);
  const double lo[3] = {0.0, E->y0, 0.0}, len[3] = {E->lx, E->ly, E->lz};
  const int nc[3] = {E->nx, E->ny, E->nz};
  for (size_t k = 0; k < E->n; k++) {
    int ci[3];
    for (int c = 0; c < 3; c++) {
      /* uniform in [lo, lo + len) and a random sign, keyed by (seed, eddy index, stream):
         streams 16-21 (the particle noise uses 0-2 of the particle ids) */
      const double r = 0.5 * (init_noise(sc->init_seed, (long long)k, 16 + c) + 1.0);
      E->pos[3 * k + c] = lo[c] + len[c] * r;
      E->eps[3 * k + c] = init_noise(sc->init_seed, (long long)k, 19 + c) < 0.0 ? -1.0 : 1.0;
      ci[c] = (int)fmin(nc[c] - 1, floor(r * nc[c]));
    }
    cellof[k] = (ci[2] * E->ny + ci[1]) * E->nx + ci[0];
    E->start[cellof[k] + 1]++;
  }
  for (size_t c = 0; c < ncell; c++) E->start[c + 1] += E->start[c];
  memcpy(fill, E->start, ncell * sizeof *fill);
  for (size_t k = 0; k < E->n; k++) E->order[fill[cellof[k]]++] = k; /* by eddy index */
  free(fill), free(cellof);
  return CHANSPH_OK;
}

void init_sem_free(struct init_sem *E) {
  free(E->pos), free(E->eps), free(E->start), free(E->order);
  memset(E, 0, sizeof *E);
}

void init_sem_xi(const struct init_sem *E, double x, double y, double z, double xi[3]) {
  const double sig = E->sigma, inv = 1.0 / sig;
  const double fn = 1.5 * sqrt(1.5); /* (3/2)^(3/2): integral of f^2 over the cube is sigma^3 */
  const double xr = x - E->lx * floor(x / E->lx), zr = z - E->lz * floor(z / E->lz);
  const int cx = (int)fmin(E->nx - 1, floor(xr / E->lx * E->nx));
  const int cy = (int)fmin(E->ny - 1, fmax(0.0, floor((y - E->y0) / E->ly * E->ny)));
  const int cz = (int)fmin(E->nz - 1, floor(zr / E->lz * E->nz));
  const int rx = E->nx >= 3 ? 1 : 0, rz = E->nz >= 3 ? 1 : 0;
  double s[3] = {0.0, 0.0, 0.0};
  for (int k = -rz; k <= rz; k++)
    for (int j = -1; j <= 1; j++) {
      if (cy + j < 0 || cy + j >= E->ny) continue;
      for (int i = -rx; i <= rx; i++) {
        const int ix = (cx + i + E->nx) % E->nx, iz = (cz + k + E->nz) % E->nz;
        const size_t c = ((size_t)iz * E->ny + cy + j) * E->nx + ix;
        for (size_t q = E->start[c]; q < E->start[c + 1]; q++) {
          const size_t e = E->order[q];
          const double ax = fabs(wrap(x - E->pos[3 * e], E->lx)) * inv;
          const double ay = fabs(y - E->pos[3 * e + 1]) * inv;
          const double az = fabs(wrap(z - E->pos[3 * e + 2], E->lz)) * inv;
          if (ax >= 1.0 || ay >= 1.0 || az >= 1.0) continue;
          const double f = fn * (1.0 - ax) * (1.0 - ay) * (1.0 - az);
          for (int d = 0; d < 3; d++) s[d] += E->eps[3 * e + d] * f;
        }
      }
    }
  for (int d = 0; d < 3; d++) xi[d] = E->scale * s[d];
}

void init_sem_velocity(const struct init_sem *E, const struct scene *sc, double ut, double x,
                       double y, double z, double vel[3]) {
  const double yw = fmin(y, 2.0 * sc->delta - y);
  const double sign =
      sc->drive_mode == DRIVE_FLUX ? (sc->u_bulk < 0 ? -1.0 : 1.0) : (sc->force < 0 ? -1.0 : 1.0);
  double d[5]; /* U+, u'u'+, v'v'+, w'w'+, u'v'+ */
  init_dns180(yw * ut / sc->nu, d);
  vel[0] = vel[1] = vel[2] = 0.0;
  if (!(yw > 0.0)) return; /* at (or beyond) a wall: no slip, no fluctuation */
  /* Lund et al. (1998): Cholesky factor of the local Reynolds-stress tensor; u'v' changes
     sign in the upper half */
  const double uv = (y > sc->delta ? -1.0 : 1.0) * d[4];
  const double a11 = sqrt(fmax(0.0, d[1]));
  const double a21 = a11 > 0.0 ? uv / a11 : 0.0;
  const double a22 = sqrt(fmax(0.0, d[2] - a21 * a21)), a33 = sqrt(fmax(0.0, d[3]));
  double xi[3];
  init_sem_xi(E, x, y, z, xi);
  /* a flow towards -x is the mirror image: u (mean and fluctuation) changes sign */
  vel[0] = sign * ut * (d[0] + a11 * xi[0]);
  vel[1] = ut * (a21 * xi[0] + a22 * xi[1]);
  vel[2] = ut * a33 * xi[2];
}

static void synthetic(const struct scene *sc, double ut, struct particles *P, size_t nf) {
  struct init_sem E;
  init_sem_make(&E, sc);
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < nf; a++) {
    double vel[3];
    init_sem_velocity(&E, sc, ut, P->x[a], P->y[a], P->z[a], vel);
    P->u[a] = vel[0], P->v[a] = vel[1], P->w[a] = vel[2];
  }
  msg("init: synthetic eddies (Jarrin et al. 2006): %zu eddies of size %.4g m, Lee & Moser "
      "Re_tau = 180 profiles with u_tau = %.6g m/s (Re_tau = %.4g)\n",
      E.n, E.sigma, ut, ut * sc->delta / sc->nu);
  if (ut * sc->delta / sc->nu > 1.1 * dns_lm180_re_tau)
    msg("init: note: Re_tau = %.4g is above the table's %.6g: beyond y+ = %.4g the synthetic "
        "field has the table's centre-line values (docs/theory.md)\n",
        ut * sc->delta / sc->nu, dns_lm180_re_tau, dns_lm180[DNS_LM180_N - 1][0]);
  init_sem_free(&E);
}

int init_fields(const struct scene *sc, struct particles *P, const struct init_owner *own) {
  const struct init_owner one = {NULL, NULL, 0, 1};
  if (!own) own = &one;
  const struct wall_law_def L = wall_law_make(WALL_LAW_REICHARDT, sc->kappa, sc->log_b);
  const double ut = sc->init_profile == INIT_REICHARDT || sc->init_profile == INIT_SYNTHETIC
                        ? init_reichardt_utau(sc)
                        : 0.0;
  if (sc->init_from[0]) {
    TRY(from_file(sc, P, local_fluid(P), own));
  } else if (sc->init_profile == INIT_SYNTHETIC) {
    synthetic(sc, ut, P, local_fluid(P));
  } else {
    const size_t nf = local_fluid(P);
    for (size_t a = 0; a < nf; a++) P->u[a] = mean_u(sc, &L, ut, P->y[a]);
    if (sc->init_profile == INIT_WAVE) /* thesis Sec. 3.1.2 */
      for (size_t a = 0; a < nf; a++)
        P->v[a] = sc->init_wave * sin(4.0 * M_PI * P->y[a] / (2.0 * sc->delta));
  }
  const double two_d = 2.0 * sc->delta;
  const double alpha = 2.0 * M_PI * sc->init_mode_kx / sc->lx;
  const double beta = sc->dim == 3 ? 2.0 * M_PI * sc->init_mode_kz / sc->lz : 0.0;
  const double bs = sc->dim == 3 ? 2.0 * M_PI * sc->init_streak_kz / sc->lz : 0.0;
  const size_t nf = local_fluid(P); /* this rank's fluid particles: the first slots */
  for (size_t a = 0; a < nf; a++) {
    const double eta = P->y[a] / two_d, x = P->x[a], z = P->z[a];
    if (sc->init_streaks > 0.0 && sc->dim == 3)
      P->u[a] += sc->init_streaks * 4.0 * eta * (1.0 - eta) * cos(bs * z);
    if (sc->init_modes > 0.0) {
      /* g = 16 eta^2 (1 - eta)^2 vanishes with its slope at both walls; psi = A g sin / k */
      const double A = sc->init_modes, g = 16.0 * eta * eta * (1 - eta) * (1 - eta);
      const double dg = 32.0 * eta * (1 - eta) * (1 - 2 * eta) / two_d; /* dg/dy */
      P->u[a] += A * dg / alpha * sin(alpha * x), P->v[a] -= A * g * cos(alpha * x);
      if (sc->dim == 3) P->v[a] += A * g * cos(beta * z), P->w[a] -= A * dg / beta * sin(beta * z);
    }
    if (sc->init_noise > 0.0) {
      const long long id = (long long)P->id[a];
      P->u[a] += sc->init_noise * init_noise(sc->init_seed, id, 0);
      P->v[a] += sc->init_noise * init_noise(sc->init_seed, id, 1);
      if (sc->dim == 3) P->w[a] += sc->init_noise * init_noise(sc->init_seed, id, 2);
    }
  }
  if (ut > 0.0 && sc->init_profile == INIT_REICHARDT && !sc->init_from[0]) /* else from the file */
    msg("init: Reichardt profile with u_tau = %.6g m/s\n", ut);
  return CHANSPH_OK;
}
