/**
 * @file term_pressure.h
 * @brief The pressure gradient of the momentum equation: its pair terms, the per-particle
 *        finish, the wall term, the budget part and the wall's time-step rate.
 *
 * Two forms (scene key sph.pressure_gradient):
 *  - symmetric: -(1/gamma_a) sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2) grad w_ab plus the wall term
 *    (Grad^{gamma,1} of thesis Eq. 3.17, k = 1), with the weight of the wall term of
 *    sph.wall_pressure_weight (docs/theory.md);
 *  - corrected: -(1/rho_a) L_a sum_b V_b (p_b - p_a) grad w_ab (Eq. 2.88-2.90, k = 0) over fluid
 *    and vertex neighbours, exact for a linear pressure, without a wall term. L_a is factorised
 *    once per particle (sph_sym_factor) and applied to the whole sum and, on sampled steps, to
 *    its fluid part for the budget.
 * Hooks: pressure_pair / pressure_corrected_pair (the pair contributions, summed by the force
 * loop into struct pressure_sums), pressure_finish (the acceleration), pressure_wall (the wall
 * term and |grad gamma_as . v_a| of the wall time-step limit, Eq. 2.163), pressure_budget
 * (budget part SX_PRESSURE).
 */
#ifndef CHANSPH_TERM_PRESSURE_H
#define CHANSPH_TERM_PRESSURE_H

#include "term_gradient.h"
#include "wall.h"

/** Pair sums of the pressure gradient of one particle over one part of its list. */
struct pressure_sums {
  struct v3 gp;  /*!< symmetric form: sum of pressure_pair */
  struct sym3 A; /*!< corrected form: the moment matrix (gradient_moment) */
  struct v3 gc;  /*!< corrected form: the pressure difference sums (gradient_difference) */
};

/** Pressure gradient, symmetric form (thesis Eq. 3.17, particle part):
    m_b (p_a/rho_a^2 + p_b/rho_b^2) F_ab r_ab, to be multiplied by -1/gamma_a. */
static inline struct v3 pressure_pair(const struct pair *g, double mb, double pr2a, double pr2b) {
  const double s = mb * (pr2a + pr2b) * g->f;
  return (struct v3){s * g->dx, s * g->dy, s * g->dz};
}

/** Corrected form, difference part: V_b (p_b - p_a) F_ab r_ab with p_b = pr2_b rho_b^2 and
    pa = p_a (the moment matrix is gradient_moment). */
static inline struct v3 pressure_corrected_pair(const struct pair *g, double vb, double pr2b,
                                                double rb, double pa) {
  return gradient_difference(g, vb, pr2b * rb * rb - pa);
}

/** Acceleration -grad p / rho of fluid particle a without the wall term, from the sums of its
    fluid (s) and vertex (sv) neighbours; corrected form: L_a factorised into *L (read by
    pressure_budget). */
static inline struct v3 pressure_finish(const struct model *M, const struct particles *P, size_t a,
                                        const struct pressure_sums *s,
                                        const struct pressure_sums *sv, struct sym_solve *L) {
  if (M->pgrad == PGRAD_CORRECTED) { /* -(1/rho_a) L_a g, L_a = A^-1 (Eq. 2.88, 2.90, k = 0) */
    const double A[6] = {s->A.xx + sv->A.xx, s->A.xy + sv->A.xy, s->A.xz + sv->A.xz,
                         s->A.yy + sv->A.yy, s->A.yz + sv->A.yz, s->A.zz + sv->A.zz};
    const double gc[3] = {s->gc.x + sv->gc.x, s->gc.y + sv->gc.y, s->gc.z + sv->gc.z};
    double gr[3];
    sph_sym_factor(M->dim, A, L);
    sph_sym_apply(L, gc, gr);
    const double ira = 1.0 / P->rho[a];
    return (struct v3){-gr[0] * ira, -gr[1] * ira, -gr[2] * ira};
  }
  const double ig = 1.0 / P->gam[a];
  return (struct v3){-ig * (s->gp.x + sv->gp.x), -ig * (s->gp.y + sv->gp.y),
                     -ig * (s->gp.z + sv->gp.z)};
}

/** The pressure wall term of the symmetric form (Eq. 3.17, k = 1) of fluid particle a added to
    *aya, with the wall values at its foot; mom1: the discrete first moment sum_b V_b y_ab F_ab
    (viscous_sums). Returns max over the walls of |grad gamma_as . v_a| for the wall time-step
    limit (Eq. 2.163), in either form. */
static inline double pressure_wall(const struct model *M, const struct particles *P,
                                   const struct walls *W, size_t a, double mom1, double *aya) {
  const double ya = P->y[a], va = P->v[a], pa = P->pr2[a];
  const double ig = 1.0 / P->gam[a];
  const int corrected = M->pgrad == PGRAD_CORRECTED;
  double gv = 0.0;
  for (int wall = 0; wall < 2; wall++) {
    struct wall_near wn;
    if (!sph_wall_near(M, ya, wall, &wn)) continue;
    const double q = wn.q, dg = wn.dg, ny = wn.ny;
    if (!corrected) {
      const struct foot ft = sph_foot(M, W, wall, P->x[a], P->z[a]);
      const double rs = sph_foot_value(M, &ft, W->rho), ps = sph_foot_value(M, &ft, W->p);
      /* |grad gamma_as| plus the excess of the discrete first moment on the particle lattice
         (so that a uniform pressure leaves the lattice in equilibrium yet pushes a displaced
         particle back), or of the current particles, or nothing (docs/theory.md) */
      const double pw = M->wall_pressure == WALL_PRESSURE_LATTICE
                            ? dg + sph_lattice_table(M, M->lat_e, q)
                        : M->wall_pressure == WALL_PRESSURE_CONSISTENT ? fmax(dg, ny * mom1)
                                                                       : dg;
      *aya += ig * rs * (pa + ps / (rs * rs)) * pw * ny;
    }
    const double g = fabs(dg * va);
    if (g > gv) gv = g;
  }
  return gv;
}

/** Budget part SX_PRESSURE: the acceleration of particle a by the pressure of its fluid
    neighbours (fluid part s of the sums; corrected form: the factorised L_a of
    pressure_finish, which the fluid and vertex parts share). */
static inline struct v3 pressure_budget(const struct model *M, const struct particles *P, size_t a,
                                        const struct pressure_sums *s, const struct sym_solve *L) {
  if (M->pgrad == PGRAD_CORRECTED) { /* -(1/rho_a) L_a g, g of the fluid neighbours only */
    const double gc[3] = {s->gc.x, s->gc.y, s->gc.z};
    double gr[3];
    sph_sym_apply(L, gc, gr);
    const double ira = 1.0 / P->rho[a];
    return (struct v3){-gr[0] * ira, -gr[1] * ira, -gr[2] * ira};
  }
  const double ig = 1.0 / P->gam[a];
  return (struct v3){-s->gp.x * ig, -s->gp.y * ig, -s->gp.z * ig};
}

#endif
