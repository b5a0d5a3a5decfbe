/**
 * @file moments.h
 * @brief Streaming moments of one wall-normal bin: count, means, co-moments (covariances
 *        times count) and third and fourth central moments, updated one sample at a time and
 *        merged pairwise (Chan, Golub & LeVeque 1979; Pebay 2008). Everything in double.
 *
 * A record is a flat array of MOM_LEN doubles, so that windows of records are plain arrays
 * that go into the run state (checkpoints) and into stats.nc without conversion.
 * The merge of two records is exact in exact arithmetic and, with the order fixed, bitwise
 * reproducible; a one-sample update is the merge with a record of count 1 (Welford).
 */
#ifndef CHANSPH_MOMENTS_H
#define CHANSPH_MOMENTS_H

/** Quantities averaged per bin (the order of the mean slots); eddy viscosity and residual
    kinetic energy are zero without LES. */
enum { MOM_U, MOM_V, MOM_W, MOM_P, MOM_RHO, MOM_Y, MOM_NUT, MOM_KR, MOM_NQ };
/** Co-moment slots: uu vv ww uv uw vw. */
enum { MOM_UU, MOM_VV, MOM_WW, MOM_UV, MOM_UW, MOM_VW, MOM_NC };
/** Layout of a record: [count | means[8] | co-moments[6] | M3 of u,v,w | M4 of u,v,w |
    co-moments of u, v, w with the position y | C2 of y]. The last four (checkpoint format
    1.12) let the stresses be taken about the local mean U(y) = U_b + dU/dy (y - y_b) instead
    of the bin mean U_b (euler_finalise); records of earlier formats are MOM_LEN_1_11 long and
    are widened with NaN there (no local mean for the bins and ranges that include them). */
enum {
  MOM_N = 0,
  MOM_MEAN = 1,
  MOM_C2 = MOM_MEAN + MOM_NQ,
  MOM_M3 = MOM_C2 + MOM_NC,
  MOM_M4 = MOM_M3 + 3,
  MOM_CY = MOM_M4 + 3,
  MOM_CYY = MOM_CY + 3,
  MOM_LEN = MOM_CYY + 1,
  MOM_LEN_1_11 = MOM_CY
};

/** Velocity indices of the six co-moments. */
static const int mom_pair[MOM_NC][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};

/**
 * @brief Merge record b into record a (a := a + b). Implements: the moments of the Eulerian
 *        statistics (thesis Sec. 5.2.3.1) with the pairwise update of Pebay (2008).
 *        Pairwise update of the mean, co-moments, M3 and M4 (Pebay 2008, Eq. 1.1-1.4 with
 *        delta = mean_b - mean_a); b empty leaves a bitwise unchanged.
 * @param[in,out] a record
 * @param[in] b record
 */
static inline void mom_merge(double *restrict a, const double *restrict b) {
  const double na = a[MOM_N], nb = b[MOM_N];
  if (nb == 0.0) return;
  if (na == 0.0) {
    for (int k = 0; k < MOM_LEN; k++) a[k] = b[k];
    return;
  }
  const double n = na + nb, f = na * nb / n;
  double d[MOM_NQ];
  for (int q = 0; q < MOM_NQ; q++) d[q] = b[MOM_MEAN + q] - a[MOM_MEAN + q];
  for (int i = 0; i < 3; i++) { /* M4 and M3 first: they use the old M2 and M3 */
    const double di = d[i], m2a = a[MOM_C2 + i], m2b = b[MOM_C2 + i];
    const double m3a = a[MOM_M3 + i], m3b = b[MOM_M3 + i];
    a[MOM_M4 + i] += b[MOM_M4 + i] +
                     di * di * di * di * f * (na * na - na * nb + nb * nb) / (n * n) +
                     6.0 * di * di * (na * na * m2b + nb * nb * m2a) / (n * n) +
                     4.0 * di * (na * m3b - nb * m3a) / n;
    a[MOM_M3 + i] += m3b + di * di * di * f * (na - nb) / n + 3.0 * di * (na * m2b - nb * m2a) / n;
  }
  for (int c = 0; c < MOM_NC; c++)
    a[MOM_C2 + c] += b[MOM_C2 + c] + d[mom_pair[c][0]] * d[mom_pair[c][1]] * f;
  for (int i = 0; i < 3; i++) a[MOM_CY + i] += b[MOM_CY + i] + d[i] * d[MOM_Y] * f;
  a[MOM_CYY] += b[MOM_CYY] + d[MOM_Y] * d[MOM_Y] * f;
  for (int q = 0; q < MOM_NQ; q++) a[MOM_MEAN + q] += d[q] * nb / n;
  a[MOM_N] = n;
}

