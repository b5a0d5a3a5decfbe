/**
 * @file test_stats_mpi.c
 * @brief The statistics engine across MPI ranks (issue 6): synthetic snapshots distributed
 *        over the ranks by cell column (contiguous column ranges in rank order, canonical order
 *        within a column, random interleaving across columns) give the same engine state,
 *        bit for bit, as one rank holding every particle, on every rank; stats.nc too.
 *
 * Usage: mpirun -np N test_stats_mpi            (check, N = 1, 2, 3, 4, ...)
 *        mpirun -np N test_stats_mpi --bench    (les395_small sizes: time per snapshot)
 *
 * Rank 0 runs the serial reference inside the same program: the same snapshots, all columns on
 * one rank with another interleaving, with MPI_COMM_SELF and with MPI_COMM_NULL.
 */
#include <math.h>
#include <mpi.h>
#include <netcdf.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "moments.h"
#include "state.h"
#include "stats.h"
#include "stats_nc.h"
#include "stats_setup.h"
#include "synthetic.h"

static int failures = 0;

#define EXPECT(cond, ...)                 \
  do {                                    \
    if (!(cond)) {                        \
      printf("FAIL (rank %d): ", rank_g); \
      printf(__VA_ARGS__);                \
      printf("\n");                       \
      failures++;                         \
    }                                     \
  } while (0)

static int rank_g = 0, size_g = 1;

/* The global particle set of one snapshot (ids 0 .. nf - 1 fluid, then nw wall vertices). */
struct world {
  size_t nf, nw, n;
  int ncol;
  double lx, lz, cell;
  double *x, *y, *z, *u, *v, *w, *p, *rho, *m, *ax, *ay, *az, *nut, *kr;
  int64_t *id;
  uint8_t *skip;
  int *col;
  size_t *order; /* canonical order: by (column, iz, iy, id) */
  size_t *start; /* [ncol + 1] first position of each column in order */
};

enum { NFIELD = 14 };

/* The addresses of the double arrays of a world, in the order of struct local's f. */
static void fields(struct world *W, double **f[NFIELD]) {
  double **g[NFIELD] = {&W->x,   &W->y, &W->z,  &W->u,  &W->v,  &W->w,   &W->p,
                        &W->rho, &W->m, &W->ax, &W->ay, &W->az, &W->nut, &W->kr};
  memcpy(f, g, sizeof g);
}

static void world_init(struct world *W, size_t nf, size_t nw, int ncol, double lx, double lz) {
  memset(W, 0, sizeof *W);
  W->nf = nf, W->nw = nw, W->n = nf + nw, W->ncol = ncol, W->lx = lx, W->lz = lz;
  W->cell = lx / ncol;
  double **f[NFIELD];
  fields(W, f);
  for (int k = 0; k < NFIELD; k++) *f[k] = malloc(W->n * sizeof(double));
  W->id = malloc(W->n * sizeof(int64_t));
  W->skip = malloc(W->n);
  W->col = malloc(W->n * sizeof(int));
  W->order = malloc(W->n * sizeof(size_t));
  W->start = malloc(((size_t)ncol + 1) * sizeof(size_t));
}

static void world_free(struct world *W) {
  double **f[NFIELD];
  fields(W, f);
  for (int k = 0; k < NFIELD; k++) free(*f[k]);
  free(W->id), free(W->skip), free(W->col), free(W->order), free(W->start);
}

static const struct world *sort_world;
static long cell_of(double v, double h) {
  return (long)floor(v / h);
}
static int canon_cmp(const void *pa, const void *pb) {
  const struct world *W = sort_world;
  const size_t a = *(const size_t *)pa, b = *(const size_t *)pb;
  if (W->col[a] != W->col[b]) return W->col[a] < W->col[b] ? -1 : 1;
  const long za = cell_of(W->z[a], W->cell), zb = cell_of(W->z[b], W->cell);
  if (za != zb) return za < zb ? -1 : 1;
  const long ya = cell_of(W->y[a], W->cell), yb = cell_of(W->y[b], W->cell);
  if (ya != yb) return ya < yb ? -1 : 1;
  return W->id[a] < W->id[b] ? -1 : W->id[a] > W->id[b];
}

