/*
 * test_nbr.c: unit test of the cell-list neighbour search of solver/nbr.h, nbr.c.
 *
 * For several 2-D and 3-D scenes (built with scene_load and part_create), the fluid particles
 * are displaced randomly by up to 0.4 dr in each direction (fixed-seed LCG, y stays inside
 * (0, 2 delta)) and some are moved by whole periods in x (and z), then nbr_sort and nbr_build
 * run. Checks:
 *  - every particle's neighbour set (pairs with |r_ab| < 2h, self excluded, minimum image in x
 *    and z) equals a brute-force O(N^2) search, compared by particle id, without duplicates;
 *  - after nbr_sort the particles are ordered by cell and by id within a cell, the cell
 *    offsets start[] match, x (z) are wrapped into [0, l] (x = l, which floor-wrapping of a
 *    tiny negative x can give, is counted and printed), and every permuted array (x, y, z,
 *    u, v, w, rho, m, gam, ksum, ddiff, kind) moved with its particle's id;
 *  - a second nbr_sort is the identity; the list is the same (in order) with 1 thread, and
 *    after forcing the list to grow from a tiny stride;
 *  - the threaded sort gives the order of 1 thread with 2, 3 and 7 threads, from shuffled slots
 *    and from sorted slots with 1% swapped (check_threads).
 */
#include <math.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernel.h"
#include "nbr.h"
#include "part.h"
#include "scene.h"

