/**
 * @file pair.h
 * @brief The geometry of one particle pair a-b and the small vector types of the pair terms.
 *
 * Every pass over a neighbour list (pair_loop.h) computes the pair geometry with pair_geom();
 * the physical terms of a pair live in the term headers (term_pressure.h, term_viscous.h,
 * term_diffusion.h, term_gradient.h), one inline function per contribution, without side
 * effects or branches, so that the loops that use them vectorise (docs/performance.md,
 * "Vectorisation").
 *
 * Notation: r_ab = r_a - r_b (minimum image in the periodic directions), grad_a w_ab = F_ab r_ab
 * (kernel.h), V_b = m_b / rho_b, u_ab = u_a - u_b.
 */
#ifndef CHANSPH_PAIR_H
#define CHANSPH_PAIR_H

#include <math.h>

#include "kernel.h"

/** Build the hot loops for several instruction sets and pick one at run time (GCC on x86-64,
    unless the whole build already targets the build machine): the default build runs on any
    x86-64 and uses AVX2 or AVX-512 where the processor has them. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(CHANSPH_NATIVE)
#define CHANSPH_CLONES __attribute__((target_clones("default", "avx2", "arch=x86-64-v4")))
#else
#define CHANSPH_CLONES
#endif

/** A vector in 3-D (z = 0 in 2-D). */
struct v3 {
  double x, y, z;
};

/** A symmetric 3x3 tensor {xx, xy, xz, yy, yz, zz}. */
struct sym3 {
  double xx, xy, xz, yy, yz, zz;
};

/** Geometry of a pair within the kernel support. */
struct pair {
  double dx, dy, dz; /*!< r_ab [m] */
  double r2, r;      /*!< |r_ab|^2 [m^2], |r_ab| [m] */
  double f;          /*!< F_ab = w'(r)/r [1/m^(dim+2)]; 0 outside the support */
};

/** Minimum-image separation in a periodic direction of length l (hl = l/2), branch-free. */
static inline double pair_wrap(double d, double l, double hl) {
  return d > hl ? d - l : d < -hl ? d + l : d;
}

/**
 * @brief Geometry of the pair (dx, dy, dz) = r_a - r_b before the periodic wrap.
 * @param K kernel; shape K->shape, a compile-time constant in the specialised hot loops (a
 *        test on K->shape inside a vectorised loop costs the C2 step 2-5%: GCC 12 does not
 *        unswitch these loops, it computes both shapes and blends);
 *        lx, lz periodic lengths; d3 nonzero in 3-D (dz = 0 otherwise)
 */
static inline struct pair pair_geom_shape(const struct kernel *K, const int shape, double lx,
                                          double lz, int d3, double dx, double dy, double dz) {
  struct pair g;
  g.dx = pair_wrap(dx, lx, 0.5 * lx), g.dy = dy;
  g.dz = (d3 ? 1.0 : 0.0) * pair_wrap(dz, lz, 0.5 * lz); /* branch-free: vectorises */
  g.r2 = g.dx * g.dx + g.dy * g.dy + g.dz * g.dz;
  g.r = sqrt(g.r2);
  g.f = kernel_f_of(K, shape, g.r * K->inv_h); /* kernel.h: F of C2 or C4 */
  return g;
}

/** pair_geom_shape() with the shape of the kernel read at run time (loops off the hot path). */
static inline struct pair pair_geom(const struct kernel *K, double lx, double lz, int d3, double dx,
                                    double dy, double dz) {
  return pair_geom_shape(K, K->shape, lx, lz, d3, dx, dy, dz);
}

#endif
