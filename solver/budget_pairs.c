/**
 * @file budget_pairs.c
 * @brief sph_budget_pairs (sph.h): the conservative split of the fluid pair forces for the
 *        momentum budget (docs/theory.md, "Momentum at the walls").
 *
 * The force on particle a from fluid neighbour b, f_ab = m_a c_a T(a, b), carries per-particle
 * factors c_a (1/gamma_a of the pressure gradient; the viscous normalisation kappa_a/gamma_a),
 * so f_ab + f_ba != 0 where they differ: within 2h of a wall, where gamma falls to 1/2. Each
 * pair force is split into its antisymmetric part (f_ab - f_ba)/2, which conserves momentum
 * pair by pair, and the rest (f_ab + f_ba)/2, which is nonzero only where the factors differ.
 * The budget keeps the first as the pair force of its term and gives the rest to the walls:
 * summed over the fluid it is the share of the wall stress that the renormalised operators
 * deliver through the pairs of the wall layer (it does not vanish as dr -> 0; docs/theory.md).
 * The accelerations themselves are untouched: this runs on sampled steps only, after the force
 * pass, with the neighbours' factors refreshed (PR_BUDGET).
 *
 * Determinism: each particle's sums run over its own neighbour list in list order.
 */
#include <math.h>

#include "pair_loop.h"
#include "sph.h"
#include "term_pressure.h"
#include "term_viscous.h"
#include "timers.h"

/** The conservative parts of particle a's fluid pair forces per unit mass of a. */
struct cons_parts {
  struct v3 p;  /*!< pressure (symmetric or kgc form) */
  struct v3 pn; /*!< its configurational part (the pressure noise): symmetric form,
                     -p_a/rho_a^2 sum_b (1/gamma_a + 1/gamma_b) m_b grad W; kgc, see below */
  struct v3 mu; /*!< molecular viscous */
  struct v3 m;  /*!< eddy-viscous (LES) */
};

/* The conservative parts of fluid particle a for the operator `op` (a constant: one loop per
   operator). Each viscous pair term is evaluated once: reversing a pair turns r_ab and u_ab
   into -r_ab and -u_ab, so Violeau's T(b, a) = -(V_a / V_b) T(a, b) (mu_ab symmetric) and
   Morris' T(b, a) = -(m_a / rho_b + V_a) / (m_b / rho_a + V_b) T(a, b); then
   m_a c_a T(a, b) - m_b c_b T(b, a) = t (w_a c_a + w_b c_b) with the common factor t and the
   weights w of each end.
   The kgc pressure gradient (`kgc`, a constant too) has the pair force
   f_ab = -(V_a V_b / gamma_a) (p_a B_b + p_b B_a) grad W_ab, so its antisymmetric part per unit
   mass of a is -(1/(2 rho_a)) (1/gamma_a + 1/gamma_b) V_b (p_a B_b + p_b B_a) grad W_ab. Its
   pressure noise is the part that a consistent gradient would give zero for: the same pair force
   with p_b replaced by p_a, -(p_a/(2 rho_a)) sum_b (1/gamma_a + 1/gamma_b) V_b (B_a + B_b)
   grad W_ab, p_a times the zeroth-order (configurational) error of the corrected kernel; the
   rest, B_a sum_b V_b (p_b - p_a) grad W_ab (with the gamma weights), is the corrected
   first-order difference, exact for a linear pressure where B_a = A_a^-1 (w = 1). */
