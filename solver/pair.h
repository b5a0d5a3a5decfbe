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

/** Minimum-image separation in a periodic direction of length l (hl = l/2), branch-free. */
static inline double pair_wrap(double d, double l, double hl) {
  return d > hl ? d - l : d < -hl ? d + l : d;
}

/* The geometry and the terms, in double (struct pair, pair_geom, term_pressure, ...) and in
   float (struct pair_f, pair_geom_f, term_pressure_f, ...: sph.precision = mixed, where the
   loops accumulate the float terms in double). */
#define R double
#define PF(name) name
#define R_SQRT sqrt
#include "pair_terms.h"
#undef R
#undef PF
#undef R_SQRT
#define R float
#define PF(name) name##_f
#define R_SQRT sqrtf
#include "pair_terms.h"
#undef R
#undef PF
#undef R_SQRT

#endif
