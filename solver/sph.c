/**
 * @file sph.c
 * @brief Implementation of sph.h. All loops are gathers over the neighbour list.
 *
 * Per-segment boundary sums. For a plane wall, sum_s f_s grad gamma_as = int_wall f w n dS.
 * We evaluate it as f(foot_a) grad gamma_a(d), with grad gamma_a the exact closed form for the
 * whole plane (wall.h) and f(foot_a) the (bi)linear interpolation of the vertex values at the
 * foot of the perpendicular from a. This is exact for f varying linearly along the wall
 * (the kernel is symmetric about the foot) and second order otherwise.
 */
#include "sph.h"

#include <math.h>

#include "timers.h"
#include "wall.h"

void sph_model_init(struct model *M, const struct scene *s) {
  M->dim = s->dim;
  M->viscous = s->viscous;
  M->h = scene_h(s);
  M->dr = s->dr;
  M->k = kernel_make(s->dim, M->h);
  M->e.rho0 = s->rho0, M->e.c0 = s->c0, M->e.zeta = s->zeta;
  M->e.pb = s->p_background * s->rho0 * s->c0 * s->c0;
  M->lx = s->lx, M->ly = 2.0 * s->delta, M->lz = s->dim == 3 ? s->lz : 1.0;
  M->nu = s->nu;
  M->inv_xi = 1.0 / scene_xi(s);
  M->gy = s->gravity_y;
  M->wall_dmin = s->wall_dmin * s->dr;
  M->eta2 = s->eta2 * M->h * M->h;
  M->lap_norm = s->lap_norm;
  M->wall_weight = s->wall_weight;
  M->wall_pressure = s->wall_pressure;
  sph_lattice_excess_table(M);
}

void sph_lattice_excess_table(struct model *M) {
  const struct kernel *K = &M->k;
  const double dr = M->dr, ih = K->inv_h, vol = pow(dr, M->dim);
  const int reach = (int)ceil(2.0 * M->h / dr); /* lattice offsets within the support */
  int n = 0;
  for (int j = 1; j * dr < 2.0 * M->h && n < LATTICE_KNOTS - 1; j++) {
    double mom1 = 0.0; /* sum_b V_b (y_a - y_b) F_ab over the virtual lattice around layer j */
    for (int k = 0; k <= j + reach; k++) {
      const double v = k == 0 ? 0.5 * vol : vol, dy = (j - k) * dr; /* k = 0: vertex row */
      for (int i = -reach; i <= reach; i++)
        for (int l = M->dim == 3 ? -reach : 0; l <= (M->dim == 3 ? reach : 0); l++) {
          if (k == j && i == 0 && l == 0) continue;
          const double r = sqrt((i * i + l * l) * dr * dr + dy * dy);
          mom1 += v * kernel_f(K, r) * dy;
        }
    }
    const double q = j * dr * ih;
    M->lat_q[n] = q;
    M->lat_e[n] = fmax(0.0, mom1 - wall_dgamma(M->dim, q) * ih);
    n++;
  }
  M->lat_q[n] = 2.0, M->lat_e[n] = 0.0;
  M->n_lat = n + 1;
}

/** Lattice excess of the pressure wall weight at q = d/h: linear between the layers of the
    lattice, constant below the first layer, zero at q = 2. */
static double lattice_excess(const struct model *M, double q) {
  if (q >= 2.0) return 0.0;
  if (q <= M->lat_q[0]) return M->lat_e[0];
  int k = 1;
  while (k < M->n_lat - 1 && M->lat_q[k] < q) k++;
  const double t = (q - M->lat_q[k - 1]) / (M->lat_q[k] - M->lat_q[k - 1]);
  return (1.0 - t) * M->lat_e[k - 1] + t * M->lat_e[k];
}

