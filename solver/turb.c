/** @file turb.c @brief Implementation of turb.h. */
#include "turb.h"

#include <math.h>
#include <omp.h>
#include <string.h>

#include "pair_loop.h"
#include "records.h"
#include "term_gradient.h"
#include "timers.h"
#include "wall.h"

double turb_van_driest(double yplus, double a_plus) {
  return -expm1(-yplus / a_plus); /* 1 - exp(-y+/A+) */
}

/** S = (2 S:S)^(1/2) of the velocity gradient G, S = (G + G^T)/2. */
static double strain_rate(int dim, double G[3][3]) {
  double s2 = 0.0;
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) {
      const double sij = 0.5 * (G[i][j] + G[j][i]);
      s2 += 2.0 * sij * sij;
    }
  return sqrt(s2);
}

double turb_strain_gradient(int dim, const double A[6], const double B[9]) {
  double G[3][3];
  for (int i = 0; i < 3; i++) sph_solve_sym(dim, A, B + 3 * i, G[i]); /* row i of B L */
  return strain_rate(dim, G);
}

double turb_q_gradient(int dim, const double A[6], const double B[9]) {
  double G[3][3], q = 0.0;
  for (int i = 0; i < 3; i++) sph_solve_sym(dim, A, B + 3 * i, G[i]); /* row i of B L */
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) q -= 0.5 * G[i][j] * G[j][i]; /* (W:W - S:S) / 2 */
  return q;
}

/** Positive root of S^3 - a S - b = 0 (a, b >= 0): the Violeau-Issa estimate solved for S
    (docs/theory.md). It lies in [max(sqrt(a), cbrt(b)), sqrt(a) + cbrt(b)]; Newton from the
    upper end decreases monotonically (the cubic is convex and increasing there). */
static double strain_cubic(double a, double b) {
  const double lo = fmax(sqrt(a), cbrt(b));
  double s = sqrt(a) + cbrt(b);
  if (!(s > 0.0)) return 0.0;
  for (int it = 0; it < 100; it++) {
    const double g = s * s * s - a * s - b, dg = 3.0 * s * s - a;
    if (!(g > 0.0) || !(dg > 0.0)) break;
    const double sn = s - g / dg;
    if (!(sn < s)) break;
    s = sn < lo ? lo : sn;
    if (g <= 1e-15 * s * s * s) break;
  }
  return s;
}

/** Distance to the nearest wall and its index (0: y = 0, 1: y = 2 delta). */
static inline double nearest_wall(const struct model *M, double y, int *wall) {
  const double top = M->ly - y;
  *wall = top < y;
  return *wall ? top : y;
}

/** The damped Smagorinsky length squared l_S^2 = (C_S Delta_G D)^2 of fluid particle a and the
    damping D (thesis Eq. 5.47, 5.50), with y+ from the local friction velocity at the foot on
    the nearest wall; *d and *utau2: its wall distance and u_tau^2 there. */
static double smagorinsky_length2(const struct model *M, const struct particles *P,
                                  const struct walls *W, size_t a, double *damp_out, double *d,
                                  double *utau2) {
  int wall;
  *d = nearest_wall(M, P->y[a], &wall);
  double damp = 1.0, rs, tsx, tsz;
  sph_wall_stress(M, W, wall, P->x[a], P->z[a], &rs, &tsx, &tsz);
  *utau2 = sqrt(tsx * tsx + tsz * tsz) / rs;
  if (M->van_driest) damp = turb_van_driest(*d * sqrt(*utau2) / M->nu, M->a_plus);
  *damp_out = damp;
  const double dg2 = M->delta_g * M->delta_g;
  return M->cs * M->cs * dg2 * damp * damp; /* l_S^2 */
}

/** nu_r = l_S^2 S and k_r = 2 C_Y (Delta_G D S)^2 (thesis Eq. 5.47, 5.49) of strain S. */
static inline void smagorinsky(const struct model *M, double ls2, double damp, double S,
                               double *nur, double *kr) {
  const double dg2 = M->delta_g * M->delta_g;
  *nur = ls2 * S;
  *kr = M->cy > 0.0 ? 2.0 * M->cy * dg2 * damp * damp * S * S : 0.0;
}

/** S of turb_strain_gradient with L_a = A^-1 formed once (one division instead of a solve per
    row; the same fallback for a degenerate A) from the sums of entry i of a chunk (A in
    ab[0..5][i], B in ab[6..14][i]): the force loop's per-particle cost. Written with selects
    instead of branches, for a constant dim, so that the loop over the chunk vectorises; the
    same operations in the same order as the branches would do (C11: no contraction), so the
    vector and scalar paths give the same bits. */
