/**
 * @file kernel.h
 * @brief Wendland (quintic, C2) kernel. Implements: thesis Eq. 2.63-2.66.
 *
 * w(r, h) = alpha_m / h^m (1 - q/2)^4 (1 + 2q) for q = r/h <= 2, support radius 2h.
 * The gradient is written as grad_a w_ab = F(r) r_ab with F = w'(r)/r = -5 alpha_m / h^(m+2)
 * (1 - q/2)^3, which has no 1/r singularity.
 */
#ifndef CHANSPH_KERNEL_H
#define CHANSPH_KERNEL_H

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/** Precomputed kernel constants for one smoothing length and dimension. */
struct kernel {
  int dim;         /*!< 1, 2 or 3 */
  double h;        /*!< smoothing length [m] */
  double inv_h;    /*!< 1/h [1/m] */
  double wfac;     /*!< alpha_m / h^m [1/m^m] */
  double ffac;     /*!< -5 alpha_m / h^(m+2) [1/m^(m+2)] */
  double support2; /*!< (2h)^2 [m^2] */
};

/**
 * @brief Normalisation constant alpha_m of the Wendland kernel.
 * @param[in] dim dimension 1, 2 or 3
 * @return alpha_m. Implements: thesis Eq. 2.64-2.66.
 */
static inline double kernel_alpha(const int dim) {
  return dim == 1 ? 0.75 : dim == 2 ? 7.0 / (4.0 * M_PI) : 21.0 / (16.0 * M_PI);
}

/**
 * @brief Set up the kernel constants.
 * @param[in] dim dimension
 * @param[in] h smoothing length [m]
 * @return the kernel constants
 */
static inline struct kernel kernel_make(const int dim, const double h) {
  const double a = kernel_alpha(dim);
  struct kernel k = {dim, h, 1.0 / h, a / pow(h, dim), -5.0 * a / pow(h, dim + 2), 4.0 * h * h};
  return k;
}

/**
 * @brief Kernel value w(r, h).
 * @param[in] k kernel constants
 * @param[in] r distance [m]
 * @return w [1/m^dim]. Implements: thesis Eq. 2.63.
 */
static inline double kernel_w(const struct kernel *k, const double r) {
  const double q = r * k->inv_h;
  if (q >= 2.0) return 0.0;
  const double t = 1.0 - 0.5 * q;
  const double t2 = t * t;
  return k->wfac * t2 * t2 * (1.0 + 2.0 * q);
}

/**
 * @brief Gradient factor F(r) = w'(r)/r, so that grad_a w_ab = F r_ab.
 * @param[in] k kernel constants
 * @param[in] r distance [m]
 * @return F [1/m^(dim+2)], negative inside the support.
 */
static inline double kernel_f(const struct kernel *k, const double r) {
  const double q = r * k->inv_h;
  if (q >= 2.0) return 0.0;
  const double t = 1.0 - 0.5 * q;
  return k->ffac * t * t * t;
}

#endif