/* Snapshot s at time t: particles drift downstream with a y-dependent speed (periodic in x and
   z), wobble in y, and carry random velocities, pressures, accelerations, LES fields. */
static void world_step(struct world *W, long s, double t) {
  const double pi2 = 6.283185307179586;
  for (size_t a = 0; a < W->n; a++) {
    const uint64_t k0 = (uint64_t)a * 16, k = ((uint64_t)s * W->n + a) * 16 + 1000003;
    const int wall = a >= W->nf;
    double y = wall ? (uniform(k0 + 1) < 0.5 ? 0.0 : 2.0)
                    : 0.02 + 1.96 * uniform(k0 + 1) + 0.015 * sin(pi2 * (t + uniform(k0 + 2)));
    const double U = wall ? 0.0 : 0.6 + 0.8 * y * (2.0 - y);
    double x = fmod(W->lx * uniform(k0 + 3) + U * t, W->lx);
    double z = fmod(W->lz * uniform(k0 + 4) + 0.05 * t, W->lz);
    W->x[a] = x, W->y[a] = y, W->z[a] = z, W->id[a] = (int64_t)a, W->skip[a] = (uint8_t)wall;
    W->u[a] = wall ? 0.0 : U + 0.2 * gauss(k);
    W->v[a] = wall ? 0.0 : 0.1 * gauss(k + 1);
    W->w[a] = wall ? 0.0 : 0.12 * gauss(k + 2);
    W->p[a] = 100.0 + gauss(k + 3), W->rho[a] = 1000.0 * (1.0 + 0.01 * gauss(k + 4));
    W->m[a] = 1000.0 * 1e-3 * (1.0 + 0.001 * uniform(k + 5));
    W->ax[a] = gauss(k + 6), W->ay[a] = gauss(k + 7), W->az[a] = gauss(k + 8);
    W->nut[a] = 1e-4 * uniform(k + 9), W->kr[a] = 1e-3 * uniform(k + 10);
    int c = (int)floor(x / W->cell);
    W->col[a] = c < 0 ? 0 : c >= W->ncol ? W->ncol - 1 : c;
    W->order[a] = a;
  }
  sort_world = W;
  qsort(W->order, W->n, sizeof(size_t), canon_cmp);
  for (int c = 0; c <= W->ncol; c++) W->start[c] = W->n;
  for (size_t i = W->n; i-- > 0;) W->start[W->col[W->order[i]]] = i;
  for (int c = W->ncol; c-- > 0;) /* empty columns start where the next one does */
    if (W->start[c] > W->start[c + 1]) W->start[c] = W->start[c + 1];
}

/* A rank's snapshot: the particles of columns [c0, c1), each column in canonical order, the
   columns interleaved at random (seeded by key). */
struct local {
  size_t n, cap;
  double *f[NFIELD];
  int64_t *id;
  uint8_t *skip;
  int *col;
};

static void local_build(struct local *L, struct world *W, int c0, int c1, uint64_t key) {
  const size_t n = W->start[c1] - W->start[c0];
  if (n > L->cap) {
    for (int k = 0; k < NFIELD; k++) L->f[k] = realloc(L->f[k], n * sizeof(double));
    L->id = realloc(L->id, n * sizeof(int64_t));
    L->skip = realloc(L->skip, n ? n : 1);
    L->col = realloc(L->col, n * sizeof(int));
    L->cap = n;
  }
  size_t *next = malloc(((size_t)(c1 - c0) + 1) * sizeof(size_t));
  for (int c = c0; c < c1; c++) next[c - c0] = W->start[c];
  double **wf[NFIELD];
  fields(W, wf);
  for (size_t i = 0; i < n; i++) {
    int c;
    do c = c0 + (int)(uniform(key + 7919 * i + (uint64_t)c0) * (c1 - c0)), key += 104729;
    while (next[c - c0] >= W->start[c + 1]);
    const size_t a = W->order[next[c - c0]++];
    for (int k = 0; k < NFIELD; k++) L->f[k][i] = (*wf[k])[a];
    L->id[i] = W->id[a], L->skip[i] = W->skip[a], L->col[i] = W->col[a];
  }
  L->n = n;
  free(next);
}

