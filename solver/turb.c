/** @file turb.c @brief Implementation of turb.h. */
#include "turb.h"

#include <math.h>
#include <string.h>

#include "timers.h"
#include "wall.h"

void turb_init(const struct model *M, struct particles *P, struct walls *W) {
  if (!M->wall_tau) return;
  const size_t nd = P->n * sizeof(double), nv = P->n_vertex * sizeof(double);
  P->twx = part_alloc("wall_law_tx", nd), P->twz = part_alloc("wall_law_tz", nd);
  W->tx = part_alloc("wall_tau_x", nv), W->tz = part_alloc("wall_tau_z", nv);
  if (M->les) P->nur = part_alloc("nu_r", nd), P->kr = part_alloc("k_r", nd);
}

void turb_free(struct particles *P, struct walls *W) {
  double **d[] = {&P->twx, &P->twz, &P->nur, &P->kr, &W->tx, &W->tz};
  for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) part_free(*d[i]), *d[i] = NULL;
}

double turb_van_driest(double yplus, double a_plus) {
  return -expm1(-yplus / a_plus); /* 1 - exp(-y+/A+) */
}

double turb_strain_gradient(int dim, const double A[6], const double B[9]) {
  double G[3][3];
  for (int i = 0; i < 3; i++) sph_solve_sym(dim, A, B + 3 * i, G[i]); /* row i of B L */
  double s2 = 0.0;
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) {
      const double sij = 0.5 * (G[i][j] + G[j][i]);
      s2 += 2.0 * sij * sij;
    }
  return sqrt(s2);
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

/** Shepard sums at vertex s over its fluid neighbours: returns alpha = sum_b V_b w_bs and sets
    out[k] = sum_b V_b w_bs f_k,b for the nf fields f (Ferrand Eq. 38 without the 1/alpha). */
static double vertex_sums(const struct model *M, const struct particles *P, const struct nbr *nb,
                          size_t s, int nf, const double *const *f, double *out) {
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const int32_t *nl = nb->list + s * (size_t)nb->stride;
  double alpha = 0.0;
  for (int k = 0; k < nf; k++) out[k] = 0.0;
  for (int j = 0; j < nb->count[s]; j++) {
    const int32_t b = nl[j];
    if (P->kind[b] != KIND_FLUID) continue;
    const double dx = nbr_wrap(x[s] - x[b], M->lx), dy = y[s] - y[b];
    const double dz = M->dim == 3 ? nbr_wrap(z[s] - z[b], M->lz) : 0.0;
    const double vw = P->vol[b] * kernel_w(&M->k, sqrt(dx * dx + dy * dy + dz * dz));
    alpha += vw;
    for (int k = 0; k < nf; k++) out[k] += vw * f[k][b];
  }
  return alpha;
}