static inline __attribute__((always_inline)) double strain_inverse(const int dim,
                                                                   const double ab[][TURB_CHUNK],
                                                                   int i) {
  double L[3][3] = {{0}};
  if (dim == 2) {
    const double a = ab[0][i], b = ab[1][i], d = ab[3][i];
    const double det = a * d - b * b, tr = a + d, id = 1.0 / det;
    const int deg = !(fabs(det) > 1e-12 * tr * tr);
    const double iso = tr > 0 ? 2.0 / tr : 0.0;
    L[0][0] = deg ? iso : d * id, L[0][1] = L[1][0] = deg ? 0.0 : -b * id;
    L[1][1] = deg ? iso : a * id;
  } else {
    const double a = ab[0][i], b = ab[1][i], c = ab[2][i], d = ab[3][i], e = ab[4][i];
    const double f = ab[5][i];
    const double c0 = d * f - e * e, c1 = c * e - b * f, c2 = b * e - c * d;
    const double det = a * c0 + b * c1 + c * c2, tr = a + d + f, id = 1.0 / det;
    const int deg = !(fabs(det) > 1e-12 * tr * tr * tr);
    const double iso = tr > 0 ? 3.0 / tr : 0.0;
    L[0][0] = deg ? iso : c0 * id, L[0][1] = L[1][0] = deg ? 0.0 : c1 * id;
    L[0][2] = L[2][0] = deg ? 0.0 : c2 * id;
    L[1][1] = deg ? iso : (a * f - c * c) * id,
    L[1][2] = L[2][1] = deg ? 0.0 : (b * c - a * e) * id;
    L[2][2] = deg ? iso : (a * d - b * b) * id;
  }
  double G[3][3];
  for (int r = 0; r < 3; r++)
    for (int j = 0; j < 3; j++)
      G[r][j] =
          ab[6 + 3 * r][i] * L[0][j] + ab[7 + 3 * r][i] * L[1][j] + ab[8 + 3 * r][i] * L[2][j];
  return strain_rate(dim, G);
}

/** turb_model_chunk for a constant dim: three loops over the chunk, the middle one scalar. */
static inline __attribute__((always_inline)) void model_chunk(
    const struct model *M, const struct particles *P, const struct walls *W, size_t a0, int n,
    const double ab[][TURB_CHUNK], double *restrict nur, double *restrict kr, const int dim) {
  const double *restrict x = P->x + a0, *restrict y = P->y + a0, *restrict z = P->z + a0;
  const uint8_t *restrict kind = P->kind + a0;
  const double nu = M->nu, a_plus = M->a_plus, cs = M->cs, cy = M->cy;
  const double dg2 = M->delta_g * M->delta_g, dr = M->dr;
  const int nx = W->nx, nz = W->nz;
  const double *restrict wrho = W->rho, *restrict wtx = W->tx, *restrict wtz = W->tz;
  double damp[TURB_CHUNK];
  /* y+ from the local friction velocity at the foot on the nearest wall (smagorinsky_length2):
     the foot indices are arithmetic and its values gathers, so this loop vectorises */
#pragma omp simd
  for (int i = 0; i < n; i++) {
    int wall;
    const double d = nearest_wall(M, y[i], &wall);
    const struct foot f = sph_foot_of(dim, dr, nx, nz, wall, x[i], z[i]);
    const double rs = sph_foot_interp(dim, &f, wrho), tsx = sph_foot_interp(dim, &f, wtx);
    const double tsz = sph_foot_interp(dim, &f, wtz);
    const double utau2 = sqrt(tsx * tsx + tsz * tsz) / rs;
    damp[i] = d * sqrt(utau2) / nu; /* y+, the damping below */
  }
  /* the damping: expm1 of libm, particle by particle, the same for every particle whatever
     the path of the other loops */
  for (int i = 0; i < n; i++) damp[i] = M->van_driest ? turb_van_driest(damp[i], a_plus) : 1.0;
#pragma omp simd
  for (int i = 0; i < n; i++) {
    const double S = strain_inverse(dim, ab, i), dm = damp[i];
    /* l_S^2 of smagorinsky_length2 and nu_r, k_r of smagorinsky(), written out with the
       model's constants in registers: calling those two here stops the loop vectorising */
    const double ls2 = cs * cs * dg2 * dm * dm;
    const int fluid = kind[i] == KIND_FLUID;
    nur[i] = fluid ? ls2 * S : 0.0;
    kr[i] = fluid && cy > 0.0 ? 2.0 * cy * dg2 * dm * dm * S * S : 0.0;
  }
}