static void local_free(struct local *L) {
  for (int k = 0; k < NFIELD; k++) free(L->f[k]);
  free(L->id), free(L->skip), free(L->col);
}

static struct stats_snapshot snapshot(const struct local *L, const struct world *W, long s,
                                      double t, int c0, int c1, MPI_Comm comm) {
  const struct stats_snapshot snap = {.n = L->n,
                                      .x = L->f[0],
                                      .y = L->f[1],
                                      .z = L->f[2],
                                      .u = L->f[3],
                                      .v = L->f[4],
                                      .w = L->f[5],
                                      .p = L->f[6],
                                      .rho = L->f[7],
                                      .m = L->f[8],
                                      .ax = L->f[9],
                                      .ay = L->f[10],
                                      .az = L->f[11],
                                      .nu_t = L->f[12],
                                      .k_r = L->f[13],
                                      .id = L->id,
                                      .skip = L->skip,
                                      .t = t,
                                      .fx = 1.0 + 0.01 * sin(t),
                                      .step = s,
                                      .wall_fx = {-0.5 - 0.01 * cos(t), -0.5 + 0.01 * sin(t)},
                                      .col = L->col,
                                      .ncol = W->ncol,
                                      .col0 = c0,
                                      .col1 = c1,
                                      .comm = comm};
  return snap;
}

/* Column range of rank r of p: uneven on purpose (and possibly empty). */
static void range_of(int r, int p, int ncol, int *c0, int *c1) {
  int b[65];
  for (int k = 0; k <= p; k++) b[k] = (int)((long)k * ncol / p);
  for (int k = 1; k < p; k++) b[k] += k % 2 ? 1 : -1;
  for (int k = 1; k < p; k++) b[k] = b[k] < b[k - 1] ? b[k - 1] : b[k] > ncol ? ncol : b[k];
  *c0 = b[r], *c1 = b[r + 1];
}

static struct test_stats_config config_a(void) { /* bins, not folded, LES; corr and Lagrangian */
  struct test_stats_config c = {.eulerian = 1};
  c.eul = (struct euler_config){.nb = 16,
                                .y0 = 0.0,
                                .y1 = 2.0,
                                .fold = 0,
                                .delta = 1.0,
                                .nu = 1e-3,
                                .rho0 = 1000.0,
                                .area = 4.5,
                                .t_start = 0.1,
                                .window = 0.5,
                                .les = 1,
                                .method = EULER_BINS,
                                .dim = 3};
  c.corr = (struct corr_config){.n_levels = 2,
                                .y = {0.3, 0.7},
                                .y_plus = {30, 70},
                                .nx = 24,
                                .nz = 8,
                                .lx = 3.0,
                                .lz = 1.5,
                                .half = 0.06,
                                .delta = 1.0,
                                .t_start = 0.1,
                                .window = 0.5};
  c.lagr = (struct lagr_config){.n_levels = 2,
                                .y = {0.25, 0.6},
                                .y_plus = {25, 60},
                                .x0 = 1.1,
                                .half = 0.08,
                                .lx = 3.0,
                                .lz = 1.5,
                                .delta = 1.0,
                                .horizon = 0.6,
                                .release_every = 0.3,
                                .n_lags = 6,
                                .n_stations = 2,
                                .station = {0.15, 0.4},
                                .pdf_bins = 10,
                                .t_start = 0.1};
  c.pdf = (struct pdf_config){.n_levels = 2,
                              .y = {0.3, 0.7},
                              .y_plus = {30, 70},
                              .half = 0.06,
                              .delta = 1.0,
                              .t_start = 0.1,
                              .window = 0.5,
                              .u_tau = 0.05,
                              .fine = 0.05,
                              .bins = 24,
                              .range = 4.0};
  return c;
}

