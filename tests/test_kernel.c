/*
 * test_kernel.c: unit test of the Wendland kernels of solver/kernel.h (C2: thesis Eq.
 * 2.63-2.66; C4: Dehnen & Aly 2012).
 *
 * Checks, for C2 in dim = 1, 2, 3 and C4 in dim = 2, 3, and several smoothing lengths h:
 *  - normalisation: the integral of w over its support is 1 to 1e-12 (radial Gauss-Legendre
 *    quadrature on [0, 2h]; the integrand is a polynomial of degree <= 11 in r, so the
 *    16-point rule is exact up to rounding);
 *  - gradient: kernel_f(r) r equals dw/dr from a central finite difference to 1e-7 relative;
 *  - compact support: w = 0 and f = 0 exactly for r > 2h, w > 0 and f < 0 just inside. At
 *    r = 2h exactly, q = r * inv_h can round to 2 - 1 ulp (inv_h = 1/h is rounded), so there w
 *    and f are only required to be zero to rounding: w(2h) <= 1e-60 w(0), |f(2h)| <= 1e-45 |f(0)|
 *    (w ~ (1 - q/2)^4, f ~ (1 - q/2)^3 with 1 - q/2 ~ 1e-16); the maximum is printed;
 *  - C4 against its closed form written out independently of kernel.h's shared expression:
 *    w = alpha / h^m (1 - q/2)^6 (1 + 3q + 35/12 q^2) to 1e-14 relative (at the q = r / h the
 *    kernel computes, so that the rounding of 1 - q/2 near the edge is the same).
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>

#include "kernel.h"
#include "quadrature.h"

enum { GL_N = 16 };

/** Integral of w over the whole space, as a radial integral over [0, 2h]. */
static double kernel_integral(const struct kernel *k, const double *gx, const double *gw) {
  const double a = 0.0, b = 2.0 * k->h, mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double s = 0.0;
  for (int i = 0; i < GL_N; i++) {
    const double r = mid + half * gx[i];
    const double shell = k->dim == 1 ? 2.0 : k->dim == 2 ? 2.0 * M_PI * r : 4.0 * M_PI * r * r;
    s += gw[i] * shell * kernel_w(k, r);
  }
  return half * s;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  double gx[GL_N], gw[GL_N];
  gauss_legendre(GL_N, gx, gw);
  int fail = 0;

  /* the quadrature itself: sum of weights 2, exact for x^30 */
  double wsum = 0.0, m30 = 0.0;
  for (int i = 0; i < GL_N; i++) wsum += gw[i], m30 += gw[i] * pow(gx[i], 30);
  if (fabs(wsum - 2.0) > 1e-14 || fabs(m30 - 2.0 / 31.0) > 1e-14) {
    printf("FAIL: Gauss-Legendre rule is wrong (sum w = %.17g, int x^30 = %.17g)\n", wsum, m30);
    fail = 1;
  }

  const double hs[] = {1e-3, 0.013, 0.065, 0.1, 1.0, 3.7, 250.0};
  const int nh = (int)(sizeof hs / sizeof hs[0]);
  const double qs[] = {0.05, 0.3, 0.7, 1.0, 1.3, 1.7, 1.9, 1.97};
  const int nq = (int)(sizeof qs / sizeof qs[0]);
  double max_norm = 0.0, max_grad = 0.0, max_w_edge = 0.0, max_f_edge = 0.0;
  int support_bad = 0;

  double max_c4 = 0.0;
  for (int shape = KERNEL_C2; shape <= KERNEL_C4; shape++)
    for (int dim = shape == KERNEL_C4 ? 2 : 1; dim <= 3; dim++)
      for (int ih = 0; ih < nh; ih++) {
        const double h = hs[ih];
        const struct kernel k = kernel_make_shape(dim, h, shape);
        if (shape == KERNEL_C4) /* the C4 formula, written out */
          for (int iq = 0; iq < nq; iq++) {
            const double q = qs[iq] * h * k.inv_h, t = 1.0 - 0.5 * q; /* the q the kernel sees */
            const double ref = kernel_alpha_of(dim, shape) / pow(h, dim) * pow(t, 6) *
                               (1.0 + 3.0 * q + 35.0 / 12.0 * q * q);
            const double rel = fabs(kernel_w(&k, qs[iq] * h) - ref) / ref;
            if (rel > max_c4) max_c4 = rel;
            if (!(rel <= 1e-14)) {
              printf("FAIL: C4 dim %d h %g q %g: w = %.17g, formula %.17g\n", dim, h, q,
                     kernel_w(&k, qs[iq] * h), ref);
              fail = 1;
            }
          }

        /* normalisation */
        const double err = fabs(kernel_integral(&k, gx, gw) - 1.0);
        if (err > max_norm) max_norm = err;
        if (err > 1e-12) {
          printf("FAIL: shape %d dim %d h %g: integral of w - 1 = %.3e\n", shape, dim, h, err);
          fail = 1;
        }

        /* gradient factor against a central difference of w */
        /* step 1e-6 h: truncation ~ (dr / (2h - r))^2 stays below 1e-8 at q = 1.97, rounding
           ~ 1e-16 h / dr ~ 1e-10; the actual step (rp - rm) is used */
        for (int iq = 0; iq < nq; iq++) {
          const double r = qs[iq] * h, rp = r + 1e-6 * h, rm = r - 1e-6 * h;
          const double fd = (kernel_w(&k, rp) - kernel_w(&k, rm)) / (rp - rm);
          const double an = kernel_f(&k, r) * r;
          const double rel = fabs(an - fd) / fabs(fd);
          if (rel > max_grad) max_grad = rel;
          if (!(rel <= 1e-7)) {
            printf("FAIL: dim %d h %g q %g: f r = %.15g, dw/dr (FD) = %.15g, rel %.3e\n", dim, h,
                   qs[iq], an, fd, rel);
            fail = 1;
          }
        }

        /* compact support */
        const double w_edge = kernel_w(&k, 2.0 * h) / kernel_w(&k, 0.0);
        const double f_edge = fabs(kernel_f(&k, 2.0 * h) / kernel_f(&k, 0.0));
        if (w_edge > max_w_edge) max_w_edge = w_edge;
        if (f_edge > max_f_edge) max_f_edge = f_edge;
        if (!(w_edge >= 0.0 && w_edge <= 1e-60 && f_edge <= 1e-45)) {
          printf("FAIL: dim %d h %.17g: w(2h)/w(0) = %.3e, f(2h)/f(0) = %.3e (not zero)\n", dim, h,
                 w_edge, f_edge);
          support_bad++, fail = 1;
        }
        const double outside[] = {nextafter(2.0 * h, INFINITY), 2.0 * h * (1.0 + 1e-12), 2.5 * h,
                                  4.0 * h, 1e3 * h};
        for (size_t i = 0; i < sizeof outside / sizeof outside[0]; i++) {
          const double w = kernel_w(&k, outside[i]), f = kernel_f(&k, outside[i]);
          if (w != 0.0 || f != 0.0) {
            printf("FAIL: dim %d h %.17g r/h = %.17g: w = %.3e, f = %.3e (must be 0)\n", dim, h,
                   outside[i] / h, w, f);
            support_bad++, fail = 1;
          }
        }
        const double inside = 2.0 * h * (1.0 - 1e-6);
        if (!(kernel_w(&k, inside) > 0.0) || !(kernel_f(&k, inside) < 0.0) ||
            !(kernel_w(&k, 0.0) > 0.0) || !(kernel_f(&k, 0.0) < 0.0)) {
          printf("FAIL: dim %d h %g: w must be > 0 and f < 0 inside the support\n", dim, h);
          fail = 1;
        }
        /* value at the origin: alpha_m / h^m */
        const double w0 = kernel_alpha_of(dim, shape) / pow(h, dim);
        if (fabs(kernel_w(&k, 0.0) - w0) > 1e-15 * w0) {
          printf("FAIL: dim %d h %g: w(0) = %.17g, expected alpha/h^m = %.17g\n", dim, h,
                 kernel_w(&k, 0.0), w0);
          fail = 1;
        }
      }

  printf("kernel: max |int w - 1| = %.3e (tol 1e-12)\n", max_norm);
  printf("kernel: max rel error of f r vs dw/dr (central FD) = %.3e (tol 1e-7)\n", max_grad);
  printf("kernel: C4 against its written-out formula: max rel error %.3e (tol 1e-14)\n", max_c4);
  printf("kernel: support violations (w or f != 0 for r > 2h) = %d\n", support_bad);
  printf("kernel: at r = 2h exactly: max w/w(0) = %.3e, max |f/f(0)| = %.3e (q rounds below 2)\n",
         max_w_edge, max_f_edge);
  printf("%s\n", fail ? "test_kernel: FAILED" : "test_kernel: passed");
  MPI_Finalize();
  return fail;
}