/** Minimal fixed-seed LCG in [0, 1). */
static unsigned long long lcg_state = 0x9E3779B97F4A7C15ULL;
static double lcg_uniform(void) {
  lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

/** Minimum-image separation for |d| <= 2.5 l. */
static double min_image(double d, double l) {
  return d - l * nearbyint(d / l);
}

static int cmp_i64(const void *a, const void *b) {
  const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

enum { N_FIELDS = 11 };

/** Values of every permuted array of one particle, indexed by id before the sort. */
struct snapshot {
  double *d[N_FIELDS];
  uint8_t *kind;
};

static double **field(struct particles *P, int j) {
  double **f[] = {&P->x,   &P->y, &P->z,   &P->u,    &P->v,    &P->w,
                  &P->rho, &P->m, &P->gam, &P->ksum, &P->ddiff};
  return f[j];
}

static int check_round(const char *name0, int round, const struct scene *sc, struct particles *P,
                       struct nbr *nb);

/** Run one scene; returns the number of failures. */
static int run_case(const char *name, int n_set, char **set) {
  struct scene s;
  if (scene_load(&s, NULL, n_set, set) != 0) {
    printf("FAIL: %s: scene_load rejected the scene\n", name);
    return 1;
  }
  struct particles P;
  struct walls W;
  part_create(&P, &W, &s);
  const size_t n = P.n;
  int fails = 0;

  /* ids are 0..n-1 in creation order */
  for (size_t a = 0; a < n; a++)
    if (P.id[a] != (int64_t)a) {
      printf("FAIL: %s: part_create id[%zu] = %lld\n", name, a, (long long)P.id[a]);
      return 1;
    }

  for (size_t a = 0; a < n; a++) {
    const double id = (double)a;
    P.u[a] = id + 0.125, P.v[a] = -id, P.w[a] = 3.0 * id + 0.5, P.rho[a] = 1000.0 + 1e-3 * id;
    P.m[a] = 1.0 + 1e-6 * id, P.gam[a] = 0.5 + 1e-7 * id, P.ksum[a] = 7.0 * id;
    P.ddiff[a] = -2.0 * id - 0.25;
  }
  struct nbr nb;
  {
    const struct nbr_range whole = nbr_whole(&s);
    nbr_init(&nb, &s, n, &whole);
  }
  for (int round = 0; round < 2; round++) {
    fails += check_round(name, round, &s, &P, &nb);
    if (fails) break;
  }
  nbr_free(&nb);
  part_destroy(&P, &W);
  return fails;
}

/**
 * One round: displace the fluid (from the lattice in round 0, from the sorted state of round 0
 * in round 1, so that particles change cell and the per-cell id sort has work to do), sort,
 * build and check everything. Returns the number of failures.
 */
static int check_round(const char *name0, int round, const struct scene *sc, struct particles *P,
                       struct nbr *nb) {
  const struct scene s = *sc;
  char name[128];
  snprintf(name, sizeof name, "%s, round %d", name0, round);
  const size_t n = P->n;
  const double dr = s.dr, h = scene_h(&s), ly = 2.0 * s.delta;
  const double lx = s.lx, lz = s.dim == 3 ? s.lz : 1.0;
  const double support2 = 4.0 * h * h;
  int fails = 0;

  /* displace the fluid (0.4 dr per round keeps y in [0.2 dr, 2 delta - 0.2 dr]) and move some
     particles by whole periods */
  for (size_t a = 0; a < n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    P->x[a] += 0.4 * dr * (2.0 * lcg_uniform() - 1.0);
    P->y[a] += 0.4 * dr * (2.0 * lcg_uniform() - 1.0);
    if (s.dim == 3) P->z[a] += 0.4 * dr * (2.0 * lcg_uniform() - 1.0);
    if (a % 5 == 0) {
      const int k = (int)(lcg_uniform() * 4.0) - 2;        /* -2 .. 1 */
      const double periods = (double)(k >= 0 ? k + 1 : k); /* -2, -1, 1, 2 */
      P->x[a] += periods * lx;
      if (s.dim == 3 && a % 10 == 0) P->z[a] -= periods * lz;
    }
    if (!(P->y[a] > 0.0 && P->y[a] < ly)) {
      printf("FAIL: %s: test set-up put y = %g outside (0, 2 delta)\n", name, P->y[a]);
      return 1;
    }
  }
  /* snapshot of every permuted array, by id */
  struct snapshot snap;
  for (int j = 0; j < N_FIELDS; j++) {
    snap.d[j] = malloc(n * sizeof(double));
    for (size_t a = 0; a < n; a++) snap.d[j][P->id[a]] = (*field(P, j))[a];
  }
  snap.kind = malloc(n);
  for (size_t a = 0; a < n; a++) snap.kind[P->id[a]] = P->kind[a];

  nbr_sort(nb, P);
  const struct kernel K = kernel_make(s.dim, h);
  double *ksum = calloc(n, sizeof *ksum);
  nbr_build(nb, P, &K, ksum);

  /* --- the sort: a permutation, arrays moved consistently, positions wrapped */
  char *seen = calloc(n, 1);
  size_t pos_bad = 0, arr_bad = 0, at_l = 0;
  double max_shift_err = 0.0;
  for (size_t i = 0; i < n; i++) {
    const int64_t id = P->id[i];
    if (id < 0 || (size_t)id >= n || seen[id]) {
      printf("FAIL: %s: ids after the sort are not a permutation (id %lld at %zu)\n", name,
             (long long)id, i);
      fails++;
      break;
    }
    seen[id] = 1;
    for (int j = 0; j < N_FIELDS; j++) {
      const double now = (*field(P, j))[i], was = snap.d[j][id];
      const double l = j == 0 ? lx : j == 2 && s.dim == 3 ? lz : 0.0;
      if (l > 0.0) { /* periodic: same point modulo l, inside [0, l) */
        const double k = nearbyint((now - was) / l), err = fabs(now - was - k * l);
        if (err > max_shift_err) max_shift_err = err;
        if (!(now >= 0.0 && now <= l) || err > 1e-12 * l) pos_bad++;
        if (now == l) at_l++;
      } else if (now != was) {
        if (j <= 2)
          pos_bad++;
        else
          arr_bad++;
      }
    }
    if (P->kind[i] != snap.kind[id]) arr_bad++;
  }
  free(seen);
  if (pos_bad || arr_bad) {
    printf("FAIL: %s: %zu positions and %zu other values did not move with their particle\n", name,
           pos_bad, arr_bad);
    fails++;
  }

  /* --- order: by cell (the solver's cell formula), by id within a cell; start[] agrees */
  size_t order_bad = 0;
  if (nb->start[0] != 0 || nb->start[nb->ncell] != n) order_bad++;
  for (size_t c = 0; c < nb->ncell; c++)
    for (size_t i = nb->start[c]; i < nb->start[c + 1]; i++) {
      int ix = (int)(P->x[i] * nb->cx), iy = (int)(P->y[i] * nb->cy);
      int iz = s.dim == 3 ? (int)(P->z[i] * nb->cz) : 0;
      ix = ix < 0 ? 0 : ix >= nb->nx ? nb->nx - 1 : ix;
      iy = iy < 0 ? 0 : iy >= nb->ny ? nb->ny - 1 : iy;
      iz = iz < 0 ? 0 : iz >= nb->nz ? nb->nz - 1 : iz;
      if ((size_t)((iz * nb->ny + iy) * nb->nx + ix) != c) order_bad++;
      if (i > nb->start[c] && P->id[i] <= P->id[i - 1]) order_bad++;
    }
  if (order_bad) {
    printf("FAIL: %s: %zu particles out of cell/id order\n", name, order_bad);
    fails++;
  }

  /* --- kernel sums of the same pass against a brute-force sum (self included) */
  double ksum_err = 0.0;
  for (size_t a = 0; a < n; a++) {
    double want_s = 0.0;
    for (size_t b = 0; b < n; b++) {
      const double dx = min_image(P->x[a] - P->x[b], lx), dy = P->y[a] - P->y[b];
      const double dz = s.dim == 3 ? min_image(P->z[a] - P->z[b], lz) : P->z[a] - P->z[b];
      want_s += P->m[b] * kernel_w(&K, sqrt(dx * dx + dy * dy + dz * dz));
    }
    const double e = fabs(ksum[a] - want_s) / want_s;
    if (e > ksum_err) ksum_err = e;
  }
  free(ksum);
  printf("%s: kernel sums against brute force: max rel error %.3e (tol 1e-13)\n", name, ksum_err);
  if (!(ksum_err <= 1e-13)) fails++;

  /* --- neighbour sets against brute force */
  size_t max_nbr = 0, total = 0, ambiguous = 0, set_bad = 0;
  int64_t *got = malloc(n * sizeof *got), *want = malloc(n * sizeof *want);
  for (size_t a = 0; a < n && set_bad < 10; a++) {
    size_t ng = 0, nw = 0;
    if (nb->count[a] < 0 || nb->count[a] > nb->stride) {
      printf("FAIL: %s: count[%zu] = %d, stride %d\n", name, a, nb->count[a], nb->stride);
      set_bad++;
      continue;
    }
    for (int k = 0; k < nb->count[a]; k++) {
      const int32_t b = nb->list[a * (size_t)nb->stride + k];
      if (b < 0 || (size_t)b >= n || (size_t)b == a) {
        printf("FAIL: %s: particle %zu lists invalid neighbour %d\n", name, a, (int)b);
        set_bad++;
        continue;
      }
      got[ng++] = P->id[b];
    }
    for (size_t b = 0; b < n; b++) {
      if (b == a) continue;
      const double dx = min_image(P->x[a] - P->x[b], lx), dy = P->y[a] - P->y[b];
      const double dz = s.dim == 3 ? min_image(P->z[a] - P->z[b], lz) : P->z[a] - P->z[b];
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (fabs(r2 - support2) <= 1e-12 * support2) {
        /* within rounding of the support radius: either answer is right; drop it from both */
        ambiguous++;
        for (size_t k = 0; k < ng; k++)
          if (got[k] == P->id[b]) got[k] = got[--ng];
        continue;
      }
      if (r2 < support2) want[nw++] = P->id[b];
    }
    qsort(got, ng, sizeof *got, cmp_i64);
    qsort(want, nw, sizeof *want, cmp_i64);
    int same = ng == nw;
    for (size_t k = 0; same && k < ng; k++) same = got[k] == want[k];
    if (!same) {
      printf(
          "FAIL: %s: particle id %lld at (%g, %g, %g): %zu neighbours listed, %zu by brute "
          "force\n",
          name, (long long)P->id[a], P->x[a], P->y[a], P->z[a], ng, nw);
      set_bad++;
    }
    if (nw > max_nbr) max_nbr = nw;
    total += nw;
  }
  free(got), free(want);
  if (set_bad) fails++;

  /* --- determinism and list growth: same lists, in the same order */
  const int stride0 = nb->stride;
  int32_t *list0 = malloc(n * (size_t)stride0 * sizeof *list0);
  int *count0 = malloc(n * sizeof *count0);
  memcpy(list0, nb->list, n * (size_t)stride0 * sizeof *list0);
  memcpy(count0, nb->count, n * sizeof *count0);
  const int threads = omp_get_max_threads();
  size_t repeat_bad = 0;
  /* variants: 1 thread; a stride too small; the other candidate scan (portable instead of
     AVX-512, where the processor has AVX-512): the same lists, the kernel sums to rounding */
  double *ks0 = calloc(n, sizeof *ks0);
  nbr_build(nb, P, &K, ks0);
  const int avx512 = nb->avx512;
  double scan_err = 0.0;
  for (int variant = 0; variant < 3; variant++) {
    if (variant == 0)
      omp_set_num_threads(1);
    else if (variant == 1)
      nb->stride = 3; /* smaller than the allocation: nbr_build must detect and grow */
    else if (avx512)
      nb->avx512 = 0;
    else
      break;
    double *ks = calloc(n, sizeof *ks);
    nbr_build(nb, P, &K, ks);
    if (variant == 2)
      for (size_t a = 0; a < n; a++) scan_err = fmax(scan_err, fabs(ks[a] / ks0[a] - 1.0));
    free(ks);
    nb->avx512 = avx512;
    omp_set_num_threads(threads);
    if (variant == 1 && nb->stride < (int)max_nbr) repeat_bad++;
    for (size_t a = 0; a < n; a++) {
      if (nb->count[a] != count0[a]) {
        repeat_bad++;
        continue;
      }
      for (int k = 0; k < count0[a]; k++)
        if (nb->list[a * (size_t)nb->stride + k] != list0[a * (size_t)stride0 + k]) repeat_bad++;
    }
  }
  const int grown_stride = nb->stride;
  free(list0), free(count0), free(ks0);
  if (repeat_bad) {
    printf(
        "FAIL: %s: %zu differences with 1 thread, after growing the list or with the other "
        "scan\n",
        name, repeat_bad);
    fails++;
  }
  if (!(scan_err <= 1e-14)) {
    printf("FAIL: %s: kernel sums of the two scans differ by %.3e (tol 1e-14)\n", name, scan_err);
    fails++;
  }
  printf("%s: %s; kernel sums of the portable scan against it: max rel difference %.3e\n", name,
         avx512 ? "AVX-512 candidate scan" : "no AVX-512: portable scan only", scan_err);

  /* --- a second sort of sorted particles changes nothing */
  int64_t *ids = malloc(n * sizeof *ids);
  memcpy(ids, P->id, n * sizeof *ids);
  nbr_sort(nb, P);
  size_t resort_bad = 0;
  for (size_t i = 0; i < n; i++) resort_bad += P->id[i] != ids[i];
  free(ids);
  if (resort_bad) {
    printf("FAIL: %s: a second nbr_sort moved %zu particles\n", name, resort_bad);
    fails++;
  }

  printf(
      "nbr %s: n = %zu (%zu fluid), cells %dx%dx%d (size/2h %.6f %.6f %.6f), "
      "neighbours mean %.2f max %zu, stride %d -> %d after forced growth\n",
      name, n, P->n_fluid, nb->nx, nb->ny, nb->nz, lx / nb->nx / (2.0 * h), ly / nb->ny / (2.0 * h),
      s.dim == 3 ? lz / nb->nz / (2.0 * h) : 0.0, (double)total / (double)n, max_nbr, stride0,
      grown_stride);
  printf(
      "nbr %s: neighbour-set mismatches %zu, order errors %zu, unmoved values %zu, "
      "max wrap error %.3e, x at l: %zu, pairs within 1e-12 of 2h: %zu, %s\n",
      name, set_bad, order_bad, pos_bad + arr_bad, max_shift_err, at_l, ambiguous,
      fails ? "FAILED" : "ok");

  for (int j = 0; j < N_FIELDS; j++) free(snap.d[j]);
  free(snap.kind);
  return fails;
}

/* Sort the particles of P with nt threads and keep the order of ids and the owned cells' start. */
static void sort_with(struct nbr *nb, struct particles *P, int nt, int64_t *id, size_t *start) {
  omp_set_num_threads(nt);
  nbr_sort(nb, P);
  memcpy(id, P->id, P->n * sizeof *id);
  memcpy(start, nb->start, (nb->ncell_own + 1) * sizeof *start);
}

/**
 * The threaded counting sort keeps the serial order: from the same state (displaced, then the
 * slots shuffled so that every thread's share spans the whole grid), sort with 1, 2, 3 and 7
 * threads; then swap 1% of the slots of the sorted state (a few out-of-place slots in
 * otherwise ordered shares) and sort again. The ids, start[] and the values moved with them
 * (u, ddiff) must be the same as with 1 thread. Returns the number of failures.
 */
static int check_threads(const char *name, int n_set, char **set) {
  struct scene s;
  if (scene_load(&s, NULL, n_set, set) != 0) return 1;
  const int threads[] = {1, 2, 3, 7}, saved = omp_get_max_threads();
  int64_t *ref[2] = {NULL, NULL};
  size_t *ref_start[2] = {NULL, NULL}, bad = 0, n = 0;
  for (int k = 0; k < 4; k++) {
    struct particles P;
    struct walls W;
    part_create(&P, &W, &s);
    n = P.n;
    lcg_state = 0x2545F4914F6CDD1DULL;
    for (size_t a = 0; a < n; a++) {
      P.u[a] = (double)a + 0.5, P.ddiff[a] = -(double)a;
      if (P.kind[a] != KIND_FLUID) continue;
      P.x[a] += 0.4 * s.dr * (2.0 * lcg_uniform() - 1.0);
      P.y[a] += 0.4 * s.dr * (2.0 * lcg_uniform() - 1.0);
      if (s.dim == 3) P.z[a] += 0.4 * s.dr * (2.0 * lcg_uniform() - 1.0);
    }
    size_t *perm = malloc(n * sizeof *perm);
    for (size_t a = 0; a < n; a++) perm[a] = a;
    for (size_t a = n - 1; a > 0; a--) { /* Fisher-Yates */
      const size_t b = (size_t)(lcg_uniform() * (double)(a + 1)), t = perm[a];
      perm[a] = perm[b], perm[b] = t;
    }
    part_permute(&P, 0, n, perm);
    struct nbr nb;
    {
      const struct nbr_range whole = nbr_whole(&s);
      nbr_init(&nb, &s, n, &whole);
    }
    for (int pass = 0; pass < 2; pass++) {
      int64_t *id = malloc(n * sizeof *id);
      size_t *start = malloc((nb.ncell_own + 1) * sizeof *start);
      if (pass == 1) { /* swap 1% of the sorted slots */
        for (size_t a = 0; a < n; a++) perm[a] = a;
        for (size_t i = 0; i < n / 100 + 1; i++) {
          const size_t a = (size_t)(lcg_uniform() * (double)n),
                       b = (size_t)(lcg_uniform() * (double)n);
          const size_t t = perm[a];
          perm[a] = perm[b], perm[b] = t;
        }
        part_permute(&P, 0, n, perm);
      }
      sort_with(&nb, &P, threads[k], id, start);
      for (size_t a = 0; a < n; a++)
        bad += P.u[a] != (double)P.id[a] + 0.5 || P.ddiff[a] != -(double)P.id[a];
      if (k == 0) {
        ref[pass] = id, ref_start[pass] = start;
        continue;
      }
      for (size_t a = 0; a < n; a++) bad += id[a] != ref[pass][a];
      for (size_t c = 0; c <= nb.ncell_own; c++) bad += start[c] != ref_start[pass][c];
      free(id), free(start);
    }
    free(perm);
    nbr_free(&nb);
    part_destroy(&P, &W);
  }
  omp_set_num_threads(saved);
  for (int pass = 0; pass < 2; pass++) free(ref[pass]), free(ref_start[pass]);
  printf("nbr %s: sort with 1, 2, 3, 7 threads (shuffled, then 1%% swapped): %zu differences, %s\n",
         name, bad, bad ? "FAILED" : "ok");
  return bad != 0;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int fails = 0;
  char *base2[] = {"domain.dimension=2", "domain.lx=1.0", "domain.dr=0.05",
                   "fluid.nu=0.1",       "fluid.c0=10",   "time.t_end=1"};
  fails += run_case("2-D lx=1", 6, base2);
  char *narrow2[] = {"domain.dimension=2", "domain.lx=0.4", "domain.dr=0.05", "domain.delta=0.1",
                     "fluid.nu=0.1",       "fluid.c0=10",   "time.t_end=1"};
  fails += run_case("2-D narrow (one cell in y)", 7, narrow2);
  char *base3[] = {"domain.dimension=3", "domain.lx=0.4", "domain.lz=0.4", "domain.dr=0.05",
                   "fluid.nu=0.1",       "fluid.c0=10",   "time.t_end=1"};
  fails += run_case("3-D 8x19x8", 7, base3);
  char *wide3[] = {"domain.dimension=3", "domain.lx=0.6",    "domain.lz=0.5",
                   "domain.dr=0.05",     "domain.delta=0.4", "sph.h_over_dr=1.6",
                   "fluid.nu=0.1",       "fluid.c0=10",      "time.t_end=1"};
  fails += run_case("3-D h=1.6dr", 9, wide3);
  fails += check_threads("3-D h=1.6dr", 9, wide3);
  printf("%s\n", fails ? "test_nbr: FAILED" : "test_nbr: passed");
  MPI_Finalize();
  return fails != 0;
}