enum { OP_MORRIS, OP_VIOLEAU, OP_LES };
static inline __attribute__((always_inline)) struct cons_parts cons_parts_op(
    const struct model *M, const struct particles *P, const struct nbr *nb, size_t a, const int op,
    const int kgc) {
  const struct pair_frame F = pair_frame_of(M);
  const int32_t *restrict nl = pair_list(nb, a);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict u = P->u, *restrict v = P->v, *restrict w = P->w;
  const double *restrict m = P->m, *restrict rho = P->rho, *restrict vol = P->vol;
  const double *restrict pr2 = P->pr2, *restrict gam = P->gam;
  const double *restrict vfx = P->vfx, *restrict vfy = P->vfy, *restrict vfz = P->vfz;
  const double *restrict nur = op == OP_LES ? P->nur : P->rho; /* read only with LES */
  const double xa = x[a], ya = y[a], za = z[a], ua = u[a], va = v[a], wa = w[a];
  const double ma = m[a], ra = rho[a], pa = pr2[a], iga = 1.0 / gam[a], vola = vol[a];
  const double nu = M->nu, np2 = M->dim + 2.0, eta2 = M->eta2;
  const double nura = op == OP_LES ? nur[a] : 0.0;
  const double cax = vfx[a], cay = vfy[a], caz = vfz[a];
  double px = 0, py = 0, pz = 0, vx = 0, vy = 0, vz = 0, tx = 0, ty = 0, tz = 0;
  double nx = 0, ny = 0, nz = 0, kx = 0, ky = 0, kz = 0;
  const double *restrict bxx = P->kgc_xx, *restrict bxy = P->kgc_xy, *restrict bxz = P->kgc_xz;
  const double *restrict byy = P->kgc_yy, *restrict byz = P->kgc_yz, *restrict bzz = P->kgc_zz;
  const int nf = nb->nfluid[a];
#pragma omp simd reduction(+ : px, py, pz, vx, vy, vz, tx, ty, tz, nx, ny, nz, kx, ky, kz)
  for (int j = 0; j < nf; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    const double ig = iga + 1.0 / gam[b];
    if (kgc) { /* p: sum ig V_b p_b F r; n: sum ig V_b B_b F r; k: sum ig V_b F r */
      const struct v3 pp = pressure_kgc_pair(&g, vol[b], pr2[b], rho[b]);
      px += ig * pp.x, py += ig * pp.y, pz += ig * pp.z;
      const struct sym3 bb = {bxx[b], bxy[b], bxz[b], byy[b], byz[b], bzz[b]};
      const struct v3 pb = pressure_kgc_matrix_pair(&g, vol[b], bb);
      nx += ig * pb.x, ny += ig * pb.y, nz += ig * pb.z;
      const double vf = ig * vol[b] * g.f;
      kx += vf * g.dx, ky += vf * g.dy, kz += vf * g.dz;
    } else {
      const struct v3 pp = pressure_pair(&g, m[b], pa, pr2[b]); /* times -(1/ga + 1/gb) */
      px += ig * pp.x, py += ig * pp.y, pz += ig * pp.z;
      const struct v3 pc = pressure_pair(&g, m[b], pa, pa); /* its configurational part */
      nx += ig * pc.x, ny += ig * pc.y, nz += ig * pc.z;
    }
    const struct v3 uab = {ua - u[b], va - v[b], wa - w[b]};
    double wa_, wb_; /* the weights of the two ends */
    struct v3 t;     /* the common factor */
    if (op == OP_MORRIS) {
      t = viscous_morris_pair(&g, 1.0, 1.0, 0.0, eta2, uab); /* F r^2 / (r^2 + eta^2) u_ab */
      wa_ = ma * (m[b] / ra + vol[b]), wb_ = m[b] * (ma / rho[b] + vola);
    } else { /* Violeau; LES: mu = rho (nu + nu_r), prefactor 1/(gamma rho) */
      t = viscous_violeau_pair(&g, 1.0, 1.0, np2, eta2, uab); /* without V_b mu_ab */
      wa_ = ma * vol[b], wb_ = m[b] * vola;
    }
    const double mu0 = op == OP_MORRIS ? 1.0 : 0.5 * (ra + rho[b]) * (op == OP_LES ? nu : 1.0);
    const double mx = mu0 * t.x * (wa_ * cax + wb_ * vfx[b]);
    const double my = mu0 * t.y * (wa_ * cay + wb_ * vfy[b]);
    const double mz = mu0 * t.z * (wa_ * caz + wb_ * vfz[b]);
    vx += mx, vy += my, vz += mz;
    if (op == OP_LES) { /* the eddy-viscous rest: mu_ab of the eddy viscosity alone */
      const double mr = 0.5 * (ra * nura + rho[b] * nur[b]) / mu0;
      tx += mr * mx, ty += mr * my, tz += mr * mz;
    }
  }
  const double h = 0.5 / ma;
  if (kgc) { /* -(1/(2 rho_a)) (p_a n + B_a p) and its noise -(p_a/(2 rho_a)) (n + B_a k) */
    double B[6];
    pressure_kgc_of(P, a, B);
    const double pf = pa * ra * ra, s = -0.5 / ra;
    const struct v3 bp = {B[0] * px + B[1] * py + B[2] * pz, B[1] * px + B[3] * py + B[4] * pz,
                          B[2] * px + B[4] * py + B[5] * pz};
    const struct v3 bk = {B[0] * kx + B[1] * ky + B[2] * kz, B[1] * kx + B[3] * ky + B[4] * kz,
                          B[2] * kx + B[4] * ky + B[5] * kz};
    return (struct cons_parts){{s * (pf * nx + bp.x), s * (pf * ny + bp.y), s * (pf * nz + bp.z)},
                               {s * pf * (nx + bk.x), s * pf * (ny + bk.y), s * pf * (nz + bk.z)},
                               {h * vx, h * vy, h * vz},
                               {h * tx, h * ty, h * tz}};
  }
  return (struct cons_parts){{-0.5 * px, -0.5 * py, -0.5 * pz},
                             {-0.5 * nx, -0.5 * ny, -0.5 * nz},
                             {h * vx, h * vy, h * vz},
                             {h * tx, h * ty, h * tz}};
}