static struct test_stats_config config_b(
    void) { /* SPH interpolation, folded; release plane x0 = 0 */
  struct test_stats_config c = config_a();
  c.eul.method = EULER_SPH, c.eul.fold = 1, c.eul.h = 0.08, c.eul.les = 0, c.eul.nb = 20;
  c.eul.y1 = 1.0;
  c.corr.n_levels = 1, c.corr.y[0] = 0.5, c.corr.nz = 1;
  c.lagr.x0 = 0.0, c.lagr.n_levels = 1, c.lagr.y[0] = 0.5, c.lagr.release_every = 0.2;
  return c;
}

/* Every field of a's state equal, bit for bit, to b's; returns the number that differ. */
static int compare_states(struct stats *a, struct stats *b, const char *what) {
  struct state_list La = {0}, Lb = {0};
  stats_state(a, &La);
  stats_state(b, &Lb);
  int bad = La.n != Lb.n;
  for (int i = 0; i < La.n; i++) {
    const struct state_field *fa = &La.f[i], *fb = state_find(&Lb, fa->name);
    const size_t bytes = state_count(fa) * 8;
    if (!fb || state_count(fb) * 8 != bytes || memcmp(fa->data, fb->data, bytes)) {
      printf("  %s: field %s differs\n", what, fa->name);
      bad++;
    }
  }
  state_free(&La), state_free(&Lb);
  return bad;
}

