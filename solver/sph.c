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
#include "term_pressure.h"

#include <math.h>

#include "pair_loop.h"
#include "records.h"
#include "term_damper.h"
#include "term_diffusion.h"
#include "timers.h"
#include "wall.h"

void sph_model_init(struct model *M, const struct scene *s) {
  M->dim = s->dim;
  M->viscous = s->viscous;
  M->h = scene_h(s);
  M->dr = s->dr;
  M->k = kernel_make_shape(s->dim, M->h, s->kernel);
  M->e.rho0 = s->rho0, M->e.c0 = s->c0, M->e.zeta = s->zeta;
  M->e.pb = s->p_background * s->rho0 * s->c0 * s->c0;
  M->lx = s->lx, M->ly = 2.0 * s->delta, M->lz = s->dim == 3 ? s->lz : 1.0;
  M->nu = s->nu;
  M->inv_xi = 1.0 / scene_xi(s);
  diffusion_init(M, s);
  M->damper_zeta = damper_zeta_of(s->damper, s->rho0, s->c0, M->h);
  M->gy = s->gravity_y;
  M->wall_dmin = s->wall_dmin * s->dr;
  M->eta2 = s->eta2 * M->h * M->h;
  M->lap_norm = s->lap_norm;
  M->wall_weight = s->wall_weight;
  M->wall_pressure = s->wall_pressure;
  M->pgrad = s->pgrad;
  M->les = s->les; /* enum les_model: non-zero with an eddy viscosity */
  M->strain = s->strain;
  M->strain_lag = scene_strain_lag(s);
  M->van_driest = s->van_driest;
  M->cs = s->cs, M->delta_g = s->filter_h * M->h, M->a_plus = s->a_plus;
  M->cy = s->les == LES_PROFILE ? 0.0 : s->cy; /* a prescribed nu_r has no k_r */
  M->nu_prof = s->nu_prof;
  M->law = wall_law_make(s->wall_law, s->kappa, s->log_b);
  M->wall_tau = scene_wall_tau(s);
  M->shifting = s->shifting;
  M->shift_velocity = s->shift_velocity;
  M->wall_reflect = s->wall_collision == WALL_REFLECT;
  M->shift_ch2 = s->shift_coef * M->h * M->h;
  M->shift_iwdr = 1.0 / kernel_w(&M->k, s->dr);
  M->shift_max = 0.1 * s->dr;
  sph_lattice_excess_table(M);
  sph_violeau_table(M);
  records_init();
}

/** Integral over the half-space y > q (units of h) of y^2 F(r) ((n+2) x_t^2 / r^2 + 1), with
    x_t^2 the mean square of one wall-parallel component (r^2 - y^2)/(n - 1). */
static double violeau_wall_moment(int dim, int shape, double q) {
  if (q >= 2.0) return 0.0;
  const struct kernel K = kernel_make_shape(dim, 1.0, shape);
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
    M->vio_m2[k] = violeau_wall_moment(M->dim, M->k.shape, 2.0 * k / VIOLEAU_KNOTS);
}

double sph_violeau_moment(const struct model *M, double q) {
  if (q >= 2.0) return 0.0;
  if (q <= 0.0) return M->vio_m2[0];
  const double f = q * VIOLEAU_KNOTS / 2.0;
  const int k = (int)f;
  const double t = f - k;
  return (1.0 - t) * M->vio_m2[k] + t * M->vio_m2[k + 1];
}

/* The kgc moment matrix of layer j of the initial lattice (j = 0: the vertex row, half volume),
   its fluid and vertex neighbours plus the analytic part behind the wall (kgc_moment_behind),
   less the lattice's value far from the walls: tangential (*dxx) and wall-normal (*dyy). */
