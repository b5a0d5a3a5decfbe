/**
 * @file term_diffusion.h
 * @brief The volume diffusion of the continuity equation (thesis Eq. 3.34, 3.64, with the
 *        hydrostatic density difference varrho_ab of Eq. 3.61): its pair term and its finish.
 *
 * D_a = (1/xi) sum_b V_b max(c_a, c_b) (rho_a - rho_b - rho0 g_y y_ab / c0^2) F_ab r_ab over the
 * fluid neighbours; sph_density() adds dt D_a to gamma_a rho_a (Eq. 3.64: no 1/gamma_a).
 * Hooks: diffusion_pair (summed by the force loop over the fluid part of the list),
 * diffusion_finish. It has no budget part (it changes no momentum) and no time-step limit of
 * its own.
 */
#ifndef CHANSPH_TERM_DIFFUSION_H
#define CHANSPH_TERM_DIFFUSION_H

#include "pair.h"
#include "sph.h"

/** Volume diffusion of one fluid pair, to be divided by xi: V_b max(c_a, c_b) (drho - dgrav
    y_ab) F_ab r, with drho = rho_a - rho_b formed by the caller in double and
    dgrav = rho0 g_y / c0^2 (diffusion_dgrav). */
static inline double diffusion_pair(const struct pair *g, double vb, double ca, double cb,
                                    double drho, double dgrav) {
  const double cab = ca > cb ? ca : cb;
  return vb * cab * (drho - dgrav * g->dy) * g->f * g->r;
}

/** rho0 g_y / c0^2 of Eq. 3.61: the hydrostatic density gradient. */
static inline double diffusion_dgrav(const struct model *M) {
  return M->e.rho0 / (M->e.c0 * M->e.c0) * M->gy;
}

/** D_a from the pair sum of particle a's fluid neighbours. */
static inline double diffusion_finish(const struct model *M, double sum) {
  return sum * M->inv_xi;
}

#endif
