/**
 * @file pair_terms.h
 * @brief The pair geometry and the pair terms, written once for a real type and included twice
 *        by pair.h: in double (the names below) and in float (suffix _f, sph.precision =
 *        mixed). No include guard, on purpose.
 *
 * Before inclusion: R is the real type, PF(name) the name of the instance, R_SQRT the square
 * root of R. Constants are written as (R)c so that the float instance does not promote to
 * double. Every function takes the separation in double and wraps it in double (pair.h); only
 * the wrapped separation, a few kernel radii long, is rounded to R.
 */

/** A vector in 3-D (z = 0 in 2-D). */
struct PF(v3) {
  R x, y, z;
};

/** A symmetric 3x3 tensor {xx, xy, xz, yy, yz, zz}. */
struct PF(sym3) {
  R xx, xy, xz, yy, yz, zz;
};

/** Geometry of a pair within the kernel support. */
struct PF(pair) {
  R dx, dy, dz; /*!< r_ab [m] */
  R r2, r;      /*!< |r_ab|^2 [m^2], |r_ab| [m] */
  R f;          /*!< F_ab = w'(r)/r [1/m^(dim+2)]; 0 outside the support */
};

/**
 * @brief Geometry of the pair (dx, dy, dz) = r_a - r_b before the periodic wrap.
 * @param K kernel; lx, lz periodic lengths; d3 nonzero in 3-D (dz = 0 otherwise)
 */
static inline struct PF(pair) PF(pair_geom)(const struct kernel *K, double lx, double lz, int d3,
                                            double dx, double dy, double dz) {
  struct PF(pair) g;
  g.dx = (R)pair_wrap(dx, lx, 0.5 * lx), g.dy = (R)dy;
  g.dz = (R)((d3 ? 1.0 : 0.0) * pair_wrap(dz, lz, 0.5 * lz)); /* branch-free: vectorises */
  g.r2 = g.dx * g.dx + g.dy * g.dy + g.dz * g.dz;
  g.r = R_SQRT(g.r2);
  const R t = (R)1 - (R)0.5 * g.r * (R)K->inv_h; /* thesis Eq. 2.63: (1 - q/2)^3 for F */
  const R tp = t > (R)0 ? t : (R)0;
  g.f = (R)K->ffac * tp * tp * tp;
  return g;
}

/** Kernel value w(r) of a pair inside the support (thesis Eq. 2.63). */
static inline R PF(pair_w)(const struct kernel *K, R r) {
  const R q = r * (R)K->inv_h, t = (R)1 - (R)0.5 * q;
  const R tp = t > (R)0 ? t : (R)0, t2 = tp * tp;
  return (R)K->wfac * t2 * t2 * ((R)1 + (R)2 * q);
}

/** Pressure gradient, symmetric form (thesis Eq. 3.17, particle part):
    m_b (p_a/rho_a^2 + p_b/rho_b^2) F_ab r_ab, to be multiplied by -1/gamma_a. */
static inline struct PF(v3) PF(term_pressure)(const struct PF(pair) * g, R mb, R pr2a, R pr2b) {
  const R s = mb * (pr2a + pr2b) * g->f;
  return (struct PF(v3)){s * g->dx, s * g->dy, s * g->dz};
}

/** Moment matrix of the first-order correction (thesis Eq. 2.88): -V_b F_ab r_ab (x) r_ab;
    its sum is A_a, with L_a = A_a^-1. */
static inline struct PF(sym3) PF(term_moment)(const struct PF(pair) * g, R vb) {
  const R vf = -vb * g->f;
  return (struct PF(sym3)){vf * g->dx * g->dx, vf * g->dx * g->dy, vf * g->dx * g->dz,
                           vf * g->dy * g->dy, vf * g->dy * g->dz, vf * g->dz * g->dz};
}

/** Corrected difference gradient of a scalar (thesis Eq. 2.90, k = 0, before L_a):
    V_b (f_b - f_a) F_ab r_ab. */
static inline struct PF(v3) PF(term_difference)(const struct PF(pair) * g, R vb, R dfba) {
  const R s = vb * dfba * g->f;
  return (struct PF(v3)){s * g->dx, s * g->dy, s * g->dz};
}

/** Morris' viscous operator (thesis Eq. 2.147, particle part, without nu / gamma_a):
    m_b (1/rho_a + 1/rho_b) F_ab r^2 / (r^2 + eta^2) u_ab. */
static inline struct PF(v3)
    PF(term_morris)(const struct PF(pair) * g, R mb, R inv_rhoa, R vb, R eta2, struct PF(v3) uab) {
  const R s = (mb * inv_rhoa + vb) * g->f * g->r2 / (g->r2 + eta2);
  return (struct PF(v3)){s * uab.x, s * uab.y, s * uab.z};
}

/** Violeau's viscous operator (thesis Eq. 2.100, particle part, without 1 / (gamma_a rho_a)):
    V_b mu_ab F_ab / (r^2 + eta^2) ((n + 2) (u_ab . r_ab) r_ab + r^2 u_ab), with mu_ab the mean
    dynamic viscosity of the pair (rho (nu + nu_r) with the eddy viscosity, or rho). */
static inline struct PF(v3) PF(term_violeau)(const struct PF(pair) * g, R vb, R mu_ab, R nplus2,
                                             R eta2, struct PF(v3) uab) {
  const R s = vb * mu_ab * g->f / (g->r2 + eta2);
  const R vr = nplus2 * (uab.x * g->dx + uab.y * g->dy + uab.z * g->dz);
  return (struct PF(v3)){s * (vr * g->dx + g->r2 * uab.x), s * (vr * g->dy + g->r2 * uab.y),
                         s * (vr * g->dz + g->r2 * uab.z)};
}

/** Volume diffusion of the continuity equation (thesis Eq. 3.34, 3.64, with varrho_ab of
    Eq. 3.61): V_b max(c_a, c_b) (rho_a - rho_b - rho0 g_y y_ab / c0^2) F_ab r; fluid pairs only,
    to be divided by xi. The density difference is formed by the caller in double. */
static inline R PF(term_diffusion)(const struct PF(pair) * g, R vb, R ca, R cb, R drho, R dgrav) {
  const R cab = ca > cb ? ca : cb;
  return vb * cab * (drho - dgrav * g->dy) * g->f * g->r;
}

/** Moments of the viscous normalisation and of the wall weights (docs/theory.md):
    V_b F_ab times r^2 (trace), y_ab^2 (wall-normal) and y_ab (discrete first moment). */
static inline struct PF(v3) PF(term_moments)(const struct PF(pair) * g, R vb) {
  const R vf = vb * g->f;
  return (struct PF(v3)){vf * g->r2, vf * g->dy * g->dy, vf * g->dy};
}

/** Violeau's wall moments of the x and z parts of the operator:
    V_b F_ab ((n+2) x_i^2 / (r^2 + eta^2) + 1) y_ab for i = x (.x) and i = z (.y); the second
    moments are these times y_ab. */
static inline struct PF(v3)
    PF(term_violeau_moments)(const struct PF(pair) * g, R vb, R nplus2, R eta2) {
  const R vf = vb * g->f, ir = (R)1 / (g->r2 + eta2);
  return (struct PF(v3)){vf * (nplus2 * g->dx * g->dx * ir + (R)1) * g->dy,
                         vf * (nplus2 * g->dz * g->dz * ir + (R)1) * g->dy, (R)0};
}