static void kgc_lattice_layer(const struct model *M, int j, int reach, double *dxx, double *dyy) {
  const struct kernel *K = &M->k;
  const double dr = M->dr, vol = pow(dr, M->dim);
  const int l0 = M->dim == 3 ? -reach : 0, l1 = M->dim == 3 ? reach : 0;
  double A[6] = {0, 0, 0, 0, 0, 0}, axx = 0.0, ayy = 0.0; /* near the wall, far from it */
  for (int k = j - reach; k <= j + reach; k++)
    for (int i = -reach; i <= reach; i++)
      for (int l = l0; l <= l1; l++) {
        if (k == j && i == 0 && l == 0) continue;
        const double dx = i * dr, dy = (j - k) * dr, r = sqrt((i * i + l * l) * dr * dr + dy * dy);
        const double f = kernel_f(K, r);
        axx -= vol * f * dx * dx, ayy -= vol * f * dy * dy;
        if (k < 0) continue;
        const double v = k == 0 ? 0.5 * vol : vol;
        A[0] -= v * f * dx * dx, A[3] -= v * f * dy * dy;
      }
  kgc_moment_behind(K, M->dim, K->inv_h, j * dr, 1e300, A);
  *dxx = A[0] - axx, *dyy = A[3] - ayy;
}

void sph_lattice_excess_table(struct model *M) {
  const struct kernel *K = &M->k;
  const double dr = M->dr, ih = K->inv_h, vol = pow(dr, M->dim);
  const int reach = (int)ceil(2.0 * M->h / dr); /* lattice offsets within the support */
  int n = 0;
  for (int j = 1; j * dr < 2.0 * M->h && n < LATTICE_KNOTS - 1; j++) {
    double mom1 = 0.0;  /* sum_b V_b (y_a - y_b) F_ab over the virtual lattice around layer j */
    double mom1s = 0.0; /* the same with the shift's anti-clustering factor */
    for (int k = 0; k <= j + reach; k++) {
      const double v = k == 0 ? 0.5 * vol : vol, dy = (j - k) * dr; /* k = 0: vertex row */
      for (int i = -reach; i <= reach; i++)
        for (int l = M->dim == 3 ? -reach : 0; l <= (M->dim == 3 ? reach : 0); l++) {
          if (k == j && i == 0 && l == 0) continue;
          const double r = sqrt((i * i + l * l) * dr * dr + dy * dy);
          mom1 += v * kernel_f(K, r) * dy;
          mom1s += v * kernel_f(K, r) * dy * (1.0 + sph_anticluster(kernel_w(K, r), M->shift_iwdr));
        }
    }
    const double q = j * dr * ih;
    kgc_lattice_layer(M, j, reach, &M->lat_kxx[n], &M->lat_kyy[n]);
    M->lat_q[n] = q;
    M->lat_e[n] = fmax(0.0, mom1 - wall_dgamma_of(&M->k, q) * ih);
    M->lat_s[n] = mom1s - wall_dgamma_of(&M->k, q) * ih;
    n++;
  }
  M->lat_q[n] = 2.0, M->lat_e[n] = M->lat_s[n] = M->lat_kxx[n] = M->lat_kyy[n] = 0.0;
  kgc_lattice_layer(M, 0, reach, &M->kgc_vxx, &M->kgc_vyy);
  M->n_lat = n + 1;
}

double sph_lattice_table(const struct model *M, const double *e, double q) {
  if (q >= 2.0) return 0.0;
  if (q <= M->lat_q[0]) return e[0];
  int k = 1;
  while (k < M->n_lat - 1 && M->lat_q[k] < q) k++;
  const double t = (q - M->lat_q[k - 1]) / (M->lat_q[k] - M->lat_q[k - 1]);
  return (1.0 - t) * e[k - 1] + t * e[k];
}

/** gamma of the channel: both walls' missing parts subtracted (they never overlap). */
static inline double channel_gamma(const struct model *M, double y) {
  const double ih = M->k.inv_h;
  return wall_gamma_of(&M->k, y * ih) + wall_gamma_of(&M->k, (M->ly - y) * ih) - 1.0;
}

/* Pressure pa (the equation of state's, or the damper's), sound speed, p / rho^2 and volume of
   fluid particle a from its density. */
