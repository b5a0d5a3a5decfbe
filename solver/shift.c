/** @file shift.c @brief Implementation of shift.h; a gather loop over the neighbour list. */
#include "shift.h"

#include <math.h>

#include "pair_loop.h"
#include "term_gradient.h"
#include "timers.h"
#include "wall.h"

/** Particle part of grad C_a: sum_b V_b [1 + R (w_ab / w(dr))^n] F_ab r_ab over fluid and
    vertex neighbours (Lind et al. 2012, Eq. 22; anti-clustering term of Sun et al. 2017). */
static CHANSPH_CLONES struct v3 shift_gradient(const struct model *M, const struct particles *P,
                                               const struct nbr *nb, size_t a) {
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z, *restrict V = P->vol;
  const int32_t *restrict nl = pair_list(nb, a);
  const double xa = x[a], ya = y[a], za = z[a], iwdr = M->shift_iwdr;
  double gx = 0.0, gy = 0.0, gz = 0.0;
#pragma omp simd reduction(+ : gx, gy, gz)
  for (int j = 0; j < nb->count[a]; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    const double s = V[b] * (1.0 + sph_anticluster(kernel_w(&F.K, g.r), iwdr)) * g.f;
    gx += s * g.dx, gy += s * g.dy, gz += s * g.dz;
  }
  return (struct v3){gx, gy, gz};
}

/** The walls' part of grad C_a at height ya, sum_walls W_as n_s (y-component), given the y-part
    gy0 of the particle sum: the region behind the wall counts as filled, with the weight of the
    pressure wall term (lattice: |grad gamma_as| plus the lattice excess of the sum, so that the
    initial lattice is at rest under the shift). */
static double shift_wall_part(const struct model *M, double ya, double gy0) {
  const double ih = M->k.inv_h;
  double sum = 0.0;
  for (int wall = 0; wall < 2; wall++) {
    const double q = (wall ? M->ly - ya : ya) * ih;
    if (q >= 2.0) continue;
    const double dg = wall_dgamma_of(&M->k, q) * ih; /* |grad gamma_as| */
    const double ny = wall ? -1.0 : 1.0;             /* inward normal */
    const double pw = M->wall_pressure == WALL_PRESSURE_LATTICE
                          ? dg + sph_lattice_table(M, M->lat_s, q)
                      : M->wall_pressure == WALL_PRESSURE_CONSISTENT ? fmax(dg, ny * gy0)
                                                                     : dg;
    sum += pw * ny;
  }
  return sum;
}

/** Shift of fluid particle a from the particle part g of grad C_a: the walls' part, the factor
    -C h^2, the cap |delta r| <= shift_max and the wall guard. */
static struct v3 shift_finish(const struct model *M, double ya, struct v3 g) {
  const double dist[2] = {ya, M->ly - ya};
  g.y -= shift_wall_part(M, ya, g.y);
  struct v3 s = {-M->shift_ch2 * g.x, -M->shift_ch2 * g.y, -M->shift_ch2 * g.z};
  const double len = sqrt(s.x * s.x + s.y * s.y + s.z * s.z);
  if (len > M->shift_max) { /* at most 0.1 dr per step */
    const double f = M->shift_max / len;
    s.x *= f, s.y *= f, s.z *= f;
  }
  /* never more than half-way to a wall: the shift alone cannot carry a particle through it */
  if (s.y < -0.5 * dist[0]) s.y = -0.5 * dist[0];
  if (s.y > 0.5 * dist[1]) s.y = 0.5 * dist[1];
  return s;
}

void shift_compute(const struct model *M, const struct particles *P, const struct nbr *nb,
                   double *sx, double *sy, double *sz) {
  timer_push("shift");
#pragma omp parallel for schedule(dynamic, 64)
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) {
      sx[a] = sy[a] = sz[a] = 0.0;
      continue;
    }
    const struct v3 s = shift_finish(M, P->y[a], shift_gradient(M, P, nb, a));
    sx[a] = s.x, sy[a] = s.y, sz[a] = s.z;
  }
  timer_pop();
}

void shift_apply(struct particles *P, const double *sx, const double *sy, const double *sz) {
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    P->x[a] += sx[a];
    P->y[a] += sy[a];
    P->z[a] += sz[a];
  }
}

