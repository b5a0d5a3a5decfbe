/**
 * @file sph.h
 * @brief The SPH operators of the channel with unified semi-analytical plane walls:
 *        density (continuity with volume diffusion), wall values, and forces.
 */
#ifndef CHANSPH_SPH_H
#define CHANSPH_SPH_H

#include "eos.h"
#include "kernel.h"
#include "nbr.h"
#include "part.h"
#include "scene.h"
#include "wall.h"
#include "walllaw.h"

enum { LATTICE_KNOTS = 16, VIOLEAU_KNOTS = 128 };

/** Constants of the discretisation, derived once from the scene. */
struct model {
  int dim;           /*!< 2 or 3 */
  int viscous;       /*!< enum viscous_form */
  struct kernel k;   /*!< Wendland kernel */
  struct eos e;      /*!< Tait equation of state */
  double lx, ly, lz; /*!< domain [m]; ly = 2 delta */
  double dr, h;      /*!< spacing and smoothing length [m] */
  double nu;         /*!< kinematic viscosity [m^2/s] */
  double inv_xi;     /*!< 1 / xi of the volume diffusion [-] */
  /** the volume diffusion's pair length l_ab = diff_lr r_ab + diff_lc: (1, 0) for ferrand, (0,
      2 delta h xi) for delta_sph (term_diffusion.h) */
  double diff_lr, diff_lc;
  int diff_substeps;  /*!< sub-steps of the volume diffusion in a time step (sph_diffusion_substep)
                       */
  double damper_zeta; /*!< bulk viscosity zeta = alpha rho0 c0 h of the acoustic damper [Pa s] */
  double gy;          /*!< wall-normal body acceleration [m/s^2] */
  double wall_dmin;   /*!< delta r of Eq. 2.148 [m] */
  double eta2;        /*!< regularisation of r^2 in the viscous term [m^2] */
  int lap_norm;       /*!< enum laplacian_norm */
  int wall_weight;    /*!< enum wall_weight: weight of the wall shear term */
  int wall_pressure;  /*!< enum wall_pressure: weight of the pressure wall term */
  int pgrad;          /*!< enum pressure_gradient */
  int les;            /*!< eddy viscosity on (enum les_model) */
  int strain;         /*!< enum les_strain */
  int strain_lag; /*!< 1: the force loop forms the strain sums; nu_r, k_r apply one step later */
  int van_driest; /*!< damping on */
  double cs, delta_g, a_plus; /*!< C_S [-], Delta_G [m], A+ [-] */
  double cy;                  /*!< Yoshizawa C_Y [-]; 0 = off */
  struct nu_profile nu_prof;  /*!< les = LES_PROFILE: nu_r / nu against y / delta */
  struct wall_law_def law;    /*!< wall law of the wall shear term */
  int wall_tau;               /*!< wall stresses carried to the vertices (turb.h) */
  /** Violeau's operator: its wall-normal second moment int y^2 F ((n+2) x_t^2/r^2 + 1) dV over
      the half-space behind a wall at q = d/h, at q = 2 k / VIOLEAU_KNOTS [-] */
  double vio_m2[VIOLEAU_KNOTS + 1];
  int n_lat;                   /*!< knots of the lattice excess of the pressure wall weight */
  double lat_q[LATTICE_KNOTS]; /*!< their wall distances d/h, increasing, the last one 2 */
  double lat_e[LATTICE_KNOTS]; /*!< excess of sum_b V_b (r_ab . n) F_ab over |grad gamma| [1/m] */
  /** the same (signed, not clipped) for the particle shift's moment, whose pair weight has the
      anti-clustering factor 1 + R (w_ab / w(dr))^n (shift.h) [1/m] */
  double lat_s[LATTICE_KNOTS];
  /** kgc (term_pressure.h): the moment matrix of the initial lattice, fluid and vertex
      neighbours plus the analytic part behind the wall, minus its value far from the walls, in
      the tangential (xx = zz) and wall-normal (yy) directions at the layers lat_q; subtracted
      from A_a so that every particle of the lattice gets the same B (kgc_lattice_correction) */
  double lat_kxx[LATTICE_KNOTS], lat_kyy[LATTICE_KNOTS];
  double kgc_vxx, kgc_vyy; /*!< the same for the vertex row (q = 0) */
  int shifting;            /*!< enum shifting */
  int shift_velocity;      /*!< enum shift_velocity: what a shift does to the velocities */
  int wall_reflect;  /*!< 1: a particle that reaches a wall is reflected (else the run stops) */
  double shift_ch2;  /*!< C h^2 of delta r = -C h^2 grad C_a [m^2] */
  double shift_iwdr; /*!< 1 / w(dr), the anti-clustering term's reference [m^dim] */
  double shift_max;  /*!< largest shift per step [m] */
};