/**
 * @brief Add one sample (u, v, w, p, rho, y, nu_t, k_r) to a record: the merge with a one-sample
 *        record, written out (Welford's update with the higher moments of Pebay 2008).
 * @param[in,out] a record
 * @param[in] s the sample, MOM_NQ values in slot order
 */
static inline void mom_add(double *restrict a, const double *restrict s) {
  const double na = a[MOM_N], n = na + 1.0, f = na / n;
  double d[MOM_NQ];
  for (int q = 0; q < MOM_NQ; q++) d[q] = s[q] - a[MOM_MEAN + q];
  for (int i = 0; i < 3; i++) {
    const double di = d[i], m2a = a[MOM_C2 + i], m3a = a[MOM_M3 + i];
    a[MOM_M4 + i] += di * di * di * di * f * (na * na - na + 1.0) / (n * n) +
                     6.0 * di * di * m2a / (n * n) - 4.0 * di * m3a / n;
    a[MOM_M3 + i] += di * di * di * f * (na - 1.0) / n - 3.0 * di * m2a / n;
  }
  for (int c = 0; c < MOM_NC; c++) a[MOM_C2 + c] += d[mom_pair[c][0]] * d[mom_pair[c][1]] * f;
  for (int i = 0; i < 3; i++) a[MOM_CY + i] += d[i] * d[MOM_Y] * f;
  a[MOM_CYY] += d[MOM_Y] * d[MOM_Y] * f;
  for (int q = 0; q < MOM_NQ; q++) a[MOM_MEAN + q] += d[q] / n;
  a[MOM_N] = n;
}

/** Streaming mean and M2 of one scalar: [count, mean, M2] (Welford). */
enum { SCAL_N, SCAL_MEAN, SCAL_M2, SCAL_LEN };

/** @brief Add a sample x to a scalar record [count, mean, M2] (Welford). */
static inline void scal_add(double *restrict a, double x) {
  const double n = a[SCAL_N] + 1.0, d = x - a[SCAL_MEAN];
  a[SCAL_MEAN] += d / n;
  a[SCAL_M2] += d * (x - a[SCAL_MEAN]);
  a[SCAL_N] = n;
}

/**
 * @brief Merge scalar record b into record a (a := a + b), the pairwise update of Chan, Golub
 *        & LeVeque (1979): n = na + nb, delta = mean_b - mean_a, mean = mean_a + delta nb / n,
 *        M2 = M2a + M2b + delta^2 na nb / n. Exact in exact arithmetic (the batches of two
 *        segments pooled, chansph extract); b empty leaves a bitwise unchanged, a empty
 *        becomes b.
 */
static inline void scal_merge(double *restrict a, const double *restrict b) {
  const double na = a[SCAL_N], nb = b[SCAL_N];
  if (nb == 0.0) return;
  if (na == 0.0) {
    for (int k = 0; k < SCAL_LEN; k++) a[k] = b[k];
    return;
  }
  const double n = na + nb, d = b[SCAL_MEAN] - a[SCAL_MEAN];
  a[SCAL_M2] += b[SCAL_M2] + d * d * na * nb / n;
  a[SCAL_MEAN] += d * nb / n;
  a[SCAL_N] = n;
}

#endif