void shift_velocity(const struct model *M, const struct particles *P, const struct nbr *nb,
                    const double *sx, const double *sy, const double *sz, double *du, double *dv,
                    double *dw) {
  timer_push("shift");
  const struct pair_view arrays = pair_view_arrays(P, NULL);
#pragma omp parallel for schedule(dynamic, 256)
  for (size_t a = 0; a < P->n; a++) {
    du[a] = dv[a] = dw[a] = 0.0;
    if (P->kind[a] != KIND_FLUID) continue;
    double s[GRADIENT_SUMS], G[3][3];
    gradient_sums_of(M, P, nb, a, &arrays, s);
    for (int i = 0; i < 3; i++) sph_solve_sym(M->dim, s, s + 6 + 3 * i, G[i]); /* row i: grad u_i */
    const double r[3] = {sx[a], sy[a], sz[a]};
    du[a] = G[0][0] * r[0] + G[0][1] * r[1] + G[0][2] * r[2];
    dv[a] = G[1][0] * r[0] + G[1][1] * r[1] + G[1][2] * r[2];
    dw[a] = G[2][0] * r[0] + G[2][1] * r[1] + G[2][2] * r[2];
  }
  timer_pop();
}

/** du_a of shift_velocity_conservative: a gather over the fluid neighbours of a. */
static CHANSPH_CLONES struct v3 conservative_sum(const struct model *M, const struct particles *P,
                                                 const struct nbr *nb, size_t a) {
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict u = P->u, *restrict v = P->v, *restrict w = P->w;
  const double *restrict m = P->m, *restrict rho = P->rho;
  const double *restrict sx = P->shift_dx, *restrict sy = P->shift_dy, *restrict sz = P->shift_dz;
  const uint8_t *restrict kind = P->kind;
  const int32_t *restrict nl = pair_list(nb, a);
  const double xa = x[a], ya = y[a], za = z[a], ira = 1.0 / rho[a], iwdr = M->shift_iwdr;
  double gx = 0.0, gy = 0.0, gz = 0.0; /* sum_b m_b phi_ab grad_a w_ab, all neighbours */
  double bx = 0.0, by = 0.0, bz = 0.0; /* sum_b m_b phi_ab u_b (dr_b . grad_a w_ab) / rho_b */
#pragma omp simd reduction(+ : gx, gy, gz, bx, by, bz)
  for (int j = 0; j < nb->count[a]; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    /* the shift's weight phi_ab = 1 + R (w_ab / w(dr))^n: symmetric in a and b */
    const double fm = m[b] * (1.0 + sph_anticluster(kernel_w(&F.K, g.r), iwdr)) * g.f;
    gx += fm * g.dx, gy += fm * g.dy, gz += fm * g.dz;
    /* vertex particles: no shift (and at rest), so only fluid b count here */
    const double cb = (kind[b] == KIND_FLUID ? 1.0 : 0.0) * fm *
                      (sx[b] * g.dx + sy[b] * g.dy + sz[b] * g.dz) / rho[b];
    bx += cb * u[b], by += cb * v[b], bz += cb * w[b];
  }
  /* dr_a . grad C_a with the walls' part, as the shift sees it (with m_b / rho_a for V_b, which
     keeps each pair's share antisymmetric): zero on the initial lattice, walls included, where
     the particle sum alone is grad gamma_a; elsewhere -C h^2 |grad C_a|^2 <= 0 (uncapped) */
  gy *= ira;
  const double ca = sx[a] * gx * ira + sy[a] * (gy - shift_wall_part(M, ya, gy)) + sz[a] * gz * ira;
  return (struct v3){u[a] * ca + bx, v[a] * ca + by, w[a] * ca + bz};
}

void shift_velocity_conservative(const struct model *M, const struct particles *P,
                                 const struct nbr *nb, double *du, double *dv, double *dw) {
  timer_push("shift");
#pragma omp parallel for schedule(dynamic, 256)
  for (size_t a = 0; a < P->n; a++) {
    du[a] = dv[a] = dw[a] = 0.0;
    if (P->kind[a] != KIND_FLUID) continue;
    const struct v3 d = conservative_sum(M, P, nb, a);
    du[a] = d.x, dv[a] = d.y, dw[a] = d.z;
  }
  timer_pop();
}