/** 1 if height y lies on or behind a wall (y <= 0 or y >= ly): a fluid particle there has
    crossed it (the health check stops the run, sph.wall_collision = reflect mirrors it). */
static inline int sph_at_wall(double y, double ly) {
  return y <= 0.0 || y >= ly;
}

/** Anti-clustering term of the particle shift (Skillen et al. 2013; Sun et al. 2017):
    R (w_ab / w(dr))^n with R = 0.2, n = 4. */
static inline double sph_anticluster(double w, double iwdr) {
  const double t = w * iwdr, t2 = t * t;
  return 0.2 * t2 * t2;
}

/** Per-step maxima from the force pass, for the time-step limits. */
struct force_info {
  double amax;  /*!< max |a| including the body forces [m/s^2] */
  double gvmax; /*!< max over particles and walls of |grad gamma_as . v_a| [1/s] */
  /** Input: if not NULL, receives per particle the x-acceleration the walls apply (wall shear
      term plus the viscous interaction with vertex particles) [m/s^2]; it gives the wall
      shear stress of the statistics (u_tau). Zero for particles away from the walls. */
  double *wall_ax;
  /** Input: if not NULL, receives per particle the parts of the x-acceleration (SX_LEN each,
      enum part_sx): the pair forces of the fluid neighbours by term and the walls' part; the
      momentum budget of the statistics (method of planes, docs/theory.md). */
  double *sx;
};

/** @brief Derive the model constants from the scene. */
void sph_model_init(struct model *M, const struct scene *s);

/**
 * @brief Tabulate, on the initial particle lattice (layers y = j dr, the vertex row at y = 0 with
 *        half volume), how much the discrete first moment sum_b V_b (y_a - y_b) F_ab of each
 *        layer within 2h of a wall exceeds |grad gamma|; used by the `lattice` pressure wall
 *        weight. Depends on dim, dr and h only, so a restart rebuilds the same table.
 * @param[in,out] M model (lat_q, lat_e, n_lat)
 */
void sph_lattice_excess_table(struct model *M);

/**
 * @brief Tabulate the wall moment of Violeau's operator (model.vio_m2) by Gauss-Legendre
 *        quadrature: the normalisation and the discrete wall weight of Eq. 2.100 in the
 *        channel (docs/theory.md, "Violeau's operator at a wall").
 * @param[in,out] M model
 */
void sph_violeau_table(struct model *M);

/** @brief A lattice table (lat_e or lat_s) at q = d/h: linear between the layers of the
           lattice, constant below the first layer, zero at q = 2. */
double sph_lattice_table(const struct model *M, const double *e, double q);

/** @brief Violeau's wall moment at q = d/h (linear in the table; 0 for q >= 2). */
double sph_violeau_moment(const struct model *M, double q);

/**
 * @brief Density update of thesis Eq. 3.64 from the kernel sums at the current positions:
 *        gamma^n rho^n = gamma^(n-1) rho^(n-1) + S^n - S^(n-1) + (dt / n_d) D^(n-1),
 *        with gamma of the plane walls in closed form; then pressure and sound speed (Eq. 2.11).
 *        n_d = sph.diffusion_substeps (1: the thesis); sph_diffusion_substep adds the rest.
 * @param[in] M model
 * @param[in,out] P particles (ksum, gam, rho, p, c of fluid particles)
 * @param[in] ksum_new kernel sums at the current positions (from nbr_build)
 * @param[in] dt the step that led here [s]; dt <= 0 only initialises S and gamma
 */
void sph_density(const struct model *M, struct particles *P, const double *ksum_new, double dt);

/**
 * @brief One sub-step of the volume diffusion at the current positions and densities:
 *        gamma_a rho_a += dts D_a (term_diffusion.h, the force pass's pair sum without the
 *        forces), then pressure and sound speed. The caller refreshes the ghosts' densities
 *        before and after (sph.diffusion_substeps: n_d - 1 of them after sph_density).
 * @param[in] M model
 * @param[in,out] P particles (ddiff: this sub-step's D_a; rho, p, c of fluid particles)
 * @param[in] nb neighbour list of the current positions
 * @param[in] dts the sub-step, dt / n_d [s]
 */
void sph_diffusion_substep(const struct model *M, struct particles *P, const struct nbr *nb,
                           double dts);

/**
 * @brief Wall values of the vertex particles by Shepard interpolation of the fluid:
 *        rho_v (thesis Eq. 2.136-2.137) and p_v / rho_v with the wall-normal body force
 *        (Eq. 2.143, 3.63; Ferrand Eq. 30); copied to the wall lattice.
 * @param[in] M model
 * @param[in,out] P particles (rho, p of vertex particles)
 * @param[in] nb neighbour list
 * @param[out] W wall lattice values
 */
