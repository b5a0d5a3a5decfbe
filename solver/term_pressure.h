/**
 * @file term_pressure.h
 * @brief The pressure gradient of the momentum equation: its pair terms, the per-particle
 *        finish, the wall term, the budget part and the wall's time-step rate.
 *
 * Three forms (scene key sph.pressure_gradient):
 *  - symmetric: -(1/gamma_a) sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2) grad w_ab plus the wall term
 *    (Grad^{gamma,1} of thesis Eq. 3.17, k = 1), with the weight of the wall term of
 *    sph.wall_pressure_weight (docs/theory.md);
 *  - corrected: -(1/rho_a) L_a sum_b V_b (p_b - p_a) grad w_ab (Eq. 2.88-2.90, k = 0) over fluid
 *    and vertex neighbours, exact for a linear pressure, without a wall term. L_a is factorised
 *    once per particle (sph_sym_factor) and applied to the whole sum and, on sampled steps, to
 *    its fluid part for the budget;
 *  - kgc (kernel-gradient corrected, conservative): -(1/(gamma_a rho_a)) sum_b V_b (p_a B_b +
 *    p_b B_a) F_ab r_ab over fluid and vertex neighbours plus the wall term
 *    (1/(gamma_a rho_a)) (p_a + p_s) B_a W_as n_s (the wall's B taken as B_a), with W_as the
 *    weight of the symmetric form. B_a = w L_a + (1 - w) I is the inverse of the moment matrix
 *    of the whole support (fluid, vertices and the analytic part behind the walls) blended
 *    towards the identity where it is ill-conditioned (kgc_blend), set per particle before the
 *    force pass (sph_kgc_matrices, kgc.c). With B = I it is the volume form of the symmetric
 *    one, and it is antisymmetric in a and b; for a linear pressure its first-order part
 *    B_a sum_b V_b (p_b - p_a) F_ab r_ab = B_a A_a grad p is exact (w = 1), the rest
 *    p_a sum_b V_b (B_a + B_b) F_ab r_ab is the configurational error (docs/theory.md).
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
  struct v3 gc;  /*!< corrected form: the pressure difference sums (gradient_difference); kgc:
                      sum_b V_b p_b F_ab r_ab (pressure_kgc_pair) */
  /* kgc: sum_b V_b B_b F_ab r_ab (pressure_kgc_matrix_pair) in A.xx, A.xy, A.xz (kgc_gb): a
     member of its own made GCC run the LES force loops scalar (2.3 times slower) */
};

/** kgc: the sums sum_b V_b B_b F_ab r_ab, kept in A.xx, A.xy, A.xz (unused by kgc). */
static inline struct v3 kgc_gb(const struct pressure_sums *s) {
  return (struct v3){s->A.xx, s->A.xy, s->A.xz};
}

/** The conditioning bounds of the kgc blend (kgc_blend): the lower Gershgorin bound of the
    smallest eigenvalue of A_a (1 for a full support in the continuum, 0.974 on the lattice at
    h/dr = 1.3) below which B_a is the identity (KGC_LAM0) and above which it is L_a (KGC_LAM1),
    linear between. */
#define KGC_LAM0 0.3
#define KGC_LAM1 0.6

/** The moment matrix behind the walls: the analytic part -int F r (x) r dV of the half-spaces
    behind both walls at y and ly - y from a particle at height y (diagonal: xx = zz, yy;
    wall_moment2, wall_moment_yy), added to a discrete A (as {xx, xy, xz, yy, yz, zz}). */
static inline void kgc_moment_behind(const struct kernel *K, int dim, double ih, double y,
                                     double ly, double A[6]) {
  const double qb = y * ih, qt = (ly - y) * ih;
  const double myy = wall_moment_yy_of(K, qb) + wall_moment_yy_of(K, qt);
  const double mtr = wall_moment2_of(K, qb) + wall_moment2_of(K, qt);
  const double mt = (mtr - myy) / (dim - 1); /* each tangential direction */
  A[0] -= mt, A[3] -= myy;
  if (dim == 3) A[5] -= mt;
}

/** The lattice correction of the kgc moment matrix of a particle at height y (vertex: on a
    wall): the deviation of the initial lattice's moment matrix near each wall from its value far
    from the walls (model.lat_kxx, lat_kyy, kgc_vxx, kgc_vyy) subtracted from A, so that every
    particle of the initial lattice, vertices included, gets the same B and a uniform pressure
    leaves the lattice in equilibrium as in the symmetric form (docs/theory.md). */
static inline void kgc_lattice_correction(const struct model *M, int vertex, double y,
                                          double A[6]) {
  const double ih = M->k.inv_h, q[2] = {y * ih, (M->ly - y) * ih};
  for (int w = 0; w < 2; w++) {
    const int on = vertex && q[w] < 1e-9;
    const double dxx = on ? M->kgc_vxx : sph_lattice_table(M, M->lat_kxx, q[w]);
    const double dyy = on ? M->kgc_vyy : sph_lattice_table(M, M->lat_kyy, q[w]);
    A[0] -= dxx, A[3] -= dyy;
    if (M->dim == 3) A[5] -= dxx;
  }
}

/**
 * @brief The kgc correction matrix B = w A^-1 + (1 - w) I (as {xx, xy, xz, yy, yz, zz}; 2-D: the
 *        z entries of the identity) of a moment matrix A, with w from the lower Gershgorin bound
 *        lam = min_i (A_ii - sum_{j != i} |A_ij|) of its smallest eigenvalue: w = 0 for
 *        lam <= KGC_LAM0, 1 for lam >= KGC_LAM1, linear between. A cheap bound that needs no
 *        eigenvalues, and conservative: it blends only where A may be nearly singular.
 */