double turb_update(const struct model *M, struct particles *P, const struct nbr *nb,
                   struct walls *W, struct dd *dd) {
  if (!M->wall_tau) return M->nu;
  timer_push("wall_law");
  const struct kernel *K = &M->k;
  const double two_h = 2.0 * M->h, nu = M->nu;
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict u = P->u, *restrict v = P->v, *restrict w = P->w;
  const double *restrict vol = P->vol, *restrict rho = P->rho;
  const uint8_t *restrict kind = P->kind;
  double *restrict twx = P->twx, *restrict twz = P->twz;
  /* 1. wall-law stress of the near-wall particles: rho u_tau^2 along their tangential velocity
        (from the particle's own values: the ghosts compute theirs too) */
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
  /* 2. vertex values rho_s u_tau u_tau = (1/alpha) sum_b V_b rho_b u_tau,b u_tau,b w_bs
        (Ferrand Eq. 38) */
  const double *tw[2] = {P->twx, P->twz};
#pragma omp parallel for schedule(static)
  for (size_t s = 0; s < P->n; s++) {
    if (kind[s] != KIND_VERTEX) continue;
    double sum[2];
    const double alpha = vertex_sums(M, P, nb, s, 2, tw, sum);
    const size_t slot = part_vertex_slot(P, P->id[s]);
    W->tx[slot] = alpha > 0.0 ? sum[0] / alpha : 0.0;
    W->tz[slot] = alpha > 0.0 ? sum[1] / alpha : 0.0;
  }
  timer_pop();
  double *const wt[2] = {W->tx, W->tz};
  if (dd) dd_update_walls(dd, P, 2, wt);
  if (!M->les) return nu;
  timer_push("les");
  /* 3. rate of strain, damping, eddy viscosity and residual kinetic energy */
  double *restrict nur = P->nur, *restrict kr = P->kr;
  const double ih = K->inv_h, dg2 = M->delta_g * M->delta_g;
  double numax = nu;
#pragma omp parallel for schedule(static) reduction(max : numax)
  for (size_t a = 0; a < P->n; a++) {
    nur[a] = kr[a] = 0.0;
    if (kind[a] != KIND_FLUID) continue;
    /* local friction velocity at the foot on the nearest wall, y+ and the damped length */
    int wall;
    const double d = nearest_wall(M, y[a], &wall);
    double damp = 1.0, rs, tsx, tsz;
    sph_wall_stress(M, W, wall, x[a], z[a], &rs, &tsx, &tsz);
    const double utau2 = sqrt(tsx * tsx + tsz * tsz) / rs;
    if (M->van_driest) damp = turb_van_driest(d * sqrt(utau2) / nu, M->a_plus);
    const double ls2 = M->cs * M->cs * dg2 * damp * damp; /* l_S^2 */
    const int32_t *nl = nb->list + a * (size_t)nb->stride;
    double S;
    if (M->strain == STRAIN_GRADIENT) {
      double A[6] = {0, 0, 0, 0, 0, 0}, B[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      for (int j = 0; j < nb->count[a]; j++) {
        const int32_t b = nl[j];
        const double dx = nbr_wrap(x[a] - x[b], M->lx), dy = y[a] - y[b];
        const double dz = M->dim == 3 ? nbr_wrap(z[a] - z[b], M->lz) : 0.0;
        const double r = sqrt(dx * dx + dy * dy + dz * dz);
        const double vf = vol[b] * kernel_f(K, r);
        const double du[3] = {u[b] - u[a], v[b] - v[a], w[b] - w[a]}, rr[3] = {dx, dy, dz};
        A[0] -= vf * dx * dx, A[1] -= vf * dx * dy, A[2] -= vf * dx * dz;
        A[3] -= vf * dy * dy, A[4] -= vf * dy * dz, A[5] -= vf * dz * dz;
        for (int i = 0; i < 3; i++)
          for (int k = 0; k < 3; k++) B[3 * i + k] += vf * du[i] * rr[k];
      }
      S = turb_strain_gradient(M->dim, A, B);
    } else { /* Violeau-Issa, Eq. 5.48 with nu_r,b = nu_r,a: S^3 - sum S - W / l_S^2 = 0 */
      double sum = 0.0;
      for (int j = 0; j < nb->count[a]; j++) {
        const int32_t b = nl[j];
        const double dx = nbr_wrap(x[a] - x[b], M->lx), dy = y[a] - y[b];
        const double dz = M->dim == 3 ? nbr_wrap(z[a] - z[b], M->lz) : 0.0;
        const double r = sqrt(dx * dx + dy * dy + dz * dz);
        const double ux = u[a] - u[b], uy = v[a] - v[b], uz = w[a] - w[b];
        sum -= vol[b] * 0.5 * (rho[a] + rho[b]) * (ux * ux + uy * uy + uz * uz) * kernel_f(K, r);
      }
      const double ig = 1.0 / P->gam[a];
      sum *= ig / rho[a];
      double wterm = 0.0; /* power of the wall shear: 2/gamma sum_s u_tau,s^2 |v_t| |grad gamma| */
      if (d < two_h)
        wterm =
            2.0 * ig * utau2 * sqrt(u[a] * u[a] + w[a] * w[a]) * wall_dgamma(M->dim, d * ih) * ih;
      S = ls2 > 0.0 ? strain_cubic(sum, wterm / ls2) : sqrt(sum);
    }
    nur[a] = ls2 * S;
    if (M->cy > 0.0) kr[a] = 2.0 * M->cy * dg2 * damp * damp * S * S;
    if (nu + nur[a] > numax) numax = nu + nur[a];
  }
  double *const nk[2] = {nur, kr};
  if (dd) dd_update(dd, P, 2, nk); /* read at neighbours by the forces and by step 4 */
  /* 4. residual kinetic energy in the pressure: p + 2/3 rho k_r for fluid and vertices */
  if (M->cy > 0.0) {
#pragma omp parallel for schedule(static)
    for (size_t s = 0; s < P->n; s++) {
      if (kind[s] == KIND_FLUID) {
        P->pr2[s] += 2.0 / 3.0 * kr[s] / rho[s];
        continue;
      }
      const double *krf[1] = {kr};
      double sk;
      const double alpha = vertex_sums(M, P, nb, s, 1, krf, &sk);
      const double ks = alpha > 0.0 ? sk / alpha : 0.0, extra = 2.0 / 3.0 * rho[s] * ks;
      P->pr2[s] += extra / (rho[s] * rho[s]);
      W->p[part_vertex_slot(P, P->id[s])] += extra;
    }
  }
  timer_pop();
  if (dd && M->cy > 0.0) {
    double *const pr[1] = {P->pr2}, *const wp[1] = {W->p};
    dd_update(dd, P, 1, pr);
    dd_update_walls(dd, P, 1, wp);
  }
  return numax;
}