void sph_walls(const struct model *M, struct particles *P, const struct nbr *nb, struct walls *W);

/**
 * @brief LES with C_Y > 0 (turb.h, step 4): the pressure the forces read becomes p + 2/3 rho k_r
 *        (thesis Eq. 5.42): p/rho^2 of fluid and vertex particles (k_r of a vertex by Shepard
 *        interpolation) and the wall pressure; P->p stays the equation-of-state pressure. With
 *        sph_density() and sph_walls() this is every place that sets a pressure. The caller then
 *        refreshes pr2 and the wall pressure at the ghosts.
 */
void sph_kr_pressure(const struct model *M, struct particles *P, const struct nbr *nb,
                     struct walls *W);

/**
 * @brief Shepard sums at vertex s over its fluid neighbours (the first nfluid of its list):
 *        returns alpha = sum_b V_b w_bs and sets out[k] = sum_b V_b w_bs f_k,b for the nf <= 2
 *        fields f (Ferrand Eq. 38 without the 1/alpha).
 */
double sph_vertex_sums(const struct model *M, const struct particles *P, const struct nbr *nb,
                       size_t s, int nf, const double *const *f, double *out);

/**
 * @brief Accelerations of the fluid particles (pressure gradient Grad^{gamma,1} of thesis
 *        Eq. 3.17, viscous term Eq. 2.147 or 2.100 with the wall shear term, wall-normal body
 *        force) and the volume-diffusion sum D of Eq. 3.64.
 * @param[in] M model
 * @param[in,out] P particles (ax, ay, az, ddiff)
 * @param[in] nb neighbour list
 * @param[in] W wall values
 * @param[in] fx current driving acceleration, only for the time-step limit [m/s^2]
 * @param[out] info maxima for the time-step limits
 */
void sph_forces(const struct model *M, struct particles *P, const struct nbr *nb,
                const struct walls *W, double fx, struct force_info *info);

/**
 * @brief sph.pressure_gradient = kgc: the correction matrix B_a of every owned particle (fluid
 *        and vertex) from its list and the analytic part behind the walls, blended towards the
 *        identity where ill-conditioned (kgc.c, term_pressure.h); after sph_walls (the volumes),
 *        before the force pass. The caller then refreshes the ghosts' copies (PR_KGC).
 * @param[in] M model
 * @param[in,out] P particles (kgc_xx ... kgc_zz of slots 0 .. n-1)
 * @param[in] nb neighbour list
 */
void sph_kgc_matrices(const struct model *M, struct particles *P, const struct nbr *nb);
/**
 * @brief The conservative split of the budget parts (budget_pairs.c): after a sampled force pass
 *        (P->sx_live) and the refresh PR_BUDGET, replaces the pair parts of P->sx by the
 *        antisymmetric parts of the fluid pair forces, (f_ab - f_ba)/2, and adds the rest to
 *        the walls' part and to wall_ax (if not NULL), and stores the configurational part of
 *        the pressure part in P->sxn (the pressure noise); the accelerations are not changed.
 */
void sph_budget_pairs(const struct model *M, struct particles *P, const struct nbr *nb,
                      double *wall_ax);

/** A wall seen from a fluid particle within the kernel support of it (sph_wall_near). */
struct wall_near {
  double d;  /*!< distance to the wall [m] */
  double q;  /*!< d / h [-] */
  double dg; /*!< |grad gamma_as| [1/m] */
  double ny; /*!< y of the inward normal: 1 at y = 0, -1 at y = 2 delta */
};

/** Wall `wall` (0: y = 0, 1: y = 2 delta) as seen from height ya: returns 0 if it is at least
    2h away (no wall term), else 1 with its distance, |grad gamma_as| and normal in *w. */
static inline int sph_wall_near(const struct model *M, double ya, int wall, struct wall_near *w) {
  const double ih = M->k.inv_h;
  w->d = wall ? M->ly - ya : ya;
  w->q = w->d * ih;
  if (w->q >= 2.0) return 0;
  w->dg = wall_dgamma_of(&M->k, w->q) * ih;
  w->ny = wall ? -1.0 : 1.0;
  return 1;
}

/** Foot of a particle on the wall lattice: corner indices and weights of the (bi)linear
    interpolation (the vertices sit at x = (i + 1/2) dr, z = (k + 1/2) dr). */
struct foot {
  size_t c00, c01, c10, c11;
  double tx, tz;
};

/** floor(v) for |v| < 2^31, by truncation: the loops that call sph_foot vectorise with it (GCC
    vectorises floor() only without -ftrapping-math). */