CHANSPH_CLONES void turb_model_chunk(const struct model *M, const struct particles *P,
                                     const struct walls *W, size_t a0, int n,
                                     const double ab[][TURB_CHUNK], double *nur, double *kr) {
  if (M->dim == 3)
    model_chunk(M, P, W, a0, n, ab, nur, kr, 3);
  else
    model_chunk(M, P, W, a0, n, ab, nur, kr, 2);
}

void turb_advance(struct particles *P) {
  double *t = P->nur;
  P->nur = P->nur_next, P->nur_next = t;
  t = P->kr, P->kr = P->kr_next, P->kr_next = t;
  P->nur_live = 1;
}

/** Violeau-Issa sum of particle a (thesis Eq. 5.48 without its factor 1 / (gamma_a rho_a)):
    -sum_b V_b (rho_a + rho_b)/2 |u_ab|^2 F_ab over its whole list. */
static CHANSPH_CLONES double violeau_issa_sum(const struct model *M, const struct pair_view *V,
                                              const struct nbr *nb, size_t a) {
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = V->f[REC_X], *restrict y = V->f[REC_Y], *restrict z = V->f[REC_Z];
  const double *restrict u = V->f[REC_U], *restrict v = V->f[REC_V], *restrict w = V->f[REC_W];
  const double *restrict vol = V->f[REC_VOL], *restrict rho = V->f[REC_RHO];
  const int32_t *restrict nl = pair_list(nb, a);
  const double xa = x[a], ya = y[a], za = z[a], ua = u[a], va = v[a], wa = w[a], ra = rho[a];
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (int j = 0; j < nb->count[a]; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    const double ux = ua - u[b], uy = va - v[b], uz = wa - w[b];
    sum -= vol[b] * 0.5 * (ra + rho[b]) * (ux * ux + uy * uy + uz * uz) * g.f;
  }
  return sum;
}

/* turb_wall_law: the wall-law stress of the near-wall fluid particles (from each
   particle's own values: the ghosts compute theirs too) and its Shepard interpolation to the
   vertices, rho_s u_tau u_tau = (1/alpha) sum_b V_b rho_b u_tau,b u_tau,b w_bs (Ferrand
   Eq. 38). */
static void wall_law_stresses(const struct model *M, struct particles *P, const struct nbr *nb,
                              struct walls *W) {
  const double two_h = 2.0 * M->h, nu = M->nu;
  const double *restrict y = P->y;
  const double *restrict u = P->u, *restrict w = P->w, *restrict rho = P->rho;
  const uint8_t *restrict kind = P->kind;
  double *restrict twx = P->twx, *restrict twz = P->twz;
  const size_t n_all = P->n + P->n_ghost;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < n_all; a++) {
    twx[a] = twz[a] = 0.0;
    if (kind[a] != KIND_FLUID) continue;
    int wall;
    const double d = nearest_wall(M, y[a], &wall);
    if (d >= two_h) continue;
    const double ut = sqrt(u[a] * u[a] + w[a] * w[a]);
    if (!(ut > 0.0)) continue;
    const double utau = wall_law_utau(&M->law, ut, d > M->wall_dmin ? d : M->wall_dmin, nu);
    const double s = rho[a] * utau * utau / ut; /* rho_a u_tau,a u_tau,a of Ferrand Eq. 38 */
    twx[a] = s * u[a], twz[a] = s * w[a];
  }
  const double *tw[2] = {P->twx, P->twz};
#pragma omp parallel for schedule(static)
  for (size_t s = 0; s < P->n; s++) {
    if (kind[s] != KIND_VERTEX) continue;
    double sum[2];
    const double alpha = sph_vertex_sums(M, P, nb, s, 2, tw, sum);
    const size_t slot = part_vertex_slot(P, P->id[s]);
    W->tx[slot] = alpha > 0.0 ? sum[0] / alpha : 0.0;
    W->tz[slot] = alpha > 0.0 ? sum[1] / alpha : 0.0;
  }
}

void turb_q_criterion(const struct model *M, const struct particles *P, const struct nbr *nb,
                      double *q) {
  const struct pair_view arrays = pair_view_arrays(P, NULL);
#pragma omp parallel for schedule(dynamic, 256)
  for (size_t a = 0; a < P->n; a++) {
    q[a] = 0.0;
    if (P->kind[a] != KIND_FLUID) continue;
    double s[GRADIENT_SUMS];
    gradient_sums_of(M, P, nb, a, &arrays, s); /* the particle arrays: the records may be older */
    q[a] = turb_q_gradient(M->dim, s, s + 6);
  }
}