/** gamma of the channel: both walls' missing parts subtracted (they never overlap). */
static inline double channel_gamma(const struct model *M, double y) {
  const double ih = M->k.inv_h;
  return wall_gamma(M->dim, y * ih) + wall_gamma(M->dim, (M->ly - y) * ih) - 1.0;
}

void sph_density(const struct model *M, struct particles *P, const double *ksum_new, double dt) {
  timer_push("density");
  const double *restrict y = P->y, *restrict m = P->m;
  const uint8_t *restrict kind = P->kind;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    if (kind[a] != KIND_FLUID) continue;
    const double s = ksum_new[a], gam = channel_gamma(M, y[a]);
    if (dt > 0.0) P->rho[a] = (P->gam[a] * P->rho[a] + s - P->ksum[a] + dt * P->ddiff[a]) / gam;
    P->ksum[a] = s;
    P->gam[a] = gam;
    const double r = P->rho[a], pa = eos_pressure(&M->e, r);
    P->p[a] = pa, P->c[a] = eos_sound(&M->e, r);
    P->pr2[a] = pa / (r * r), P->vol[a] = m[a] / r;
  }
  timer_pop();
}

void sph_walls(const struct model *M, struct particles *P, const struct nbr *nb, struct walls *W) {
  timer_push("walls");
  const struct kernel *K = &M->k;
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z, *restrict m = P->m;
  const double *restrict rho = P->rho, *restrict p = P->p;
  const uint8_t *restrict kind = P->kind;
#pragma omp parallel for schedule(static)
  for (size_t v = 0; v < P->n; v++) {
    if (kind[v] != KIND_VERTEX) continue;
    const int32_t *nl = nb->list + v * (size_t)nb->stride;
    double alpha = 0.0, mw = 0.0, pw = 0.0;
    for (int j = 0; j < nb->count[v]; j++) {
      const int32_t b = nl[j];
      if (kind[b] != KIND_FLUID) continue;
      const double dx = nbr_wrap(x[v] - x[b], M->lx), dy = y[v] - y[b];
      const double dz = M->dim == 3 ? nbr_wrap(z[v] - z[b], M->lz) : 0.0;
      const double wvb = kernel_w(K, sqrt(dx * dx + dy * dy + dz * dz));
      const double vol = m[b] / rho[b];
      alpha += vol * wvb;
      mw += m[b] * wvb;
      pw += vol * (p[b] / rho[b] + M->gy * (y[v] - y[b])) * wvb;
    }
    double rv = M->e.rho0, pv = 0.0;
    if (alpha > 0.0) rv = mw / alpha, pv = rv * pw / alpha;
    P->rho[v] = rv, P->p[v] = pv;
    P->c[v] = eos_sound(&M->e, rv);
    P->pr2[v] = pv / (rv * rv), P->vol[v] = m[v] / rv;
    const size_t slot = part_vertex_slot(P, P->id[v]);
    W->rho[slot] = rv, W->p[slot] = pv;
  }
  timer_pop();
}

void sph_wall_values(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *p) {
  const double fx = x / M->dr - 0.5;
  const double ix = floor(fx), tx = fx - ix;
  int i0 = (int)ix % W->nx;
  if (i0 < 0) i0 += W->nx;
  const int i1 = (i0 + 1) % W->nx;
  const size_t off = (size_t)wall * W->nx * W->nz;
  const double *rw = W->rho + off, *pw = W->p + off;
  if (M->dim == 2) {
    *rho = (1.0 - tx) * rw[i0] + tx * rw[i1];
    *p = (1.0 - tx) * pw[i0] + tx * pw[i1];
    return;
  }
  const double fz = z / M->dr - 0.5;
  const double iz = floor(fz), tz = fz - iz;
  int k0 = (int)iz % W->nz;
  if (k0 < 0) k0 += W->nz;
  const int k1 = (k0 + 1) % W->nz;
  const int nz = W->nz;
  const size_t c00 = (size_t)i0 * nz + k0, c01 = (size_t)i0 * nz + k1;
  const size_t c10 = (size_t)i1 * nz + k0, c11 = (size_t)i1 * nz + k1;
  *rho = (1.0 - tx) * ((1.0 - tz) * rw[c00] + tz * rw[c01]) +
         tx * ((1.0 - tz) * rw[c10] + tz * rw[c11]);
  *p = (1.0 - tx) * ((1.0 - tz) * pw[c00] + tz * pw[c01]) +
       tx * ((1.0 - tz) * pw[c10] + tz * pw[c11]);
}