static inline double sph_floor(double v) {
  const double t = (double)(int)v;
  return t > v ? t - 1.0 : t;
}

/** The floored remainder i mod n in [0, n) of an integer-valued i, in double arithmetic (exact for
    |i| < 2^31): no integer division, so that the loops that call sph_foot vectorise. */
static inline int sph_wrap_index(double i, int n) {
  return (int)(i - (double)n * sph_floor(i / (double)n));
}

/** sph_foot from the values it needs (dim, the spacing dr, the lattice nx x nz), so that a loop
    with a constant dim and these in registers vectorises. */
static inline struct foot sph_foot_of(int dim, double dr, int nx, int nz, int wall, double x,
                                      double z) {
  const double fx = x / dr - 0.5;
  const double ix = sph_floor(fx), tx = fx - ix;
  const int i0 = sph_wrap_index(ix, nx), i1 = i0 + 1 < nx ? i0 + 1 : 0;
  const size_t off = (size_t)wall * nx * nz;
  struct foot f = {off + i0, off + i0, off + i1, off + i1, tx, 0.0};
  if (dim == 2) return f;
  const double fz = z / dr - 0.5;
  const double iz = sph_floor(fz), tz = fz - iz;
  const int k0 = sph_wrap_index(iz, nz), k1 = k0 + 1 < nz ? k0 + 1 : 0;
  f.c00 = off + i0 * (size_t)nz + k0, f.c01 = off + i0 * (size_t)nz + k1;
  f.c10 = off + i1 * (size_t)nz + k0, f.c11 = off + i1 * (size_t)nz + k1;
  f.tz = tz;
  return f;
}

static inline struct foot sph_foot(const struct model *M, const struct walls *W, int wall, double x,
                                   double z) {
  return sph_foot_of(M->dim, M->dr, W->nx, W->nz, wall, x, z);
}

/** The (bi)linear interpolation of the vertex values v at a foot, in dim dimensions. */
static inline double sph_foot_interp(int dim, const struct foot *f, const double *v) {
  if (dim == 2) return (1.0 - f->tx) * v[f->c00] + f->tx * v[f->c10];
  return (1.0 - f->tx) * ((1.0 - f->tz) * v[f->c00] + f->tz * v[f->c01]) +
         f->tx * ((1.0 - f->tz) * v[f->c10] + f->tz * v[f->c11]);
}

static inline double sph_foot_value(const struct model *M, const struct foot *f, const double *v) {
  return sph_foot_interp(M->dim, f, v);
}

/**
 * @brief Wall density and pressure at the foot of a particle on a wall: bilinear (3-D) or
 *        linear (2-D) interpolation of the vertex values, the generalisation of thesis
 *        Eq. 2.138 used for the per-segment boundary sums (see docs/theory.md).
 * @param[out] rho wall density [kg/m^3]
 * @param[out] p wall pressure [Pa]
 */
void sph_wall_values(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *p);

/** A symmetric 2x2 or 3x3 matrix factorised for sph_sym_apply: its cofactors and determinant
    (Cramer's rule), or the isotropic fallback of a degenerate matrix. */
struct sym_solve {
  int dim;     /*!< 2 or 3 */
  int deg;     /*!< degenerate: x = dim g / trace(A) (0 if the trace is not positive) */
  double det;  /*!< determinant */
  double tr;   /*!< trace */
  double c[6]; /*!< cofactors {xx, xy, xz, yy, yz, zz} (2-D: {yy, xy, xx}) */
};

/** @brief Factorise a symmetric A (stored as {xx, xy, xz, yy, yz, zz}) for sph_sym_apply. */
void sph_sym_factor(int dim, const double A[6], struct sym_solve *f);

/** @brief x = A^-1 g from the factorisation of A (the same arithmetic as sph_solve_sym). */
void sph_sym_apply(const struct sym_solve *f, const double g[3], double x[3]);

/**
 * @brief Solve A x = g for a symmetric positive definite A (2x2 or 3x3, stored as
 *        {xx, xy, xz, yy, yz, zz}): applies L = A^-1 of thesis Eq. 2.88. A degenerate A (an
 *        isolated particle) falls back to the isotropic dim / trace(A). sph_sym_factor and
 *        sph_sym_apply: the same in two steps, for several right-hand sides.
 */
void sph_solve_sym(int dim, const double A[6], const double g[3], double x[3]);

/** @brief Wall density and wall stress rho_s u_tau u_tau (x, z) at the foot of a particle, with
           the same interpolation as sph_wall_values (one foot for the three fields). */
void sph_wall_stress(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *tx, double *tz);

#endif
