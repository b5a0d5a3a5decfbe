/**
 * @file wall.h
 * @brief Renormalisation gamma and its gradient for a plane wall (line wall in 2-D), closed form.
 *
 * For a particle at distance d = q h from an infinite plane wall, with the Wendland C2 kernel
 * (the C4 forms and the *_of functions that pick the model's kernel follow below):
 * - 3-D: gamma(q) = 1 - (2 - q)^6 (4 + 6q + 3q^2) / 512 and |grad gamma| = I_full(q) / h with
 *   I_full(q) = 3/8 (2 + 5q + 4q^2)(1 - q/2)^5 (thesis Eq. 4.9-4.11, alpha_3 = 21/(16 pi)).
 * - 2-D (derived for chansph, see docs/theory.md; checked against Ferrand Eq. 51-52 summed over
 *   segments and against quadrature in tests/test_wall.c), with S = sqrt(4 - q^2) and
 *   L = ln((2 + S)/q):
 *     |grad gamma| h = 7/(768 pi) [(15 q^6 + 360 q^4) L + (128 - 224 q^2 - 162 q^4) S]
 *     (for q > 1.5 the terms cancel to O((2-q)^4.5), so the same integral is evaluated there
 *     by 12-point Gauss-Legendre along the line, accurate to ~1e-14 relative)
 *     gamma = 1/2 + [(15 q^7 + 504 q^5) L + (704 q - 480 q^3 - 194 q^5) S + 768 asin(q/2)]
 *             / (768 pi)
 * grad gamma points into the fluid (the inward wall normal), gamma = 1 for q >= 2.
 */
#ifndef CHANSPH_WALL_H
#define CHANSPH_WALL_H

#include <math.h>

#include "kernel.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/**
 * @brief gamma of a plane wall at normalised distance q = d/h.
 * @param[in] dim 2 or 3
 * @param[in] q distance over h, q >= 0
 * @return gamma in [1/2, 1]. Implements: thesis Eq. 4.10 (3-D), its 2-D analogue.
 */
static inline double wall_gamma(const int dim, const double q) {
  if (q >= 2.0) return 1.0;
  if (dim == 3) {
    const double t = 2.0 - q, t2 = t * t;
    return 1.0 - t2 * t2 * t2 * (4.0 + 6.0 * q + 3.0 * q * q) / 512.0;
  }
  if (q <= 0.0) return 0.5;
  const double q2 = q * q, q4 = q2 * q2;
  const double s = sqrt(4.0 - q2), l = log((2.0 + s) / q);
  return 0.5 + ((15.0 * q2 + 504.0) * q4 * q * l + (704.0 - 480.0 * q2 - 194.0 * q4) * q * s +
                768.0 * asin(0.5 * q)) /
                   (768.0 * M_PI);
}

/** 12-point Gauss-Legendre nodes and weights on [0, 1]. */
static const double wall_gl12_t[12] = {
    0.009219682876640378, 0.0479413718147626,  0.11504866290284765, 0.20634102285669126,
    0.31608425050090994,  0.43738329574426554, 0.5626167042557344,  0.6839157494990901,
    0.7936589771433087,   0.8849513370971523,  0.9520586281852375,  0.9907803171233596};
static const double wall_gl12_w[12] = {
    0.02358766819325601, 0.05346966299765944, 0.08003916427167306, 0.10158371336153282,
    0.11674626826917732, 0.12457352290670134, 0.12457352290670134, 0.11674626826917732,
    0.10158371336153282, 0.08003916427167306, 0.05346966299765944, 0.02358766819325601};

/**
 * @brief |grad gamma| of a plane wall times h, at normalised distance q = d/h.
 * @param[in] dim 2 or 3
 * @param[in] q distance over h, q >= 0
 * @return h |grad gamma| (multiply by 1/h for [1/m]). Implements: thesis Eq. 4.9, 4.11 (3-D),
 *         Ferrand Eq. 51 over an infinite line (2-D).
 */
static inline double wall_dgamma(const int dim, const double q) {
  if (q >= 2.0) return 0.0;
  if (dim == 3) {
    const double t = 1.0 - 0.5 * q, t2 = t * t;
    return 0.375 * (2.0 + 5.0 * q + 4.0 * q * q) * t2 * t2 * t;
  }
  const double q2 = q * q, q4 = q2 * q2;
  const double s = sqrt(4.0 - q2);
  if (q > 1.5) { /* the closed form cancels to (2 - q)^4.5 here: integrate along the line */
    const double *t = wall_gl12_t, *wt = wall_gl12_w;
    double sum = 0.0;
    for (int i = 0; i < 12; i++) { /* 12-point Gauss-Legendre on [0, s], exact to ~1e-14 */
      const double r = sqrt(q2 + s * s * t[i] * t[i]), u = 1.0 - 0.5 * r, u2 = u * u;
      sum += wt[i] * u2 * u2 * (1.0 + 2.0 * r);
    }
    return 2.0 * s * 7.0 / (4.0 * M_PI) * sum;
  }
  const double lterm = q > 0.0 ? (15.0 * q2 + 360.0) * q4 * log((2.0 + s) / q) : 0.0;
  return 7.0 / (768.0 * M_PI) * (lterm + (128.0 - 224.0 * q2 - 162.0 * q4) * s);
}