static inline void density_state(const struct model *M, struct particles *P, size_t a, double pa) {
  const double r = P->rho[a];
  P->p[a] = pa, P->c[a] = eos_sound(&M->e, r);
  P->pr2[a] = pa / (r * r), P->vol[a] = P->m[a] / r;
}

void sph_density(const struct model *M, struct particles *P, const double *ksum_new, double dt) {
  timer_push("density");
  const double dtd = dt / M->diff_substeps; /* the force pass's D_a: the first sub-step */
  const double *restrict y = P->y;
  const uint8_t *restrict kind = P->kind;
  double *restrict drate = M->damper_zeta > 0.0 ? P->drate : NULL;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    if (kind[a] != KIND_FLUID) continue;
    const double s = ksum_new[a], gam = channel_gamma(M, y[a]), r_old = P->rho[a];
    if (dt > 0.0) P->rho[a] = (P->gam[a] * r_old + s - P->ksum[a] + dtd * P->ddiff[a]) / gam;
    P->ksum[a] = s;
    P->gam[a] = gam;
    const double r = P->rho[a];
    double pa = eos_pressure(&M->e, r);
    if (drate) { /* term_damper.h; restored (dt = 0): the rate of the checkpoint */
      if (dt > 0.0) drate[a] = damper_rate(r_old, r, dt, P->ddiff[a], gam);
      pa = damper_pressure(pa, M->damper_zeta, drate[a]);
    }
    density_state(M, P, a, pa);
  }
  timer_pop();
}

/* The volume diffusion's fluid-pair sum of particle a at the current state: the force pass's
   diffusion_pair (forces.c) without the forces, for one kernel shape. */
static inline __attribute__((always_inline)) double diffusion_sum(const struct model *M,
                                                                  const struct particles *P,
                                                                  const struct nbr *nb, size_t a,
                                                                  const int shape) {
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict rho = P->rho, *restrict vol = P->vol, *restrict c = P->c;
  const double dgrav = diffusion_dgrav(M), lr = M->diff_lr, lc = M->diff_lc;
  const int32_t *restrict nl = pair_list(nb, a);
  const double xa = x[a], ya = y[a], za = z[a], ra = rho[a], ca = c[a];
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (int j = 0; j < nb->nfluid[a]; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at_shape(&F, shape, xa - x[b], ya - y[b], za - z[b]);
    sum += diffusion_pair(&g, vol[b], ca, c[b], ra - rho[b], dgrav, lr, lc);
  }
  return sum;
}

/* D_a of the fluid particles a0 .. a1-1 into P->ddiff, for one kernel shape. */
static inline __attribute__((always_inline)) void diffusion_range(const struct model *M,
                                                                  struct particles *P,
                                                                  const struct nbr *nb, size_t a0,
                                                                  size_t a1, const int shape) {
  for (size_t a = a0; a < a1; a++)
    if (P->kind[a] == KIND_FLUID)
      P->ddiff[a] = diffusion_finish(M, diffusion_sum(M, P, nb, a, shape));
}

/* One function per kernel shape, called per chunk from the parallel loop, as the force loops
   (forces.c): with both shapes inlined into the parallel loop's body GCC 12 left the pair loop
   scalar in every clone; so the x86-64-v4 clone runs it in 64-byte vectors (the others stay
   scalar: not profitable by GCC's cost model). The pass took as long either way (17 ms a step
   at dr+ = 9 on 2 threads): it waits on memory (docs/validation/scheme_ab.md). */
typedef void (*diffusion_loop)(const struct model *M, struct particles *P, const struct nbr *nb,
                               size_t a0, size_t a1);
static CHANSPH_CLONES void diffusion_range_C2(const struct model *M, struct particles *P,
                                              const struct nbr *nb, size_t a0, size_t a1) {
  diffusion_range(M, P, nb, a0, a1, KERNEL_C2);
}
static CHANSPH_CLONES void diffusion_range_C4(const struct model *M, struct particles *P,
                                              const struct nbr *nb, size_t a0, size_t a1) {
  diffusion_range(M, P, nb, a0, a1, KERNEL_C4);
}

