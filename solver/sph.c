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
  M->pgrad = s->pgrad;
  M->les = s->les != LES_NONE;
  M->strain = s->strain;
  M->van_driest = s->van_driest;
  M->cs = s->cs, M->delta_g = s->filter_h * M->h, M->a_plus = s->a_plus;
  M->cy = s->cy;
  M->law = wall_law_make(s->wall_law, s->kappa, s->log_b);
  M->wall_tau = M->les || s->wall_law != WALL_LAW_LAMINAR;
  sph_lattice_excess_table(M);
  sph_violeau_table(M);
}

/** Integral over the half-space y > q (units of h) of y^2 F(r) ((n+2) x_t^2 / r^2 + 1), with
    x_t^2 the mean square of one wall-parallel component (r^2 - y^2)/(n - 1). */
static double violeau_wall_moment(int dim, double q) {
  if (q >= 2.0) return 0.0;
  const struct kernel K = kernel_make(dim, 1.0);
  const double n = dim, gp = (n + 2.0) / (n - 1.0);
  enum { PANELS = 8 };
  double sum = 0.0;
  for (int py = 0; py < PANELS; py++)
    for (int iy = 0; iy < 12; iy++) {
      const double ya = q + (2.0 - q) * py / PANELS, yl = (2.0 - q) / PANELS;
      const double y = ya + yl * wall_gl12_t[iy], wy = yl * wall_gl12_w[iy];
      const double rmax = sqrt(fmax(0.0, 4.0 - y * y)); /* radial extent in the plane */
      double inner = 0.0;
      for (int pr = 0; pr < PANELS; pr++)
        for (int ir = 0; ir < 12; ir++) {
          const double rl = rmax / PANELS, rho = rl * (pr + wall_gl12_t[ir]);
          const double wr = rl * wall_gl12_w[ir], r2 = rho * rho + y * y, r = sqrt(r2);
          const double g = y * y * kernel_f(&K, r) * (gp * rho * rho / r2 + 1.0);
          inner += wr * g * (dim == 3 ? 2.0 * M_PI * rho : 2.0); /* both sides of x in 2-D */
        }
      sum += wy * inner;
    }
  return sum;
}

void sph_violeau_table(struct model *M) {
  for (int k = 0; k <= VIOLEAU_KNOTS; k++)
    M->vio_m2[k] = violeau_wall_moment(M->dim, 2.0 * k / VIOLEAU_KNOTS);
}