double turb_profile_value(const struct nu_profile *t, double y) {
  if (y <= t->y[0]) return t->v[0];
  if (y >= t->y[t->n - 1]) return t->v[t->n - 1];
  int lo = 0, hi = t->n - 1; /* t->y[lo] < y < t->y[hi] */
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (t->y[mid] <= y)
      lo = mid;
    else
      hi = mid;
  }
  const double f = (y - t->y[lo]) / (t->y[hi] - t->y[lo]);
  return t->v[lo] + f * (t->v[hi] - t->v[lo]);
}

/* les.model = profile: nu_r = nu f(d / delta) of the table, d the distance to the nearest
   wall; no k_r. Returns the largest nu + nu_r. */
static double profile_viscosity(const struct model *M, struct particles *P) {
  const double nu = M->nu, idelta = 2.0 / M->ly;
  const uint8_t *restrict kind = P->kind;
  double *restrict nur = P->nur, *restrict kr = P->kr;
  double numax = nu;
#pragma omp parallel for schedule(static) reduction(max : numax)
  for (size_t a = 0; a < P->n; a++) {
    nur[a] = kr[a] = 0.0;
    if (kind[a] != KIND_FLUID) continue;
    int wall;
    const double d = nearest_wall(M, P->y[a], &wall);
    nur[a] = nu * turb_profile_value(&M->nu_prof, d * idelta);
    if (nu + nur[a] > numax) numax = nu + nur[a];
  }
  return numax;
}

/* turb_eddy_viscosity at the current state (not les.strain_lag, or a run's first step): rate of
   strain, damping, nu_r and k_r of every owned particle; returns the largest nu + nu_r. */
static double eddy_viscosity(const struct model *M, struct particles *P, const struct nbr *nb,
                             const struct walls *W) {
  const double two_h = 2.0 * M->h, nu = M->nu, ih = M->k.inv_h;
  const double *restrict u = P->u, *restrict w = P->w, *restrict rho = P->rho;
  const uint8_t *restrict kind = P->kind;
  double *restrict nur = P->nur, *restrict kr = P->kr;
  const int records = records_fast(); /* the gathered records are faster with AVX-512 */
  if (records) records_pack(P, P->n + P->n_ghost); /* positions, velocities, volumes */
  const struct pair_view arrays = pair_view_arrays(P, NULL);
  double numax = nu;
#pragma omp parallel for schedule(dynamic, 256) reduction(max : numax)
  for (size_t a = 0; a < P->n; a++) {
    nur[a] = kr[a] = 0.0;
    if (kind[a] != KIND_FLUID) continue;
    double damp, d, utau2;
    const double ls2 = smagorinsky_length2(M, P, W, a, &damp, &d, &utau2);
    double S;
    if (M->strain == STRAIN_GRADIENT) {
      double s[GRADIENT_SUMS];
      gradient_sums_of(M, P, nb, a, records ? NULL : &arrays, s);
      S = turb_strain_gradient(M->dim, s, s + 6);
    } else { /* Violeau-Issa, Eq. 5.48 with nu_r,b = nu_r,a: S^3 - sum S - W / l_S^2 = 0 */
      const double ig = 1.0 / P->gam[a];
      const double sum = violeau_issa_sum(M, &arrays, nb, a) * ig / rho[a];
      double wterm = 0.0; /* power of the wall shear: 2/gamma sum_s u_tau,s^2 |v_t| |grad gamma| */
      if (d < two_h)
        wterm =
            2.0 * ig * utau2 * sqrt(u[a] * u[a] + w[a] * w[a]) * wall_dgamma_of(&M->k, d * ih) * ih;
      S = ls2 > 0.0 ? strain_cubic(sum, wterm / ls2) : sqrt(sum);
    }
    smagorinsky(M, ls2, damp, S, &nur[a], &kr[a]);
    if (nu + nur[a] > numax) numax = nu + nur[a];
  }
  return numax;
}

void turb_wall_law(const struct model *M, struct particles *P, const struct nbr *nb,
                   struct walls *W) {
  timer_push("wall_law");
  wall_law_stresses(M, P, nb, W);
  timer_pop();
}

double turb_eddy_viscosity(const struct model *M, struct particles *P, const struct nbr *nb,
                           const struct walls *W) {
  timer_push("les");
  /* with les.strain_lag the last force pass has formed nu_r and k_r (except on a run's first
     step): only their maximum is taken here */
  double numax = M->nu;
  if (P->nur_live) {
    const double nu = M->nu, *restrict nur = P->nur;
#pragma omp parallel for schedule(static) reduction(max : numax)
    for (size_t a = 0; a < P->n; a++)
      if (P->kind[a] == KIND_FLUID && nu + nur[a] > numax) numax = nu + nur[a];
  } else if (M->les == LES_PROFILE) {
    numax = profile_viscosity(M, P);
  } else {
    numax = eddy_viscosity(M, P, nb, W);
  }
  timer_pop();
  return numax;
}