/* D_a of every fluid particle into P->ddiff (each particle's sum on its own: any chunking and
   thread count give the same bits). */
static void diffusion_rates(const struct model *M, struct particles *P, const struct nbr *nb) {
  const diffusion_loop loop = M->k.shape == KERNEL_C4 ? diffusion_range_C4 : diffusion_range_C2;
  enum { CHUNK = 64 };
  const size_t n = P->n;
#pragma omp parallel for schedule(static)
  for (size_t a0 = 0; a0 < n; a0 += CHUNK) loop(M, P, nb, a0, a0 + CHUNK < n ? a0 + CHUNK : n);
}

void sph_diffusion_substep(const struct model *M, struct particles *P, const struct nbr *nb,
                           double dts) {
  timer_push("diffusion sub-steps");
  diffusion_rates(M, P, nb);
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    P->rho[a] += dts * P->ddiff[a] / P->gam[a];
    density_state(M, P, a, eos_pressure(&M->e, P->rho[a]));
  }
  timer_pop();
}

/* Shepard sums of vertex v over its fluid neighbours (the first nfluid of its list):
   out = {sum V_b w_vb, sum m_b w_vb, sum V_b (p_b/rho_b + g_y (y_v - y_b)) w_vb}. */
static CHANSPH_CLONES void vertex_shepard(const struct model *M, const struct particles *P,
                                          const struct nbr *nb, size_t v, double out[3]) {
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z, *restrict m = P->m;
  const double *restrict rho = P->rho, *restrict p = P->p, *restrict V = P->vol;
  const int32_t *restrict nl = pair_list(nb, v);
  const double xv = x[v], yv = y[v], zv = z[v], gy = M->gy;
  double alpha = 0.0, mw = 0.0, pw = 0.0;
#pragma omp simd reduction(+ : alpha, mw, pw)
  for (int j = 0; j < nb->nfluid[v]; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xv - x[b], yv - y[b], zv - z[b]);
    const double wvb = kernel_w(&F.K, g.r), vol = V[b]; /* m_b / rho_b, set by sph_density */
    alpha += vol * wvb;
    mw += m[b] * wvb;
    pw += vol * (p[b] / rho[b] + gy * g.dy) * wvb;
  }
  out[0] = alpha, out[1] = mw, out[2] = pw;
}

void sph_walls(const struct model *M, struct particles *P, const struct nbr *nb, struct walls *W) {
  timer_push("walls");
  const double *restrict m = P->m;
  const uint8_t *restrict kind = P->kind;
#pragma omp parallel for schedule(static)
  for (size_t v = 0; v < P->n; v++) {
    if (kind[v] != KIND_VERTEX) continue;
    double sum[3];
    vertex_shepard(M, P, nb, v, sum);
    double rv = M->e.rho0, pv = 0.0;
    if (sum[0] > 0.0) rv = sum[1] / sum[0], pv = rv * sum[2] / sum[0];
    P->rho[v] = rv, P->p[v] = pv;
    P->c[v] = eos_sound(&M->e, rv);
    P->pr2[v] = pv / (rv * rv), P->vol[v] = m[v] / rv;
    const size_t slot = part_vertex_slot(P, P->id[v]);
    W->rho[slot] = rv, W->p[slot] = pv;
  }
  timer_pop();
}

/* sph.h; the wall law (turb.c) and sph_kr_pressure use it. */
CHANSPH_CLONES double sph_vertex_sums(const struct model *M, const struct particles *P,
                                      const struct nbr *nb, size_t s, int nf,
                                      const double *const *f, double *out) {
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict vol = P->vol, *restrict f0 = f[0], *restrict f1 = nf > 1 ? f[1] : f[0];
  const int32_t *restrict nl = pair_list(nb, s);
  const double xs = x[s], ys = y[s], zs = z[s];
  double alpha = 0.0, s0 = 0.0, s1 = 0.0;
#pragma omp simd reduction(+ : alpha, s0, s1)
  for (int j = 0; j < nb->nfluid[s]; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xs - x[b], ys - y[b], zs - z[b]);
    const double vw = vol[b] * kernel_w(&F.K, g.r);
    alpha += vw, s0 += vw * f0[b], s1 += vw * f1[b];
  }
  out[0] = s0;
  if (nf > 1) out[1] = s1;
  return alpha;
}