double sph_violeau_moment(const struct model *M, double q) {
  if (q >= 2.0) return 0.0;
  if (q <= 0.0) return M->vio_m2[0];
  const double f = q * VIOLEAU_KNOTS / 2.0;
  const int k = (int)f;
  const double t = f - k;
  return (1.0 - t) * M->vio_m2[k] + t * M->vio_m2[k + 1];
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

/** Foot of a particle on the wall lattice: corner indices and weights of the (bi)linear
    interpolation (the vertices sit at x = (i + 1/2) dr, z = (k + 1/2) dr). */
struct foot {
  size_t c00, c01, c10, c11;
  double tx, tz;
};

static inline struct foot wall_foot(const struct model *M, const struct walls *W, int wall,
                                    double x, double z) {
  const double fx = x / M->dr - 0.5;
  const double ix = floor(fx), tx = fx - ix;
  int i0 = (int)ix % W->nx;
  if (i0 < 0) i0 += W->nx;
  const int i1 = (i0 + 1) % W->nx;
  const size_t off = (size_t)wall * W->nx * W->nz;
  struct foot f = {off + i0, off + i0, off + i1, off + i1, tx, 0.0};
  if (M->dim == 2) return f;
  const double fz = z / M->dr - 0.5;
  const double iz = floor(fz), tz = fz - iz;
  int k0 = (int)iz % W->nz;
  if (k0 < 0) k0 += W->nz;
  const int k1 = (k0 + 1) % W->nz;
  const size_t nz = (size_t)W->nz;
  f.c00 = off + i0 * nz + k0, f.c01 = off + i0 * nz + k1;
  f.c10 = off + i1 * nz + k0, f.c11 = off + i1 * nz + k1;
  f.tz = tz;
  return f;
}

static inline double foot_value(const struct model *M, const struct foot *f, const double *v) {
  if (M->dim == 2) return (1.0 - f->tx) * v[f->c00] + f->tx * v[f->c10];
  return (1.0 - f->tx) * ((1.0 - f->tz) * v[f->c00] + f->tz * v[f->c01]) +
         f->tx * ((1.0 - f->tz) * v[f->c10] + f->tz * v[f->c11]);
}

void sph_wall_values(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *p) {
  const struct foot f = wall_foot(M, W, wall, x, z);
  *rho = foot_value(M, &f, W->rho);
  *p = foot_value(M, &f, W->p);
}

void sph_wall_stress(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *tx, double *tz) {
  const struct foot f = wall_foot(M, W, wall, x, z);
  *rho = foot_value(M, &f, W->rho);
  *tx = foot_value(M, &f, W->tx);
  *tz = foot_value(M, &f, W->tz);
}

void sph_solve_sym(int dim, const double A[6], const double g[3], double x[3]) {
  if (dim == 2) {
    const double det = A[0] * A[3] - A[1] * A[1];
    const double tr = A[0] + A[3];
    if (!(fabs(det) > 1e-12 * tr * tr)) { /* degenerate support: uncorrected */
      x[0] = tr > 0 ? 2.0 * g[0] / tr : 0.0, x[1] = tr > 0 ? 2.0 * g[1] / tr : 0.0, x[2] = 0.0;
      return;
    }
    x[0] = (A[3] * g[0] - A[1] * g[1]) / det;
    x[1] = (A[0] * g[1] - A[1] * g[0]) / det;
    x[2] = 0.0;
    return;
  }
  /* A = [a b c; b d e; c e f] stored as {a, b, c, d, e, f} */
  const double a = A[0], b = A[1], c = A[2], d = A[3], e = A[4], f = A[5];
  const double c0 = d * f - e * e, c1 = c * e - b * f, c2 = b * e - c * d;
  const double det = a * c0 + b * c1 + c * c2;
  const double tr = a + d + f;
  if (!(fabs(det) > 1e-12 * tr * tr * tr)) {
    for (int i = 0; i < 3; i++) x[i] = tr > 0 ? 3.0 * g[i] / tr : 0.0;
    return;
  }
  const double c4 = a * f - c * c, c5 = b * c - a * e, c8 = a * d - b * b;
  x[0] = (c0 * g[0] + c1 * g[1] + c2 * g[2]) / det;
  x[1] = (c1 * g[0] + c4 * g[1] + c5 * g[2]) / det;
  x[2] = (c2 * g[0] + c5 * g[1] + c8 * g[2]) / det;
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
  const int discrete = M->wall_weight == WALL_WEIGHT_DISCRETE;
  const double np2 = M->dim + 2.0; /* Violeau weight (n + 2) x_i^2 / r^2 + 1, see m1x */
  const int les = M->les, corrected = M->pgrad == PGRAD_CORRECTED;
  const int wall_law = M->law.law != WALL_LAW_LAMINAR;
  const double *restrict nur = P->nur;
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
    /* Violeau: sum V_b y_ab^k F_ab ((n+2) x_i^2/r^2 + 1), k = 1, 2, for i = x and z */
    double m1x = 0, m2x = 0, m1z = 0, m2z = 0;
    double A[6] = {0, 0, 0, 0, 0, 0}; /* corrected gradient: -sum V_b f r_ab (x) r_ab */
    double gc[3] = {0, 0, 0};         /* corrected gradient: sum V_b (p_b - p_a) f r_ab */
    const double pm_a = corrected ? pa * ra * ra : 0.0;
    const double mu_a = les ? ra * (nu + nur[a]) : 0.0;
    for (int j = 0; j < cnt; j++) {
      const int32_t b = nl[j];
      const double dx = nbr_wrap(x[a] - x[b], M->lx), dy = y[a] - y[b];
      const double dz = M->dim == 3 ? nbr_wrap(z[a] - z[b], M->lz) : 0.0;
      const double r2 = dx * dx + dy * dy + dz * dz, r = sqrt(r2);
      const double f = kernel_f(K, r); /* grad_a w_ab = f r_ab */
      const double rb = rho[b], mb = m[b], vb = vol[b];
      if (corrected) {
        const double vf = vb * f, dp = pr2[b] * rb * rb - pm_a;
        A[0] -= vf * dx * dx, A[1] -= vf * dx * dy, A[2] -= vf * dx * dz;
        A[3] -= vf * dy * dy, A[4] -= vf * dy * dz, A[5] -= vf * dz * dz;
        gc[0] += vf * dp * dx, gc[1] += vf * dp * dy, gc[2] += vf * dp * dz;
      } else {
        const double pp = mb * (pa + pr2[b]) * f;
        gpx += pp * dx, gpy += pp * dy, gpz += pp * dz;
      }
      const double ux = u[a] - u[b], uy = v[a] - v[b], uz = w[a] - w[b];
      const double vf = vb * f, vx_before = vx;
      mom2 += vf * r2, momyy += vf * dy * dy, mom1 += vf * dy;
      if (violeau) {
        const double gx = vf * (np2 * dx * dx / (r2 + eta2) + 1.0) * dy;
        const double gz = vf * (np2 * dz * dz / (r2 + eta2) + 1.0) * dy;
        m1x += gx, m2x += gx * dy, m1z += gz, m2z += gz * dy;
      }
      if (les) { /* Eq. 2.100 with f = mu = rho (nu + nu_r) */
        const double coef = vb * 0.5 * (mu_a + rb * (nu + nur[b])) * f / (r2 + eta2);
        const double vr = dplus2 * (ux * dx + uy * dy + uz * dz);
        vx += coef * (vr * dx + r2 * ux), vy += coef * (vr * dy + r2 * uy);
        vz += coef * (vr * dz + r2 * uz);
      } else if (violeau) {
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
    if (corrected) { /* -(1/rho_a) L_a g, L_a = A^-1 (Eq. 2.88, 2.90 with k = 0) */
      double gr[3];
      sph_solve_sym(M->dim, A, gc, gr);
      axa = -gr[0] * ira, aya = -gr[1] * ira, aza = -gr[2] * ira;
    }
    double kappa = 1.0, kx = 1.0, kz = 1.0; /* normalisation; Violeau: of the x and z parts */
    if (M->lap_norm != LAPNORM_NONE) {      /* discrete + analytic part behind the walls */
      const double qb = y[a] * ih, qt = (M->ly - y[a]) * ih;
      if (M->lap_norm == LAPNORM_TRACE) {
        kappa = -M->dim / (mom2 + wall_moment2(M->dim, qb) + wall_moment2(M->dim, qt));
        kx = kz = kappa;
      } else if (violeau) { /* its own y-y moments: -2 in the full space */
        const double wm = sph_violeau_moment(M, qb) + sph_violeau_moment(M, qt);
        kx = -2.0 / (m2x + wm);
        kz = M->dim == 3 ? -2.0 / (m2z + wm) : kx;
        kappa = 0.5 * (kx + kz);
      } else {
        kappa = -1.0 / (momyy + wall_moment_yy(M->dim, qb) + wall_moment_yy(M->dim, qt));
        kx = kz = kappa;
      }
    }
    const double lap = nu * ig * kappa; /* nu / gamma_a, normalised */
    const double vis = les ? ig / ra : violeau ? nu * ig / ra : nu * ig;
    axa += vis * kx * vx, aya += vis * kappa * vy, aza += vis * kz * vz;
    double awall = vis * kx * wvx; /* x-acceleration from the walls, for the statistics */
    /* wall terms: pressure (Eq. 3.17, k = 1) and wall shear (Eq. 2.147-2.148) */
    double gv = 0.0;
    for (int wall = 0; wall < 2; wall++) {
      const double d = wall ? M->ly - y[a] : y[a];
      const double q = d * ih;
      if (q >= 2.0) continue;
      const double dg = wall_dgamma(M->dim, q) * ih; /* |grad gamma_as| */
      const double ny = wall ? -1.0 : 1.0;           /* inward normal */
      const struct foot ft = wall_foot(M, W, wall, x[a], z[a]);
      const double rs = foot_value(M, &ft, W->rho), ps = foot_value(M, &ft, W->p);
      /* pressure wall term: |grad gamma_as| plus the excess of the discrete first moment on
         the particle lattice (so that a uniform pressure leaves the lattice in equilibrium yet
         pushes a displaced particle back), or of the current particles, or nothing
         (docs/theory.md) */
      const double pw = M->wall_pressure == WALL_PRESSURE_LATTICE      ? dg + lattice_excess(M, q)
                        : M->wall_pressure == WALL_PRESSURE_CONSISTENT ? fmax(dg, ny * mom1)
                                                                       : dg;
      if (!corrected) aya += ig * rs * (pa + ps / (rs * rs)) * pw * ny;
      if (wall_law) { /* -(2 / gamma_a) rho_s u_tau,s u_tau,s |grad gamma_as| / rho_a (Eq. 2.144-
                         2.145) with the vertex values of Ferrand Eq. 38 at the foot */
        const double sw = 2.0 * ig * dg * ira;
        const double tx = sw * foot_value(M, &ft, W->tx);
        axa -= tx, aza -= sw * foot_value(M, &ft, W->tz);
        awall -= tx;
      } else {
        /* |grad gamma_as|, or the discrete first moment that makes the Morris operator exact
           for a velocity varying linearly with the wall distance (docs/theory.md) */
        const double dw = 2.0 * nu * ig / (d > M->wall_dmin ? d : M->wall_dmin);
        if (violeau) { /* half the first moment of its x and z parts */
          const double wx = discrete ? 0.5 * fmax(0.0, ny * m1x) : dg;
          const double wz = discrete ? 0.5 * fmax(0.0, ny * m1z) : dg;
          axa -= dw * kx * wx * u[a], aza -= dw * kz * wz * w[a];
          awall -= dw * kx * wx * u[a];
        } else {
          const double weight = discrete ? fmax(0.0, ny * mom1) : dg;
          const double shear = 2.0 * lap * weight / (d > M->wall_dmin ? d : M->wall_dmin);
          axa -= shear * u[a], aza -= shear * w[a];
          awall -= shear * u[a];
        }
      }
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