/* The conservative parts of fluid particle a (CHANSPH_CLONES: one loop per instruction set). */
static CHANSPH_CLONES struct cons_parts cons_parts_of(const struct model *M,
                                                      const struct particles *P,
                                                      const struct nbr *nb, size_t a) {
  const int op = M->les ? OP_LES : M->viscous == VISCOUS_VIOLEAU ? OP_VIOLEAU : OP_MORRIS;
  if (M->pgrad == PGRAD_KGC) {
    if (op == OP_LES) return cons_parts_op(M, P, nb, a, OP_LES, 1);
    if (op == OP_VIOLEAU) return cons_parts_op(M, P, nb, a, OP_VIOLEAU, 1);
    return cons_parts_op(M, P, nb, a, OP_MORRIS, 1);
  }
  if (op == OP_LES) return cons_parts_op(M, P, nb, a, OP_LES, 0);
  if (op == OP_VIOLEAU) return cons_parts_op(M, P, nb, a, OP_VIOLEAU, 0);
  return cons_parts_op(M, P, nb, a, OP_MORRIS, 0);
}

void sph_budget_pairs(const struct model *M, struct particles *P, const struct nbr *nb,
                      double *wall_ax) {
  timer_push("budget");
  const int corrected = M->pgrad == PGRAD_CORRECTED;
#pragma omp parallel for schedule(dynamic, 256)
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    const struct cons_parts c = cons_parts_of(M, P, nb, a);
    const double p[3] = {c.p.x, c.p.y, c.p.z}, mu[3] = {c.mu.x, c.mu.y, c.mu.z};
    const double mo[3] = {c.m.x, c.m.y, c.m.z};
    for (int k = 0; k < 3; k++) { /* components x, y, z */
      double *sx = P->sx + a * SX_STRIDE + k * SX_LEN;
      /* the corrected gradient is not antisymmetric anywhere (its L_a, Eq. 2.88): kept whole */
      const double cp = corrected ? sx[SX_PRESSURE] : p[k];
      const double rest = sx[SX_PRESSURE] + sx[SX_VISCOUS] + sx[SX_MODEL] - cp - mu[k] - mo[k];
      sx[SX_PRESSURE] = cp, sx[SX_VISCOUS] = mu[k], sx[SX_MODEL] = mo[k];
      sx[SX_WALL] += rest;
      if (wall_ax && k == 0) wall_ax[a] += rest;
      /* the pressure noise, of the symmetric and kgc forms (cons_parts_op) */
      if (P->sxn)
        P->sxn[3 * a + k] = corrected ? 0.0 : (k == 0 ? c.pn.x : k == 1 ? c.pn.y : c.pn.z);
    }
  }
  timer_pop();
}
