/*
 * test_reduce.c: unit test of the deterministic blocked sums of solver/reduce.h, reduce.c.
 *
 * Checks:
 *  - reduce_sum of 1e6 values spanning 16 decades, both signs (fixed-seed LCG), is bitwise
 *    identical with 1, 2 and 3 OpenMP threads (and 4, 7), and within 1e-13 relative of a
 *    long-double Kahan sum;
 *  - the same for lengths around the block size REDUCE_BLOCK (0, 1, B - 1, B, B + 1, 3B + 5)
 *    and for 1e6 + 1 values;
 *  - reduce_sums of several arrays at once equals reduce_sum of each, bitwise.
 */
#include <math.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reduce.h"

/** Minimal fixed-seed LCG in [0, 1). */
static unsigned long long lcg_state = 0xD1B54A32D192ED03ULL;
static double lcg_uniform(void) {
  lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
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

/** Checks reduce_sum(x, n) for determinism and accuracy; returns the number of failures. */
static int check(const char *what, const double *x, size_t n, double *max_rel) {
  const int nt[] = {1, 2, 3, 4, 7};
  double s[5];
  for (int i = 0; i < 5; i++) {
    omp_set_num_threads(nt[i]);
    s[i] = reduce_sum(x, n);
  }
  int fails = 0;
  for (int i = 1; i < 5; i++)
    if (memcmp(&s[i], &s[0], sizeof s[0]) != 0) {
      printf("FAIL: %s: %d threads give %.17g, 1 thread %.17g\n", what, nt[i], s[i], s[0]);
      fails++;
    }
  const long double ref = kahan(x, n);
  const double rel =
      ref != 0.0L ? (double)(fabsl((long double)s[0] - ref) / fabsl(ref)) : fabs(s[0]);
  if (rel > *max_rel) *max_rel = rel;
  if (!(rel <= 1e-13)) {
    printf("FAIL: %s: sum %.17g, Kahan %.17Lg, rel %.3e\n", what, s[0], ref, rel);
    fails++;
  }
  printf(
      "reduce %s: n = %zu, sum %.17g, rel error vs long-double Kahan %.3e, bitwise equal for "
      "1, 2, 3, 4, 7 threads: %s\n",
      what, n, s[0], rel, fails ? "NO" : "yes");
  return fails;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const int threads = omp_get_max_threads();
  const size_t n = 1000001;
  double *x = malloc(n * sizeof *x);
  /* magnitudes 10^-8 .. 10^8, about 30 % negative: sum |x| / |sum x| ~ 1.5 */
  for (size_t i = 0; i < n; i++)
    x[i] = (lcg_uniform() - 0.3) * pow(10.0, 16.0 * lcg_uniform() - 8.0);
  int fails = 0;
  double max_rel = 0.0;
  fails += check("1e6 values, 16 decades", x, 1000000, &max_rel);
  fails += check("1e6 + 1 values", x, n, &max_rel);

  /* positive values only, the dynamic range ordered against the summation (large first) */
  double *y = malloc(n * sizeof *y);
  for (size_t i = 0; i < n; i++) y[i] = pow(10.0, 8.0 - 16.0 * (double)i / (double)n);
  fails += check("1e6 decreasing positive", y, 1000000, &max_rel);

  const size_t b = REDUCE_BLOCK, lens[] = {0, 1, b - 1, b, b + 1, 3 * b + 5};
  for (size_t i = 0; i < sizeof lens / sizeof lens[0]; i++) {
    char what[64];
    snprintf(what, sizeof what, "length %zu", lens[i]);
    fails += check(what, x + 17, lens[i], &max_rel);
  }
  omp_set_num_threads(threads);
  if (reduce_sum(x, 0) != 0.0) {
    printf("FAIL: empty sum is %.17g\n", reduce_sum(x, 0));
    fails++;
  }

  /* several arrays at once */
  const double *arrs[3] = {x, y, x + 1};
  double out[3];
  reduce_sums(3, arrs, 1000000, out);
  for (int v = 0; v < 3; v++) {
    const double one = reduce_sum(arrs[v], 1000000);
    if (memcmp(&one, &out[v], sizeof one) != 0) {
      printf("FAIL: reduce_sums[%d] = %.17g, reduce_sum = %.17g\n", v, out[v], one);
      fails++;
    }
  }

  printf("reduce: max rel error vs long-double Kahan %.3e (tol 1e-13)\n", max_rel);
  printf("%s\n", fails ? "test_reduce: FAILED" : "test_reduce: passed");
  free(x), free(y);
  MPI_Finalize();
  return fails != 0;
}
