/**
 * @file kernel.h
 * @brief Wendland kernels, support radius 2h, q = r/h (`sph.kernel`):
 *
 * - C2 (default; thesis Eq. 2.63-2.66): w = alpha_m / h^m (1 - q/2)^4 (1 + 2q),
 *   F = w'(r)/r = -5 alpha_m / h^(m+2) (1 - q/2)^3;
 * - C4 (Wendland 1995; Dehnen & Aly 2012, Table 1, with their support H = 2h):
 *   w = alpha_m / h^m (1 - q/2)^6 (1 + 3q + 35/12 q^2),
 *   F = -14/3 alpha_m / h^(m+2) (1 - q/2)^5 (1 + 5q/2), alpha_3 = 495/(256 pi),
 *   alpha_2 = 9/(4 pi).
 *
 * The gradient is written as grad_a w_ab = F(r) r_ab, which has no 1/r singularity. With
 * t = 1 - q/2 both shapes share the factors wfac t^4 of w and ffac t^3 of F; C4 multiplies them
 * by t^2 (1 + 3q + 35/12 q^2) / (1 + 2q) and t^2 (1 + 5q/2). kernel_w_of() and kernel_f_of()
 * take the shape as an argument, a compile-time constant in the specialised hot loops (pair.h);
 * kernel_w() and kernel_f() read it from the kernel.
 */
#ifndef CHANSPH_KERNEL_H
#define CHANSPH_KERNEL_H

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/** The kernel's shape (`sph.kernel`). */
enum kernel_shape { KERNEL_C2 = 0, KERNEL_C4 = 1 };

/** Precomputed kernel constants for one smoothing length, dimension and shape. */
struct kernel {
  int dim;         /*!< 1, 2 or 3 */
  double h;        /*!< smoothing length [m] */
  double inv_h;    /*!< 1/h [1/m] */
  double wfac;     /*!< alpha_m / h^m [1/m^m] */
  double ffac;     /*!< C2: -5 alpha_m / h^(m+2); C4: -14/3 alpha_m / h^(m+2) [1/m^(m+2)] */
  double support2; /*!< (2h)^2 [m^2] */
  int shape;       /*!< enum kernel_shape */
};

/**
 * @brief Normalisation constant alpha_m of a Wendland kernel of support 2h.
 * @param[in] dim dimension 1, 2 or 3 (C4: 2 or 3)
 * @param[in] shape enum kernel_shape
 * @return alpha_m. Implements: thesis Eq. 2.64-2.66 (C2); Dehnen & Aly (2012) Table 1 (C4).
 */
static inline double kernel_alpha_of(const int dim, const int shape) {
  if (shape == KERNEL_C4) return dim == 2 ? 9.0 / (4.0 * M_PI) : 495.0 / (256.0 * M_PI);
  return dim == 1 ? 0.75 : dim == 2 ? 7.0 / (4.0 * M_PI) : 21.0 / (16.0 * M_PI);
}

/** alpha_m of the Wendland C2 kernel (thesis Eq. 2.64-2.66). */
static inline double kernel_alpha(const int dim) {
  return kernel_alpha_of(dim, KERNEL_C2);
}

/**
 * @brief Set up the kernel constants.
 * @param[in] dim dimension
 * @param[in] h smoothing length [m]
 * @param[in] shape enum kernel_shape
 * @return the kernel constants
 */
static inline struct kernel kernel_make_shape(const int dim, const double h, const int shape) {
  const double a = kernel_alpha_of(dim, shape), c4 = shape == KERNEL_C4;
  struct kernel k = {.dim = dim,
                     .h = h,
                     .inv_h = 1.0 / h,
                     .wfac = a / pow(h, dim),
                     .ffac = (c4 ? -14.0 / 3.0 : -5.0) * a / pow(h, dim + 2),
                     .support2 = 4.0 * h * h,
                     .shape = shape};
  return k;
}

/** The Wendland C2 kernel of smoothing length h (thesis Eq. 2.63-2.66). */
static inline struct kernel kernel_make(const int dim, const double h) {
  return kernel_make_shape(dim, h, KERNEL_C2);
}

/**
 * @brief w of shape `shape` at q = r/h (any q >= 0: t is clamped at 0 beyond the support).
 * @param[in] k kernel constants
 * @param[in] shape k->shape, or that value as a compile-time constant of a specialised loop
 * @param[in] q r/h
 * @return w [1/m^dim]. Implements: thesis Eq. 2.63 (C2); Dehnen & Aly (2012) Table 1 (C4).
 */
static inline double kernel_w_of(const struct kernel *k, const int shape, const double q) {
  const double t = 1.0 - 0.5 * q, tp = t > 0.0 ? t : 0.0, t2 = tp * tp;
  if (shape == KERNEL_C4) return k->wfac * t2 * t2 * t2 * (1.0 + q * (3.0 + 35.0 / 12.0 * q));
  return k->wfac * t2 * t2 * (1.0 + 2.0 * q);
}

/**
 * @brief F = w'(r)/r of shape `shape` at q = r/h (0 beyond the support).
 * @param[in] k kernel constants
 * @param[in] shape as for kernel_w_of
 * @param[in] q r/h
 * @return F [1/m^(dim+2)], negative inside the support.
 */
static inline double kernel_f_of(const struct kernel *k, const int shape, const double q) {
  const double t = 1.0 - 0.5 * q, tp = t > 0.0 ? t : 0.0, f = k->ffac * tp * tp * tp;
  return shape == KERNEL_C4 ? f * (tp * tp) * (1.0 + 2.5 * q) : f;
}

/**
 * @brief Kernel value w(r, h).
 * @param[in] k kernel constants
 * @param[in] r distance [m]
 * @return w [1/m^dim]. Implements: thesis Eq. 2.63 (C2).
 */
static inline double kernel_w(const struct kernel *k, const double r) {
  return kernel_w_of(k, k->shape, r * k->inv_h); /* exactly +0 beyond the support */
}

/**
 * @brief Gradient factor F(r) = w'(r)/r, so that grad_a w_ab = F r_ab.
 * @param[in] k kernel constants
 * @param[in] r distance [m]
 * @return F [1/m^(dim+2)], negative inside the support.
 */
static inline double kernel_f(const struct kernel *k, const double r) {
  const double q = r * k->inv_h;
  return q >= 2.0 ? 0.0 : kernel_f_of(k, k->shape, q);
}

#endif
