/**
 * @file pair.h
 * @brief The physics of one particle pair a-b, one small inline function per term.
 *
 * Every pass over the neighbour list (forces, the LES strain, the vertex values) computes the
 * pair geometry with pair_geom() and adds the terms it needs; which terms a scene needs is
 * decided once, outside the particle loop (forces.c assembles specialised loops). Each term
 * returns its contribution and the loop accumulates it: the functions have no side effects and
 * no branches, so the loops that use them vectorise (docs/performance.md, "Vectorisation").
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
 * @param K kernel; lx, lz periodic lengths; d3 nonzero in 3-D (dz = 0 otherwise)
 */
static inline struct pair pair_geom(const struct kernel *K, double lx, double lz, int d3, double dx,
                                    double dy, double dz) {
  struct pair g;
  g.dx = pair_wrap(dx, lx, 0.5 * lx), g.dy = dy;
  g.dz = (d3 ? 1.0 : 0.0) * pair_wrap(dz, lz, 0.5 * lz); /* branch-free: the loop vectorises */
  g.r2 = g.dx * g.dx + g.dy * g.dy + g.dz * g.dz;
  g.r = sqrt(g.r2);
  const double t = 1.0 - 0.5 * g.r * K->inv_h; /* thesis Eq. 2.63: (1 - q/2)^3 for F */
  const double tp = t > 0.0 ? t : 0.0;
  g.f = K->ffac * tp * tp * tp;
  return g;
}

/** Kernel value w(r) of a pair inside the support (thesis Eq. 2.63). */
static inline double pair_w(const struct kernel *K, double r) {
  const double q = r * K->inv_h, t = 1.0 - 0.5 * q;
  const double tp = t > 0.0 ? t : 0.0, t2 = tp * tp;
  return K->wfac * t2 * t2 * (1.0 + 2.0 * q);
}

/** Pressure gradient, symmetric form (thesis Eq. 3.17, particle part):
    m_b (p_a/rho_a^2 + p_b/rho_b^2) F_ab r_ab, to be multiplied by -1/gamma_a. */
static inline struct v3 term_pressure(const struct pair *g, double mb, double pr2a, double pr2b) {
  const double s = mb * (pr2a + pr2b) * g->f;
  return (struct v3){s * g->dx, s * g->dy, s * g->dz};
}

/** Moment matrix of the first-order correction (thesis Eq. 2.88): -V_b F_ab r_ab (x) r_ab;
    its sum is A_a, with L_a = A_a^-1. */
static inline struct sym3 term_moment(const struct pair *g, double vb) {
  const double vf = -vb * g->f;
  return (struct sym3){vf * g->dx * g->dx, vf * g->dx * g->dy, vf * g->dx * g->dz,
                       vf * g->dy * g->dy, vf * g->dy * g->dz, vf * g->dz * g->dz};
}

/** Corrected difference gradient of a scalar (thesis Eq. 2.90, k = 0, before L_a):
    V_b (f_b - f_a) F_ab r_ab. */
static inline struct v3 term_difference(const struct pair *g, double vb, double dfba) {
  const double s = vb * dfba * g->f;
  return (struct v3){s * g->dx, s * g->dy, s * g->dz};
}

/** Morris' viscous operator (thesis Eq. 2.147, particle part, without nu / gamma_a):
    m_b (1/rho_a + 1/rho_b) F_ab r^2 / (r^2 + eta^2) u_ab. */
static inline struct v3 term_morris(const struct pair *g, double mb, double inv_rhoa, double vb,
                                    double eta2, struct v3 uab) {
  const double s = (mb * inv_rhoa + vb) * g->f * g->r2 / (g->r2 + eta2);
  return (struct v3){s * uab.x, s * uab.y, s * uab.z};
}

/** Violeau's viscous operator (thesis Eq. 2.100, particle part, without 1 / (gamma_a rho_a)):
    V_b mu_ab F_ab / (r^2 + eta^2) ((n + 2) (u_ab . r_ab) r_ab + r^2 u_ab), with mu_ab the mean
    dynamic viscosity of the pair (rho (nu + nu_r) with the eddy viscosity, or rho). */
static inline struct v3 term_violeau(const struct pair *g, double vb, double mu_ab, double nplus2,
                                     double eta2, struct v3 uab) {
  const double s = vb * mu_ab * g->f / (g->r2 + eta2);
  const double vr = nplus2 * (uab.x * g->dx + uab.y * g->dy + uab.z * g->dz);
  return (struct v3){s * (vr * g->dx + g->r2 * uab.x), s * (vr * g->dy + g->r2 * uab.y),
                     s * (vr * g->dz + g->r2 * uab.z)};
}

/** Volume diffusion of the continuity equation (thesis Eq. 3.34, 3.64, with varrho_ab of
    Eq. 3.61): V_b max(c_a, c_b) (rho_a - rho_b - rho0 g_y y_ab / c0^2) F_ab r; fluid pairs only,
    to be divided by xi. */
static inline double term_diffusion(const struct pair *g, double vb, double ca, double cb,
                                    double rhoa, double rhob, double dgrav) {
  const double cab = ca > cb ? ca : cb;
  return vb * cab * (rhoa - rhob - dgrav * g->dy) * g->f * g->r;
}

/** Moments of the viscous normalisation and of the wall weights (docs/theory.md):
    V_b F_ab times r^2 (trace), y_ab^2 (wall-normal) and y_ab (discrete first moment). */
static inline struct v3 term_moments(const struct pair *g, double vb) {
  const double vf = vb * g->f;
  return (struct v3){vf * g->r2, vf * g->dy * g->dy, vf * g->dy};
}

/** Violeau's wall moments of the x and z parts of the operator:
    V_b F_ab ((n+2) x_i^2 / (r^2 + eta^2) + 1) y_ab for i = x (.x) and i = z (.y); the second
    moments are these times y_ab. */
static inline struct v3 term_violeau_moments(const struct pair *g, double vb, double nplus2,
                                             double eta2) {
  const double vf = vb * g->f, ir = 1.0 / (g->r2 + eta2);
  return (struct v3){vf * (nplus2 * g->dx * g->dx * ir + 1.0) * g->dy,
                     vf * (nplus2 * g->dz * g->dz * ir + 1.0) * g->dy, 0.0};
}

#endif
