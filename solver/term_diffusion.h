/**
 * @file term_diffusion.h
 * @brief The volume diffusion of the continuity equation (thesis Eq. 3.34, 3.64, with the
 *        hydrostatic density difference varrho_ab of Eq. 3.61): its pair term and its finish.
 *
 * D_a = (1/xi) sum_b V_b max(c_a, c_b) (rho_a - rho_b - rho0 g_y y_ab / c0^2) F_ab l_ab over the
 * fluid neighbours, with the pair length l_ab = r_ab (sph.diffusion = ferrand, the thesis) or
 * l_ab = 2 delta h xi (delta_sph: the strength of the delta-SPH diffusion of Antuono et al.
 * 2010, D_a = 2 delta h sum_b V_b c_ab varrho_ab F_ab; varrho_ab is the dynamic density
 * difference of Fourtakas et al. 2019); sph_density() adds dt D_a to gamma_a rho_a (Eq. 3.64:
 * no 1/gamma_a). Hooks: diffusion_init (the model's constants), diffusion_pair (summed by the
 * force loop over the fluid part of the list), diffusion_finish. It has no budget part (it
 * changes no momentum). Its time-step limit (diffusion_dt_limit) is that of an explicit
 * diffusion of diffusivity D = c0 (2 h diff_lr + diff_lc) / (2 xi), delta h c0 for delta_sph:
 * dt <= c_diffusion h^2 / D (time.c_diffusion).
 */
#ifndef CHANSPH_TERM_DIFFUSION_H
#define CHANSPH_TERM_DIFFUSION_H

#include "pair.h"
#include "sph.h"

/** The pair length of the scene's form: l_ab = diff_lr r_ab + diff_lc. */
static inline void diffusion_init(struct model *M, const struct scene *s) {
  const int delta = s->diffusion == DIFFUSION_DELTA_SPH;
  M->diff_lr = delta ? 0.0 : 1.0;
  M->diff_lc = delta ? 2.0 * s->diff_delta * M->h / M->inv_xi : 0.0;
  M->diff_substeps = s->diff_substeps;
}

/** Volume diffusion of one fluid pair, to be divided by xi: V_b max(c_a, c_b) (drho - dgrav
    y_ab) F_ab l_ab, with drho = rho_a - rho_b formed by the caller in double,
    dgrav = rho0 g_y / c0^2 (diffusion_dgrav) and l_ab = lr r_ab + lc (struct model diff_lr,
    diff_lc): one form of loop for both pair forms. */
static inline double diffusion_pair(const struct pair *g, double vb, double ca, double cb,
                                    double drho, double dgrav, double lr, double lc) {
  const double cab = ca > cb ? ca : cb;
  return vb * cab * (drho - dgrav * g->dy) * g->f * (lr * g->r + lc);
}

/** rho0 g_y / c0^2 of Eq. 3.61: the hydrostatic density gradient. */
static inline double diffusion_dgrav(const struct model *M) {
  return M->e.rho0 / (M->e.c0 * M->e.c0) * M->gy;
}

/** D_a from the pair sum of particle a's fluid neighbours. */
static inline double diffusion_finish(const struct model *M, double sum) {
  return sum * M->inv_xi;
}

/** The diffusivity of the volume diffusion, D = c0 (2 h lr + lc) / (2 xi) [m^2/s]: delta h c0 for
    delta_sph (l_ab = 2 delta h xi), and its bound over the kernel support (r_ab <= 2 h) for
    the thesis form. */
static inline double diffusion_diffusivity(const struct model *M) {
  return M->e.c0 * (2.0 * M->h * M->diff_lr + M->diff_lc) * M->inv_xi / 2.0;
}

/** The explicit diffusion's time-step limit n_d c_diffusion h^2 / D [s] (INFINITY without one):
    each of the n_d sub-steps (sph.diffusion_substeps) within it. */
static inline double diffusion_dt_limit(const struct model *M, double c_diffusion) {
  const double d = diffusion_diffusivity(M);
  return c_diffusion > 0.0 && d > 0.0 ? M->diff_substeps * (c_diffusion * M->h * M->h / d)
                                      : INFINITY;
}

#endif