void sph_kr_pressure(const struct model *M, struct particles *P, const struct nbr *nb,
                     struct walls *W) {
  timer_push("les");
  const double *restrict rho = P->rho, *restrict kr = P->kr;
#pragma omp parallel for schedule(static)
  for (size_t s = 0; s < P->n; s++) {
    if (P->kind[s] == KIND_FLUID) {
      P->pr2[s] += 2.0 / 3.0 * kr[s] / rho[s];
      continue;
    }
    const double *krf[1] = {kr};
    double sk;
    const double alpha = sph_vertex_sums(M, P, nb, s, 1, krf, &sk);
    const double ks = alpha > 0.0 ? sk / alpha : 0.0, extra = 2.0 / 3.0 * rho[s] * ks;
    P->pr2[s] += extra / (rho[s] * rho[s]);
    W->p[part_vertex_slot(P, P->id[s])] += extra;
  }
  timer_pop();
}

void sph_wall_values(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *p) {
  const struct foot f = sph_foot(M, W, wall, x, z);
  *rho = sph_foot_value(M, &f, W->rho);
  *p = sph_foot_value(M, &f, W->p);
}

void sph_wall_stress(const struct model *M, const struct walls *W, int wall, double x, double z,
                     double *rho, double *tx, double *tz) {
  const struct foot f = sph_foot(M, W, wall, x, z);
  *rho = sph_foot_value(M, &f, W->rho);
  *tx = sph_foot_value(M, &f, W->tx);
  *tz = sph_foot_value(M, &f, W->tz);
}

void sph_sym_factor(int dim, const double A[6], struct sym_solve *f) {
  f->dim = dim;
  if (dim == 2) {
    f->det = A[0] * A[3] - A[1] * A[1];
    f->tr = A[0] + A[3];
    f->deg = !(fabs(f->det) > 1e-12 * f->tr * f->tr); /* degenerate support: uncorrected */
    f->c[0] = A[3], f->c[1] = A[1], f->c[2] = A[0];
    return;
  }
  /* A = [a b c; b d e; c e f] stored as {a, b, c, d, e, f} */
  const double a = A[0], b = A[1], c = A[2], d = A[3], e = A[4], ff = A[5];
  f->c[0] = d * ff - e * e, f->c[1] = c * e - b * ff, f->c[2] = b * e - c * d;
  f->det = a * f->c[0] + b * f->c[1] + c * f->c[2];
  f->tr = a + d + ff;
  f->deg = !(fabs(f->det) > 1e-12 * f->tr * f->tr * f->tr);
  f->c[3] = a * ff - c * c, f->c[4] = b * c - a * e, f->c[5] = a * d - b * b;
}

void sph_sym_apply(const struct sym_solve *f, const double g[3], double x[3]) {
  const double *c = f->c, det = f->det, tr = f->tr;
  if (f->deg) {
    const double n = f->dim;
    for (int i = 0; i < 3; i++) x[i] = i < f->dim && tr > 0 ? n * g[i] / tr : 0.0;
    return;
  }
  if (f->dim == 2) {
    x[0] = (c[0] * g[0] - c[1] * g[1]) / det;
    x[1] = (c[2] * g[1] - c[1] * g[0]) / det;
    x[2] = 0.0;
    return;
  }
  x[0] = (c[0] * g[0] + c[1] * g[1] + c[2] * g[2]) / det;
  x[1] = (c[1] * g[0] + c[3] * g[1] + c[4] * g[2]) / det;
  x[2] = (c[2] * g[0] + c[4] * g[1] + c[5] * g[2]) / det;
}

void sph_solve_sym(int dim, const double A[6], const double g[3], double x[3]) {
  struct sym_solve f;
  sph_sym_factor(dim, A, &f);
  sph_sym_apply(&f, g, x);
}