/**
 * @brief Second moment of the kernel gradient over the half-space behind a plane wall:
 *        M(q) = int_{behind} r_ab . grad_a w_ab dV, dimensionless; M(0) = -dim/2, M(2) = 0.
 *
 * The full-space value is -dim (integration by parts), so the discrete sum over the particles
 * plus M of both walls estimates -dim; its deviation measures the lattice error of the
 * Laplacian (used by the Laplacian normalisation in sph.c, docs/theory.md).
 * 3-D: M = 3 (q - 2)^5 (5q^3 + 10q^2 + 12q + 8) / 512.
 * 2-D: M = -1 - [(75q^7 + 1512q^5) L - (746q^5 + 608q^3 + 512q) S - 1536 asin(q/2)] / (768 pi).
 */
static inline double wall_moment2(const int dim, const double q) {
  if (q >= 2.0) return 0.0;
  if (dim == 3) {
    const double t = q - 2.0, t2 = t * t;
    return 3.0 * t2 * t2 * t * (((5.0 * q + 10.0) * q + 12.0) * q + 8.0) / 512.0;
  }
  if (q <= 0.0) return -1.0;
  const double q2 = q * q, q4 = q2 * q2;
  const double s = sqrt(4.0 - q2), l = log((2.0 + s) / q);
  return -1.0 - ((75.0 * q2 + 1512.0) * q4 * q * l - (746.0 * q4 + 608.0 * q2 + 512.0) * q * s -
                 1536.0 * asin(0.5 * q)) /
                    (768.0 * M_PI);
}

/**
 * @brief Wall-normal second moment behind a plane wall: M_yy(q) = int_{behind} F r_y^2 dV with
 *        grad_a w_ab = F r_ab, dimensionless; the full-space value is -1, M_yy(0) = -1/2.
 *
 * 3-D: M_yy = (q - 2)^5 (21 q^3 + 30 q^2 + 20 q + 8) / 512.
 * 2-D: M_yy = [-(3/128) q^5 (5 q^2 + 112) L + q S (235 q^4 + 272 q^2 - 48) / 192
 *              + asin(q/2) - pi/2] / pi.
 */
static inline double wall_moment_yy(const int dim, const double q) {
  if (q >= 2.0) return 0.0;
  if (dim == 3) {
    const double t = q - 2.0, t2 = t * t;
    return t2 * t2 * t * (((21.0 * q + 30.0) * q + 20.0) * q + 8.0) / 512.0;
  }
  if (q <= 0.0) return -0.5;
  const double q2 = q * q, q4 = q2 * q2;
  const double s = sqrt(4.0 - q2), l = log((2.0 + s) / q);
  return (-3.0 / 128.0 * q4 * q * (5.0 * q2 + 112.0) * l +
          q * s * (235.0 * q4 + 272.0 * q2 - 48.0) / 192.0 + asin(0.5 * q) - 0.5 * M_PI) /
         M_PI;
}

/*
 * The Wendland C4 kernel (kernel.h), 3-D only (derived for chansph with a computer-algebra
 * integration of the same integrals; checked against quadrature in tests/test_wall.c):
 *   |grad gamma| h = 55/65536 (2 - q)^7 (3q + 2)(7q^2 + 8q + 4)
 *   gamma  = 1 - (2 - q)^8 (105 q^3 + 272 q^2 + 292 q + 128) / 65536 (1/2 at q = 0)
 *   M      = (q - 2)^7 (105 q^4 + 238 q^3 + 287 q^2 + 226 q + 96) / 8192
 *   M_yy   = (q - 2)^7 (525 q^4 + 1014 q^3 + 896 q^2 + 448 q + 128) / 32768
 */

/** gamma of a plane wall for the Wendland C4 kernel in 3-D. */
static inline double wall_gamma_c4(const double q) {
  if (q >= 2.0) return 1.0;
  const double t = 2.0 - q, t2 = t * t, t4 = t2 * t2;
  return 1.0 - t4 * t4 * (((105.0 * q + 272.0) * q + 292.0) * q + 128.0) / 65536.0;
}