void sph_forces(const struct model *M, struct particles *P, const struct nbr *nb,
                const struct walls *W, double fx, struct force_info *info) {
  timer_push("forces");
  const struct kernel *K = &M->k;
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict u = P->u, *restrict v = P->v, *restrict w = P->w;
  const double *restrict m = P->m, *restrict rho = P->rho;
  const double *restrict c = P->c, *restrict pr2 = P->pr2, *restrict vol = P->vol;
  const uint8_t *restrict kind = P->kind;
  const double nu = M->nu, eta2 = M->eta2, inv_xi = M->inv_xi, ih = K->inv_h;
  const double dgrav = M->e.rho0 / (M->e.c0 * M->e.c0) * M->gy; /* Eq. 3.61 */
  const double dplus2 = M->dim + 2.0;
  const int violeau = M->viscous == VISCOUS_VIOLEAU;
  const int discrete = !violeau && M->wall_weight == WALL_WEIGHT_DISCRETE;
  double amax2 = 0.0, gvmax = 0.0;
#pragma omp parallel for schedule(static) reduction(max : amax2, gvmax)
  for (size_t a = 0; a < P->n; a++) {
    if (kind[a] != KIND_FLUID) continue;
    const int32_t *nl = nb->list + a * (size_t)nb->stride;
    const int cnt = nb->count[a];
    const double ra = rho[a], pa = pr2[a], ca = c[a], ira = 1.0 / ra;
    double gpx = 0, gpy = 0, gpz = 0; /* sum m_b (p_a/rho_a^2 + p_b/rho_b^2) grad w */
    double vx = 0, vy = 0, vz = 0;    /* viscous sum */
    double diff = 0;                  /* volume diffusion */
    double mom2 = 0;                  /* sum V_b r_ab . grad w_ab, Laplacian normalisation */
    double momyy = 0;                 /* sum V_b y_ab^2 F_ab, wall-normal normalisation */
    double mom1 = 0;                  /* sum V_b y_ab f_ab, discrete wall weight */
    double wvx = 0;                   /* part of vx from wall vertices */
    for (int j = 0; j < cnt; j++) {
      const int32_t b = nl[j];
      const double dx = nbr_wrap(x[a] - x[b], M->lx), dy = y[a] - y[b];
      const double dz = M->dim == 3 ? nbr_wrap(z[a] - z[b], M->lz) : 0.0;
      const double r2 = dx * dx + dy * dy + dz * dz, r = sqrt(r2);
      const double f = kernel_f(K, r); /* grad_a w_ab = f r_ab */
      const double rb = rho[b], mb = m[b], vb = vol[b];
      const double pp = mb * (pa + pr2[b]) * f;
      gpx += pp * dx, gpy += pp * dy, gpz += pp * dz;
      const double ux = u[a] - u[b], uy = v[a] - v[b], uz = w[a] - w[b];
      const double vf = vb * f, vx_before = vx;
      mom2 += vf * r2, momyy += vf * dy * dy, mom1 += vf * dy;
      if (violeau) {
        const double coef = vb * 0.5 * (ra + rb) * f / (r2 + eta2);
        const double vr = dplus2 * (ux * dx + uy * dy + uz * dz);
        vx += coef * (vr * dx + r2 * ux), vy += coef * (vr * dy + r2 * uy);
        vz += coef * (vr * dz + r2 * uz);
      } else {
        const double coef = (mb * ira + vb) * f * r2 / (r2 + eta2); /* m_b (1/rho_a + 1/rho_b) */
        vx += coef * ux, vy += coef * uy, vz += coef * uz;
      }
      if (kind[b] == KIND_FLUID) {
        const double cab = ca > c[b] ? ca : c[b];
        const double vrho = ra - rb - dgrav * dy; /* varrho_ab of Eq. 3.61 */
        diff += vb * cab * vrho * f * r;
      } else { /* viscous pull of the wall vertices, for the wall shear stress */
        wvx += vx - vx_before;
      }
    }
    const double ig = 1.0 / P->gam[a];
    double axa = -ig * gpx, aya = -ig * gpy, aza = -ig * gpz;
    double kappa = 1.0;
    if (M->lap_norm != LAPNORM_NONE) { /* discrete + analytic part behind the walls */
      const double qb = y[a] * ih, qt = (M->ly - y[a]) * ih;
      if (M->lap_norm == LAPNORM_TRACE)
        kappa = -M->dim / (mom2 + wall_moment2(M->dim, qb) + wall_moment2(M->dim, qt));
      else
        kappa = -1.0 / (momyy + wall_moment_yy(M->dim, qb) + wall_moment_yy(M->dim, qt));
    }
    const double lap = nu * ig * kappa; /* nu / gamma_a, normalised */
    const double vis = violeau ? lap / ra : lap;
    axa += vis * vx, aya += vis * vy, aza += vis * vz;
    double awall = vis * wvx; /* x-acceleration from the walls, for the statistics */
    /* wall terms: pressure (Eq. 3.17, k = 1) and wall shear (Eq. 2.147-2.148) */
    double gv = 0.0;
    for (int wall = 0; wall < 2; wall++) {
      const double d = wall ? M->ly - y[a] : y[a];
      const double q = d * ih;
      if (q >= 2.0) continue;
      const double dg = wall_dgamma(M->dim, q) * ih; /* |grad gamma_as| */
      const double ny = wall ? -1.0 : 1.0;           /* inward normal */
      double rs, ps;
      sph_wall_values(M, W, wall, x[a], z[a], &rs, &ps);
      /* pressure wall term: |grad gamma_as| plus the excess of the discrete first moment on
         the particle lattice (so that a uniform pressure leaves the lattice in equilibrium yet
         pushes a displaced particle back), or of the current particles, or nothing
         (docs/theory.md) */
      const double pw = M->wall_pressure == WALL_PRESSURE_LATTICE      ? dg + lattice_excess(M, q)
                        : M->wall_pressure == WALL_PRESSURE_CONSISTENT ? fmax(dg, ny * mom1)
                                                                       : dg;
      aya += ig * rs * (pa + ps / (rs * rs)) * pw * ny;
      /* |grad gamma_as|, or the discrete first moment that makes the Morris operator exact
         for a velocity varying linearly with the wall distance (docs/theory.md) */
      const double weight = discrete ? fmax(0.0, ny * mom1) : dg;
      const double shear = 2.0 * lap * weight / (d > M->wall_dmin ? d : M->wall_dmin);
      axa -= shear * u[a], aza -= shear * w[a];
      awall -= shear * u[a];
      const double g = fabs(dg * v[a]);
      if (g > gv) gv = g;
    }
    aya += M->gy;
    P->ax[a] = axa, P->ay[a] = aya, P->az[a] = aza;
    if (info->wall_ax) info->wall_ax[a] = awall;
    P->ddiff[a] = diff * inv_xi; /* enters gamma rho directly (Eq. 3.64): no 1/gamma */
    const double ax2 = (axa + fx) * (axa + fx) + aya * aya + aza * aza;
    if (ax2 > amax2) amax2 = ax2;
    if (gv > gvmax) gvmax = gv;
  }
  info->amax = sqrt(amax2);
  info->gvmax = gvmax;
  timer_pop();
}
