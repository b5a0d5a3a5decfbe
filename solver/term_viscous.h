/**
 * @file term_viscous.h
 * @brief The viscous term of the momentum equation: its pair terms, their normalisation, the
 *        wall shear term, the budget parts and the viscous time-step limit.
 *
 * Three operators (scene keys sph.viscous and les.model):
 *  - Morris (thesis Eq. 2.147): (nu/gamma_a) sum_b m_b (1/rho_a + 1/rho_b) F_ab r^2/(r^2 + eta^2)
 *    u_ab;
 *  - Violeau (Eq. 2.100): 1/(gamma_a rho_a) sum_b V_b mu_ab F_ab / (r^2 + eta^2)
 *    ((n + 2)(u_ab . r_ab) r_ab + r^2 u_ab) with mu_ab = (rho_a + rho_b) nu / 2;
 *  - the LES operator: Violeau's with the variable viscosity mu = rho (nu + nu_r).
 * Each is normalised by its discrete second moment plus the analytic part behind the walls
 * (sph.laplacian_norm, docs/theory.md), and completed by the wall shear term (Eq. 2.147-2.148
 * with the weight of sph.wall_shear_weight, or the wall law of wall.law).
 * Hooks: viscous_morris_pair / viscous_violeau_pair and the moments (summed by the force loop
 * into struct viscous_sums), viscous_norm and viscous_finish (the acceleration),
 * viscous_wall (the wall shear), viscous_budget (the budget's viscous part),
 * viscous_dt_limit (Eq. 2.161).
 */
#ifndef CHANSPH_TERM_VISCOUS_H
#define CHANSPH_TERM_VISCOUS_H

#include "pair_loop.h"
#include "wall.h"

/** Pair sums of the viscous term of one particle over one part of its list. */
struct viscous_sums {
  struct v3 vis;   /*!< the operator's sum (viscous_morris_pair or viscous_violeau_pair) */
  struct v3 mom;   /*!< moments r^2, y^2, y (viscous_moments) */
  double m1x, m2x; /*!< Violeau's wall moments, x part (first, second) */
  double m1z, m2z; /*!< and z part */
};

/** Morris' viscous operator (thesis Eq. 2.147, particle part, without nu / gamma_a):
    m_b (1/rho_a + 1/rho_b) F_ab r^2 / (r^2 + eta^2) u_ab. */
static inline struct v3 viscous_morris_pair(const struct pair *g, double mb, double inv_rhoa,
                                            double vb, double eta2, struct v3 uab) {
  const double s = (mb * inv_rhoa + vb) * g->f * g->r2 / (g->r2 + eta2);
  return (struct v3){s * uab.x, s * uab.y, s * uab.z};
}

/** Violeau's viscous operator (thesis Eq. 2.100, particle part, without 1 / (gamma_a rho_a)):
    V_b mu_ab F_ab / (r^2 + eta^2) ((n + 2) (u_ab . r_ab) r_ab + r^2 u_ab), with mu_ab the mean
    dynamic viscosity of the pair (rho (nu + nu_r) with the eddy viscosity, or rho). */
static inline struct v3 viscous_violeau_pair(const struct pair *g, double vb, double mu_ab,
                                             double nplus2, double eta2, struct v3 uab) {
  const double s = vb * mu_ab * g->f / (g->r2 + eta2);
  const double vr = nplus2 * (uab.x * g->dx + uab.y * g->dy + uab.z * g->dz);
  return (struct v3){s * (vr * g->dx + g->r2 * uab.x), s * (vr * g->dy + g->r2 * uab.y),
                     s * (vr * g->dz + g->r2 * uab.z)};
}

/** Moments of the viscous normalisation and of the wall weights (docs/theory.md):
    V_b F_ab times r^2 (trace), y_ab^2 (wall-normal) and y_ab (discrete first moment). */
static inline struct v3 viscous_moments(const struct pair *g, double vb) {
  const double vf = vb * g->f;
  return (struct v3){vf * g->r2, vf * g->dy * g->dy, vf * g->dy};
}

/** Violeau's wall moments of the x and z parts of the operator:
    V_b F_ab ((n+2) x_i^2 / (r^2 + eta^2) + 1) y_ab for i = x (.x) and i = z (.y); the second
    moments are these times y_ab. */
static inline struct v3 viscous_violeau_moments(const struct pair *g, double vb, double nplus2,
                                                double eta2) {
  const double vf = vb * g->f, ir = 1.0 / (g->r2 + eta2);
  return (struct v3){vf * (nplus2 * g->dx * g->dx * ir + 1.0) * g->dy,
                     vf * (nplus2 * g->dz * g->dz * ir + 1.0) * g->dy, 0.0};
}

/** The normalisation and prefactors of the viscous sum of one particle. */
struct viscous_norm {
  double kappa, kx, kz; /*!< normalisation (mean); Violeau: of its x and z parts */
  double lap;           /*!< nu / gamma_a, normalised (Morris' wall shear) */
  double vis; /*!< prefactor of the sum: nu/gamma_a, nu/(gamma_a rho_a), 1/(gamma_a rho_a) */
};

/** The normalisation of fluid particle a from the moments of its fluid (s) and vertex (sv)
    sums: the discrete second moment plus the analytic part behind the walls. */