/** h |grad gamma| of a plane wall for the Wendland C4 kernel in 3-D. */
static inline double wall_dgamma_c4(const double q) {
  if (q >= 2.0) return 0.0;
  const double t = 2.0 - q, t2 = t * t, t3 = t2 * t;
  return 55.0 / 65536.0 * t3 * t3 * t * (3.0 * q + 2.0) * ((7.0 * q + 8.0) * q + 4.0);
}

/** M(q) (wall_moment2) for the Wendland C4 kernel in 3-D; M(0) = -3/2. */
static inline double wall_moment2_c4(const double q) {
  if (q >= 2.0) return 0.0;
  const double t = q - 2.0, t2 = t * t, t3 = t2 * t;
  return t3 * t3 * t * ((((105.0 * q + 238.0) * q + 287.0) * q + 226.0) * q + 96.0) / 8192.0;
}

/** M_yy(q) (wall_moment_yy) for the Wendland C4 kernel in 3-D; M_yy(0) = -1/2. */
static inline double wall_moment_yy_c4(const double q) {
  if (q >= 2.0) return 0.0;
  const double t = q - 2.0, t2 = t * t, t3 = t2 * t;
  return t3 * t3 * t * ((((525.0 * q + 1014.0) * q + 896.0) * q + 448.0) * q + 128.0) / 32768.0;
}

/** The wall functions of the kernel K's shape and dimension (C4: 3-D only, sph.kernel). */
static inline double wall_gamma_of(const struct kernel *K, const double q) {
  return K->shape == KERNEL_C4 ? wall_gamma_c4(q) : wall_gamma(K->dim, q);
}
/** h |grad gamma| of the kernel K (wall_dgamma, wall_dgamma_c4). */
static inline double wall_dgamma_of(const struct kernel *K, const double q) {
  return K->shape == KERNEL_C4 ? wall_dgamma_c4(q) : wall_dgamma(K->dim, q);
}
/** M(q) of the kernel K (wall_moment2, wall_moment2_c4). */
static inline double wall_moment2_of(const struct kernel *K, const double q) {
  return K->shape == KERNEL_C4 ? wall_moment2_c4(q) : wall_moment2(K->dim, q);
}
/** M_yy(q) of the kernel K (wall_moment_yy, wall_moment_yy_c4). */
static inline double wall_moment_yy_of(const struct kernel *K, const double q) {
  return K->shape == KERNEL_C4 ? wall_moment_yy_c4(q) : wall_moment_yy(K->dim, q);
}

/**
 * @brief Ferrand's polynomial P_{q0}(X) of the 2-D segment integral. Implements: Ferrand Eq. 52
 *        (thesis Eq. 2.108 misprints the first coefficient as 7/129; 7/192 is right).
 */
static inline double wall_ferrand_p(const double q0, const double x) {
  const double x2 = x * x, x3 = x2 * x, q02 = q0 * q0;
  return 7.0 / 192.0 * x3 * x2 - 21.0 / 64.0 * x2 * x2 + 35.0 / 32.0 * x3 - 35.0 / 24.0 * x2 +
         7.0 / 4.0 + q02 * (35.0 / 768.0 * x3 - 7.0 / 16.0 * x2 + 105.0 / 64.0 * x - 35.0 / 12.0) +
         q02 * q02 * (35.0 / 512.0 * x - 7.0 / 8.0);
}

/**
 * @brief h times the integral of w along a 2-D segment, for a particle at normal distance q0 > 0.
 *
 * The segment runs from tangential coordinate s1 to s2 (normalised by h, measured from the foot
 * of the perpendicular); ends outside the support are clipped to it, so that q_i <= 2.
 * Implements: Ferrand Eq. 51 with q_i cos(alpha_i) the signed tangential distance of end i.
 */
static inline double wall_segment_2d(const double q0, double s1, double s2) {
  if (q0 >= 2.0) return 0.0;
  const double smax = sqrt(4.0 - q0 * q0);
  s1 = fmax(-smax, fmin(smax, s1));
  s2 = fmax(-smax, fmin(smax, s2));
  const double q1 = sqrt(q0 * q0 + s1 * s1), q2 = sqrt(q0 * q0 + s2 * s2);
  const double sg1 = s1 > 0 ? 1.0 : s1 < 0 ? -1.0 : 0.0, sg2 = s2 > 0 ? 1.0 : s2 < 0 ? -1.0 : 0.0;
  const double q04 = q0 * q0 * q0 * q0;
  return s2 / M_PI * wall_ferrand_p(q0, q2) - s1 / M_PI * wall_ferrand_p(q0, q1) +
         q04 / M_PI * (105.0 / 64.0 + 35.0 / 512.0 * q0 * q0) *
             (sg2 * log((q2 + fabs(s2)) / q0) - sg1 * log((q1 + fabs(s1)) / q0));
}

#endif