/* Every rank's state equal to rank 0's (broadcast field by field). */
static int compare_across_ranks(struct stats *a) {
  struct state_list L = {0};
  stats_state(a, &L);
  int bad = 0;
  for (int i = 0; i < L.n; i++) {
    unsigned long long n = state_count(&L.f[i]);
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    char *buf = malloc(n * 8 + 1);
    if (rank_g == 0) memcpy(buf, L.f[i].data, n * 8);
    MPI_Bcast(buf, (int)(n * 8), MPI_BYTE, 0, MPI_COMM_WORLD);
    if (n != state_count(&L.f[i]) || memcmp(buf, L.f[i].data, n * 8)) {
      printf("  rank %d: field %s differs from rank 0\n", rank_g, L.f[i].name);
      bad++;
    }
    free(buf);
  }
  state_free(&L);
  int all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

static int write_nc(const struct stats *st, const char *path) {
  int ncid, rc = nc_create(path, NC_NETCDF4 | NC_CLOBBER, &ncid);
  char err[256] = "";
  if (rc == NC_NOERR) rc = stats_nc_write(st, ncid, err, sizeof err);
  if (rc == NC_NOERR) rc = nc_close(ncid);
  if (rc != NC_NOERR) printf("cannot write %s: %s %s\n", path, nc_strerror(rc), err);
  return rc;
}

/* Every variable of every group of two files bitwise equal; returns variables compared or -1. */
static int compare_nc_group(int ga, int gb, int *nvar) {
  int nv = 0, nva = 0, ng = 0, ngb = 0;
  if (nc_inq_varids(ga, &nv, NULL) || nc_inq_varids(gb, &nva, NULL) || nv != nva) return -1;
  int *ids = malloc((size_t)(nv ? nv : 1) * sizeof(int));
  nc_inq_varids(ga, &nv, ids);
  int bad = 0;
  for (int i = 0; i < nv; i++) {
    char name[NC_MAX_NAME + 1];
    nc_type type;
    int nd, dims[NC_MAX_VAR_DIMS], vb;
    size_t count = 1, tsize = 0;
    nc_inq_var(ga, ids[i], name, &type, &nd, dims, NULL);
    for (int d = 0; d < nd; d++) {
      size_t len;
      nc_inq_dimlen(ga, dims[d], &len);
      count *= len;
    }
    nc_inq_type(ga, type, NULL, &tsize);
    if (nc_inq_varid(gb, name, &vb)) {
      printf("  stats.nc: variable %s missing\n", name);
      bad++;
      continue;
    }
    char *a = malloc(count * tsize + 1), *b = malloc(count * tsize + 1);
    int differ = nc_get_var(ga, ids[i], a) || nc_get_var(gb, vb, b);
    if (!differ && type == NC_STRING) { /* labels: compare the strings, not the pointers */
      for (size_t j = 0; j < count; j++)
        differ |= strcmp(((char **)(void *)a)[j], ((char **)(void *)b)[j]) != 0;
      nc_free_string(count, (char **)(void *)a), nc_free_string(count, (char **)(void *)b);
    } else if (!differ) {
      differ = memcmp(a, b, count * tsize) != 0;
    }
    if (differ) {
      printf("  stats.nc: variable %s differs\n", name);
      bad++;
    }
    free(a), free(b);
    (*nvar)++;
  }
  free(ids);
  if (nc_inq_grps(ga, &ng, NULL) || nc_inq_grps(gb, &ngb, NULL) || ng != ngb) return -1;
  int *grps = malloc((size_t)(ng ? ng : 1) * sizeof(int));
  nc_inq_grps(ga, &ng, grps);
  for (int i = 0; i < ng; i++) {
    char name[NC_MAX_NAME + 1];
    int sub;
    nc_inq_grpname(grps[i], name);
    if (nc_inq_grp_ncid(gb, name, &sub)) {
      bad++;
      continue;
    }
    const int r = compare_nc_group(grps[i], sub, nvar);
    bad += r < 0 ? 1 : r;
  }
  free(grps);
  return bad;
}

static int compare_nc(const char *pa, const char *pb, int *nvar) {
  int a, b;
  if (nc_open(pa, NC_NOWRITE, &a) || nc_open(pb, NC_NOWRITE, &b)) return 1;
  const int bad = compare_nc_group(a, b, nvar);
  nc_close(a), nc_close(b);
  return bad < 0 ? 1 : bad;
}

/* One configuration: nsnap snapshots to the distributed engine and, on rank 0, to the serial
   references; then the comparisons. */
static void run_check(const char *name, const struct test_stats_config *cfg, size_t nf, size_t nw,
                      int ncol, long nsnap, uint64_t seed) {
  struct world W;
  world_init(&W, nf, nw, ncol, cfg->corr.lx, cfg->corr.lz);
  struct local Lp = {0}, Ls = {0};
  struct stats par, self, null;
  test_stats_init(&par, cfg);
  if (rank_g == 0) test_stats_init(&self, cfg), test_stats_init(&null, cfg);
  int c0, c1;
  range_of(rank_g, size_g, ncol, &c0, &c1);
  for (long s = 0; s < nsnap; s++) {
    const double t = 0.05 * (double)s;
    world_step(&W, s, t);
    local_build(&Lp, &W, c0, c1, seed + ((uint64_t)s * 64 + (uint64_t)rank_g) * 1000003);
    const struct stats_snapshot sp = snapshot(&Lp, &W, s, t, c0, c1, MPI_COMM_WORLD);
    stats_sample(&par, &sp);
    if (rank_g == 0) {
      local_build(&Ls, &W, 0, ncol, seed + (uint64_t)s * 77777 + 5);
      const struct stats_snapshot ss = snapshot(&Ls, &W, s, t, 0, ncol, MPI_COMM_SELF);
      stats_sample(&self, &ss);
      struct stats_snapshot sn = ss;
      sn.comm = MPI_COMM_NULL;
      stats_sample(&null, &sn);
    }
  }
  const int across = compare_across_ranks(&par);
  EXPECT(across == 0, "%s: %d state fields differ between the ranks", name, across);
  if (rank_g == 0) {
    const int d1 = compare_states(&par, &self, "vs MPI_COMM_SELF");
    const int d2 = compare_states(&self, &null, "MPI_COMM_SELF vs MPI_COMM_NULL");
    EXPECT(d1 == 0, "%s: %d state fields differ from the serial run", name, d1);
    EXPECT(d2 == 0, "%s: MPI_COMM_NULL differs from MPI_COMM_SELF in %d fields", name, d2);
    /* the engines did work */
    const struct euler *eu = test_eu(&par);
    const struct corr *co = test_co(&par);
    const struct lagr *la = test_la(&par);
    double pdf_n = 0.0; /* station crossings over all levels and stations */
    for (int k = 0; k < cfg->lagr.n_levels * cfg->lagr.n_stations; k++)
      pdf_n += la->pdf[(size_t)k * (size_t)(cfg->lagr.pdf_bins + 3) + cfg->lagr.pdf_bins];
    EXPECT(eu->nwin >= 2, "%s: %zu windows", name, eu->nwin);
    const struct pdf *pd = test_pdf(&par);
    EXPECT(pd->nwin >= 2 && pd->pow[0] > 0, "%s: PDF engine idle (%zu windows)", name, pd->nwin);
    EXPECT(co->samples[0] > 0, "%s: no correlation planes", name);
    EXPECT(co->cfg.n_levels == 0 || co->nwin >= 2, "%s: %zu correlation windows", name, co->nwin);
    EXPECT(la->releases >= 2 && la->ntracks > 0 && pdf_n > 0,
           "%s: Lagrangian idle (%g releases, %zu tracks, %g crossings)", name, la->releases,
           la->ntracks, pdf_n);
    char pa[256], pb[256];
    snprintf(pa, sizeof pa, "stats_mpi_%s_np%d.nc", name, size_g);
    snprintf(pb, sizeof pb, "stats_mpi_%s_np%d_serial.nc", name, size_g);
    int nvar = 0, dn = 1;
    if (!write_nc(&par, pa) && !write_nc(&self, pb)) dn = compare_nc(pa, pb, &nvar);
    EXPECT(dn == 0, "%s: stats.nc differs from the serial one (%d)", name, dn);
    remove(pa), remove(pb);
    char ranges[256] = "";
    for (int r = 0, c0r, c1r; r < size_g && r < 16; r++) {
      range_of(r, size_g, ncol, &c0r, &c1r);
      snprintf(ranges + strlen(ranges), sizeof ranges - strlen(ranges), "%s[%d,%d)", r ? " " : "",
               c0r, c1r);
    }
    printf("%s: column ranges %s\n", name, ranges);
    printf(
        "%s on %d rank(s), %d columns, %zu particles x %ld snapshots: state %s to the serial "
        "run (%zu windows, %g correlation planes, %g releases, %zu tracks, %g station "
        "crossings), the same on every rank: %s; stats.nc: %d variables %s\n",
        name, size_g, ncol, W.n, nsnap, d1 ? "DIFFERENT" : "bitwise identical", eu->nwin,
        co->samples[0], la->releases, la->ntracks, pdf_n, across ? "NO" : "yes", nvar,
        dn ? "DIFFERENT" : "bitwise identical");
    stats_free(&self), stats_free(&null);
  }
  stats_free(&par);
  local_free(&Lp), local_free(&Ls);
  world_free(&W);
}

/* les395_small sizes: 38 750 fluid + 2 500 wall particles, 32 bins, 38 columns, two
   correlation levels on 50 x 25, two Lagrangian levels. Time of stats_sample per snapshot. */
static void run_bench(void) {
  const int ncol = 38, nsnap = 30;
  struct test_stats_config cfg = config_a();
  cfg.eul.nb = 32, cfg.eul.window = 0.25, cfg.eul.t_start = 0.0;
  cfg.corr.lx = 3.125, cfg.corr.lz = 1.5625, cfg.corr.nx = 50, cfg.corr.nz = 25;
  cfg.corr.half = 0.03125, cfg.corr.t_start = 0.0;
  cfg.lagr.lx = 3.125, cfg.lagr.lz = 1.5625, cfg.lagr.half = 0.03125, cfg.lagr.t_start = 0.0;
  cfg.lagr.horizon = 1.0, cfg.lagr.release_every = 0.25, cfg.lagr.n_lags = 20;
  const struct {
    const char *what;
    int eul, corr, lagr;
  } parts[] = {{"Eulerian bins", 1, 0, 0},
               {"correlations", 0, 1, 0},
               {"Lagrangian", 0, 0, 1},
               {"all three", 1, 1, 1}};
  struct world W;
  world_init(&W, 38750, 2500, ncol, cfg.corr.lx, cfg.corr.lz);
  struct local L = {0};
  int c0, c1;
  range_of(rank_g, size_g, ncol, &c0, &c1);
  for (size_t k = 0; k < sizeof parts / sizeof parts[0]; k++) {
    struct test_stats_config c = cfg;
    c.eulerian = parts[k].eul;
    if (!parts[k].corr) c.corr.n_levels = 0;
    if (!parts[k].lagr) c.lagr.n_levels = 0;
    struct stats st;
    test_stats_init(&st, &c);
    double tsum = 0.0, tmax = 0.0;
    size_t gathered = 0;
    for (long s = 0; s < nsnap; s++) {
      const double t = 0.05 * (double)s;
      world_step(&W, s, t);
      local_build(&L, &W, c0, c1, 99 + ((uint64_t)s * 64 + (uint64_t)rank_g) * 1000003);
      const struct stats_snapshot sp = snapshot(&L, &W, s, t, c0, c1, MPI_COMM_WORLD);
      MPI_Barrier(MPI_COMM_WORLD);
      const double t0 = MPI_Wtime();
      stats_sample(&st, &sp);
      double dt = MPI_Wtime() - t0, dmax;
      MPI_Allreduce(&dt, &dmax, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      tsum += dmax, tmax = fmax(tmax, dmax);
      gathered +=
          (parts[k].eul && size_g > 1 ? test_eu(&st)->nsub * (size_t)c.eul.nb * (MOM_LEN + 2) : 0) +
          (parts[k].corr && size_g > 1 ? test_co(&st)->nall * CORR_ENT : 0) +
          (parts[k].lagr && size_g > 1 ? test_la(&st)->nall * LAGR_REC : 0);
    }
    if (rank_g == 0)
      printf(
          "bench %-13s %d rank(s): stats_sample %.3f ms per snapshot (mean of %d, max %.3f "
          "ms); %.1f kB received per rank and snapshot\n",
          parts[k].what, size_g, 1e3 * tsum / nsnap, nsnap, 1e3 * tmax,
          8.0 * (double)gathered / nsnap / 1024.0);
    stats_free(&st);
  }
  local_free(&L);
  world_free(&W);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_g);
  MPI_Comm_size(MPI_COMM_WORLD, &size_g);
  if (argc > 1 && !strcmp(argv[1], "--bench")) {
    run_bench();
    MPI_Finalize();
    return 0;
  }
  const struct test_stats_config a = config_a(), b = config_b();
  run_check("bins", &a, 6000, 400, 13, 60, 1234567);
  run_check("sph_folded", &b, 5000, 300, 11, 50, 7654321);
  run_check("three_columns", &a, 3000, 200, 3, 40, 424242); /* empty ranges on 4 ranks */
  int all = 0;
  MPI_Allreduce(&failures, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank_g == 0) printf(all ? "FAILED (%d)\n" : "all passed\n", all);
  MPI_Finalize();
  return all ? 1 : 0;
}