static inline struct viscous_norm viscous_norm(const struct model *M, const struct particles *P,
                                               size_t a, const struct viscous_sums *s,
                                               const struct viscous_sums *sv) {
  const double ih = M->k.inv_h, ya = P->y[a], ig = 1.0 / P->gam[a], nu = M->nu;
  const int violeau = M->viscous == VISCOUS_VIOLEAU;
  double kappa = 1.0, kx = 1.0, kz = 1.0;
  if (M->lap_norm != LAPNORM_NONE) { /* discrete + analytic part behind the walls */
    const double qb = ya * ih, qt = (M->ly - ya) * ih;
    if (M->lap_norm == LAPNORM_TRACE) {
      kappa = -M->dim /
              (s->mom.x + sv->mom.x + wall_moment2_of(&M->k, qb) + wall_moment2_of(&M->k, qt));
      kx = kz = kappa;
    } else if (violeau) { /* its own y-y moments: -2 in the full space */
      const double wm = sph_violeau_moment(M, qb) + sph_violeau_moment(M, qt);
      kx = -2.0 / (s->m2x + sv->m2x + wm);
      kz = M->dim == 3 ? -2.0 / (s->m2z + sv->m2z + wm) : kx;
      kappa = 0.5 * (kx + kz);
    } else {
      kappa = -1.0 /
              (s->mom.y + sv->mom.y + wall_moment_yy_of(&M->k, qb) + wall_moment_yy_of(&M->k, qt));
      kx = kz = kappa;
    }
  }
  const double ra = P->rho[a];
  const double vis = M->les ? ig / ra : violeau ? nu * ig / ra : nu * ig;
  return (struct viscous_norm){kappa, kx, kz, nu * ig * kappa, vis};
}

/** The normalised viscous sum of fluid and vertex neighbours added to acc; returns its vertex
    part in x, the viscous pull of the wall vertices (for the wall shear stress). */
static inline double viscous_finish(const struct viscous_norm *n, const struct viscous_sums *s,
                                    const struct viscous_sums *sv, struct v3 *acc) {
  const double vx = s->vis.x + sv->vis.x, vy = s->vis.y + sv->vis.y, vz = s->vis.z + sv->vis.z;
  acc->x += n->vis * n->kx * vx, acc->y += n->vis * n->kappa * vy, acc->z += n->vis * n->kz * vz;
  return n->vis * n->kx * sv->vis.x;
}

/** The first moments the wall shear term weighs with, summed over fluid and vertex parts. */
struct viscous_wall_moments {
  double mom1;     /*!< sum_b V_b y_ab F_ab */
  double m1x, m1z; /*!< Violeau's x and z parts */
};

/**
 * @brief The wall shear term of fluid particle a added to acc and to *awall (the x-acceleration
 *        from the walls): the wall law's stress at the foot (Eq. 2.144-2.145 with the vertex
 *        values of Ferrand Eq. 38), or the laminar term of Eq. 2.147-2.148 weighted by
 *        |grad gamma_as| or by the discrete first moment that makes the operator exact for a
 *        velocity varying linearly with the wall distance (docs/theory.md).
 */
static inline void viscous_wall(const struct model *M, const struct particles *P,
                                const struct walls *W, size_t a, const struct viscous_norm *n,
                                const struct viscous_wall_moments *wm, struct v3 *acc,
                                double *awall) {
  const double nu = M->nu, ig = 1.0 / P->gam[a], ira = 1.0 / P->rho[a];
  const double ya = P->y[a], ua = P->u[a], wa = P->w[a];
  const int violeau = M->viscous == VISCOUS_VIOLEAU;
  const int discrete = M->wall_weight == WALL_WEIGHT_DISCRETE;
  for (int wall = 0; wall < 2; wall++) {
    struct wall_near wn;
    if (!sph_wall_near(M, ya, wall, &wn)) continue;
    const double d = wn.d, dg = wn.dg, ny = wn.ny;
    if (M->law.law != WALL_LAW_LAMINAR) {
      /* -(2 / gamma_a) rho_s u_tau,s u_tau,s |grad gamma_as| / rho_a */
      const struct foot ft = sph_foot(M, W, wall, P->x[a], P->z[a]);
      const double sw = 2.0 * ig * dg * ira;
      const double tx = sw * sph_foot_value(M, &ft, W->tx);
      acc->x -= tx, acc->z -= sw * sph_foot_value(M, &ft, W->tz);
      *awall -= tx;
      continue;
    }
    const double dist = d > M->wall_dmin ? d : M->wall_dmin;
    if (violeau) { /* half the first moment of its x and z parts */
      const double dw = 2.0 * nu * ig / dist;
      const double wx = discrete ? 0.5 * fmax(0.0, ny * wm->m1x) : dg;
      const double wz = discrete ? 0.5 * fmax(0.0, ny * wm->m1z) : dg;
      acc->x -= dw * n->kx * wx * ua, acc->z -= dw * n->kz * wz * wa;
      *awall -= dw * n->kx * wx * ua;
    } else {
      const double weight = discrete ? fmax(0.0, ny * wm->mom1) : dg;
      const double shear = 2.0 * n->lap * weight / dist;
      acc->x -= shear * ua, acc->z -= shear * wa;
      *awall -= shear * ua;
    }
  }
}

/** The acceleration of particle a by the viscous pair forces of its fluid neighbours (fluid
    part s of the sums), molecular and eddy-viscous together, as its own sums give it: the
    budget (sph_budget_pairs splits it into its conservative molecular and eddy-viscous parts
    and the walls' share). */
static inline struct v3 viscous_budget(const struct viscous_norm *n, const struct viscous_sums *s) {
  return (struct v3){n->vis * n->kx * s->vis.x, n->vis * n->kappa * s->vis.y,
                     n->vis * n->kz * s->vis.z};
}

/** The viscous time-step limit c_visc h^2 / max(nu + nu_r) (thesis Eq. 2.161) [s]. */
static inline double viscous_dt_limit(double c_visc, double h, double nu_max) {
  return nu_max > 0.0 ? c_visc * h * h / nu_max : INFINITY;
}

#endif