static inline void kgc_blend(int dim, const double A[6], double B[6]) {
  const double ax = fabs(A[1]), az = dim == 3 ? fabs(A[2]) : 0.0, ayz = dim == 3 ? fabs(A[4]) : 0.0;
  double lam = fmin(A[0] - ax - az, A[3] - ax - ayz);
  if (dim == 3) lam = fmin(lam, A[5] - az - ayz);
  const double w = fmin(1.0, fmax(0.0, (lam - KGC_LAM0) / (KGC_LAM1 - KGC_LAM0)));
  const double I[6] = {1.0, 0.0, 0.0, 1.0, 0.0, 1.0};
  if (w <= 0.0) {
    for (int k = 0; k < 6; k++) B[k] = I[k];
    return;
  }
  struct sym_solve f;
  sph_sym_factor(dim, A, &f);
  double c0[3], c1[3], c2[3];
  sph_sym_apply(&f, (const double[3]){1.0, 0.0, 0.0}, c0);
  sph_sym_apply(&f, (const double[3]){0.0, 1.0, 0.0}, c1);
  sph_sym_apply(&f, (const double[3]){0.0, 0.0, 1.0}, c2);
  const double L[6] = {
      c0[0], c0[1], dim == 3 ? c0[2] : 0.0, c1[1], dim == 3 ? c1[2] : 0.0, dim == 3 ? c2[2] : 1.0};
  for (int k = 0; k < 6; k++) B[k] = w * L[k] + (1.0 - w) * I[k];
}

/** kgc, pressure part: V_b p_b F_ab r_ab (p_b = pr2_b rho_b^2); B_a applies in the finish. */
static inline struct v3 pressure_kgc_pair(const struct pair *g, double vb, double pr2b, double rb) {
  const double s = vb * pr2b * rb * rb * g->f;
  return (struct v3){s * g->dx, s * g->dy, s * g->dz};
}

/** kgc, matrix part: V_b B_b F_ab r_ab (B_b of neighbour b); p_a applies in the finish. B by
    value: an array local to the force loop's body (omp simd) kept GCC from vectorising it. */
static inline struct v3 pressure_kgc_matrix_pair(const struct pair *g, double vb, struct sym3 b) {
  const double s = vb * g->f;
  return (struct v3){s * (b.xx * g->dx + b.xy * g->dy + b.xz * g->dz),
                     s * (b.xy * g->dx + b.yy * g->dy + b.yz * g->dz),
                     s * (b.xz * g->dx + b.yz * g->dy + b.zz * g->dz)};
}

/** B_a of particle a of P (kgc). */
static inline void pressure_kgc_of(const struct particles *P, size_t a, double b[6]) {
  b[0] = P->kgc_xx[a], b[1] = P->kgc_xy[a], b[2] = P->kgc_xz[a];
  b[3] = P->kgc_yy[a], b[4] = P->kgc_yz[a], b[5] = P->kgc_zz[a];
}

/** kgc: -(1/(gamma_a rho_a)) (p_a gb + B_a gc) of the sums gc, gb. */
static inline struct v3 pressure_kgc_acc(const struct particles *P, size_t a, struct v3 gc,
                                         struct v3 gb) {
  double b[6];
  pressure_kgc_of(P, a, b);
  const double ra = P->rho[a], pa = P->pr2[a] * ra * ra, s = -1.0 / (P->gam[a] * ra);
  return (struct v3){s * (pa * gb.x + b[0] * gc.x + b[1] * gc.y + b[2] * gc.z),
                     s * (pa * gb.y + b[1] * gc.x + b[3] * gc.y + b[4] * gc.z),
                     s * (pa * gb.z + b[2] * gc.x + b[4] * gc.y + b[5] * gc.z)};
}

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
  if (M->pgrad == PGRAD_KGC)
    return pressure_kgc_acc(
        P, a, (struct v3){s->gc.x + sv->gc.x, s->gc.y + sv->gc.y, s->gc.z + sv->gc.z},
        (struct v3){s->A.xx + sv->A.xx, s->A.xy + sv->A.xy, s->A.xz + sv->A.xz}); /* kgc_gb */
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
    *acc, with the wall values at its foot; mom1: the discrete first moment sum_b V_b y_ab F_ab
    (viscous_sums). kgc: (1/(gamma_a rho_a)) (p_a + p_s) W_as B_a n_s with the same weight W_as
    (the wall's B taken as B_a: the wall term of the B = I form, turned by B_a). Returns max over
    the walls of |grad gamma_as . v_a| for the wall time-step limit (Eq. 2.163), in every form. */
static inline double pressure_wall(const struct model *M, const struct particles *P,
                                   const struct walls *W, size_t a, double mom1, struct v3 *acc) {
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
      if (M->pgrad == PGRAD_KGC) { /* (1/(gamma_a rho_a)) (p_a + p_s) pw B_a n */
        const double ra = P->rho[a], t = ig / ra * (pa * ra * ra + ps) * pw * ny;
        acc->x += t * P->kgc_xy[a], acc->y += t * P->kgc_yy[a], acc->z += t * P->kgc_yz[a];
      } else
        acc->y += ig * rs * (pa + ps / (rs * rs)) * pw * ny;
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
  if (M->pgrad == PGRAD_KGC) return pressure_kgc_acc(P, a, s->gc, kgc_gb(s));
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
