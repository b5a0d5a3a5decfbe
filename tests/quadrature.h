/**
 * @file quadrature.h
 * @brief Gauss-Legendre nodes and weights for the reference quadratures of the unit tests.
 */
#ifndef CHANSPH_TEST_QUADRATURE_H
#define CHANSPH_TEST_QUADRATURE_H

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/** Legendre polynomial P_n(z) and its derivative, by the three-term recurrence. */
static inline double legendre(int n, double z, double *dp) {
  double p0 = 1.0, p1 = z;
  for (int k = 2; k <= n; k++) {
    const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
    p0 = p1, p1 = p2;
  }
  *dp = n * (z * p1 - p0) / (z * z - 1.0);
  return p1;
}

/** Gauss-Legendre nodes x and weights w on [-1, 1], by Newton iteration on P_n. */
static inline void gauss_legendre(int n, double *x, double *w) {
  for (int i = 0; i < n; i++) {
    double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp;
    for (int it = 0; it < 100; it++) {
      const double dz = legendre(n, z, &dp) / dp;
      z -= dz;
      if (fabs(dz) < 1e-16) break;
    }
    legendre(n, z, &dp); /* the derivative at the converged root */
    x[i] = z, w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

#endif
