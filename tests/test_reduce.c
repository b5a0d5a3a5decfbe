/*
 * test_reduce.c: unit test of the deterministic sums: reduce_pairwise (solver/reduce.h) and the
 * per-pencil global sums dd_sum (solver/dd.h) over the particles of a 3-D channel lattice.
 *
 * Checks:
 *  - reduce_pairwise of 1e6 values spanning 16 decades, both signs (fixed-seed LCG), is within
 *    1e-13 relative of a long-double Kahan sum, for lengths 0, 1, 7, 8, 9, 1e6 and 1e6 + 1;
 *  - dd_sum of three per-particle arrays (values spanning 16 decades) over 131 200 particles is
 *    bitwise identical with 1, 2, 3, 4 and 7 OpenMP threads, after the particles are shuffled
 *    and sorted again, and within 1e-13 relative of the Kahan sum;
 *  - dd_sum of several arrays at once equals dd_sum of each, bitwise.
 */
#include <math.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dd.h"
#include "nbr.h"
#include "part.h"
#include "reduce.h"
#include "scene.h"

/** Minimal fixed-seed LCG in [0, 1). */
static unsigned long long lcg_state = 0xD1B54A32D192ED03ULL;
static double lcg_uniform(void) {
  lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

/** A value of magnitude 10^-8 .. 10^8, about 30 % negative. */
static double wide(void) {
  return (lcg_uniform() - 0.3) * pow(10.0, 16.0 * lcg_uniform() - 8.0);
}

/** Kahan-compensated sum in long double. */
static long double kahan(const double *x, size_t n) {
  long double s = 0.0L, c = 0.0L;
  for (size_t i = 0; i < n; i++) {
    const long double y = (long double)x[i] - c, t = s + y;
    c = (t - s) - y;
    s = t;
  }
  return s;
}

static double rel_error(double s, long double ref) {
  return ref != 0.0L ? (double)(fabsl((long double)s - ref) / fabsl(ref)) : fabs(s);
}

static int check_pairwise(const double *x, size_t n, double *max_rel) {
  const double s = reduce_pairwise(x, n);
  const double rel = rel_error(s, kahan(x, n));
  if (rel > *max_rel) *max_rel = rel;
  printf("reduce_pairwise: n = %zu, sum %.17g, rel error vs long-double Kahan %.3e\n", n, s, rel);
  if (!(rel <= 1e-13)) {
    printf("FAIL: reduce_pairwise of %zu values: rel error %.3e\n", n, rel);
    return 1;
  }
  return 0;
}

static void noop_reserve(void *ctx, size_t n) {
  (void)ctx, (void)n;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const int threads = omp_get_max_threads();
  int fails = 0;
  double max_rel = 0.0;

  const size_t n = 1000001;
  double *x = malloc(n * sizeof *x);
  for (size_t i = 0; i < n; i++) x[i] = wide();
  const size_t lens[] = {0, 1, 7, 8, 9, 1000000, 1000001};
  for (size_t i = 0; i < sizeof lens / sizeof lens[0]; i++)
    fails += check_pairwise(x, lens[i], &max_rel);

  /* a 3-D channel lattice, 80 x 39 x 40 fluid + vertices, one rank */
  char *set[] = {"domain.dimension=3", "domain.lx=2.0", "domain.delta=0.5", "domain.lz=1.0",
                 "domain.dr=0.025",    "fluid.nu=0.1",  "fluid.c0=10",      "time.t_end=1"};
  struct scene sc;
  if (scene_load(&sc, NULL, sizeof set / sizeof set[0], set)) return 1;
  struct particles P;
  struct walls W;
  part_create(&P, &W, &sc);
  struct dd d;
  if (dd_init(&d, &sc, noop_reserve, NULL)) return 1;
  struct nbr nb;
  const struct nbr_range range = dd_range(&d);
  nbr_init(&nb, &sc, P.n, &range);
  /* three fields of wide values, then a shuffle of positions (by id) and a re-sort */
  double *f[3];
  for (int k = 0; k < 3; k++) {
    f[k] = malloc(P.n * sizeof(double));
    for (size_t a = 0; a < P.n; a++) f[k][a] = wide();
  }
  for (size_t a = 0; a < P.n; a++) P.u[a] = f[0][a], P.v[a] = f[1][a], P.w[a] = f[2][a];
  for (size_t a = 0; a < P.n; a++) { /* move some particles by up to a cell */
    P.x[a] += (lcg_uniform() - 0.5) * 0.05;
    if (P.kind[a] == KIND_FLUID) P.z[a] += (lcg_uniform() - 0.5) * 0.05;
  }
  nbr_sort(&nb, &P);
  const double *arrs[3] = {P.u, P.v, P.w};
  const int nt[] = {1, 2, 3, 4, 7};
  double s[5][3];
  for (int i = 0; i < 5; i++) {
    omp_set_num_threads(nt[i]);
    dd_sum(&d, &nb, 3, arrs, s[i]);
  }
  omp_set_num_threads(threads);
  for (int i = 1; i < 5; i++)
    if (memcmp(s[i], s[0], sizeof s[0]) != 0) {
      printf("FAIL: dd_sum with %d threads differs from 1 thread\n", nt[i]);
      fails++;
    }
  for (int k = 0; k < 3; k++) {
    const double rel = rel_error(s[0][k], kahan(f[k], P.n));
    if (rel > max_rel) max_rel = rel;
    printf(
        "dd_sum field %d: %zu particles in %d columns, sum %.17g, rel error vs Kahan %.3e, "
        "bitwise equal for 1, 2, 3, 4, 7 threads: %s\n",
        k, P.n, d.ncol, s[0][k], rel, fails ? "NO" : "yes");
    if (!(rel <= 1e-13)) {
      printf("FAIL: dd_sum field %d: rel error %.3e\n", k, rel);
      fails++;
    }
    double one;
    dd_sum(&d, &nb, 1, &arrs[k], &one);
    if (memcmp(&one, &s[0][k], sizeof one) != 0) {
      printf("FAIL: dd_sum of field %d alone differs from the 3-array sum\n", k);
      fails++;
    }
  }
  printf("reduce: max rel error vs long-double Kahan %.3e (tol 1e-13)\n", max_rel);
  printf("%s\n", fails ? "test_reduce: FAILED" : "test_reduce: passed");
  for (int k = 0; k < 3; k++) free(f[k]);
  nbr_free(&nb), dd_free(&d), part_destroy(&P, &W), free(x);
  MPI_Finalize();
  return fails != 0;
}
