/**
 * @file forces.c
 * @brief sph_forces (sph.h): the accelerations of the fluid particles and the volume-diffusion
 *        sum, assembled from the pair terms of pair.h.
 *
 * The terms a scene needs are fixed for the whole run, so the pair loop is specialised once per
 * combination (data path x viscous operator x pressure-gradient form: the table `loops` below)
 * and chosen before the particle loop; the loops have no branches per pair and vectorise. The
 * data path: with AVX-512 the neighbours' pair records are gathered into contiguous buffers
 * (records.h), otherwise the loops read the particle arrays through the list. Each particle's
 * neighbour list holds its fluid neighbours first, then the wall vertices (nbr.h): the fluid
 * part adds the volume diffusion, the vertex part gives the viscous pull of the wall for the
 * wall shear stress of the statistics. The per-particle part (normalisation, wall terms,
 * time-step maxima) follows the sums in force_finish().
 *
 * Determinism: a particle's sums depend only on its own neighbour list, whose order is the same
 * on any number of threads and ranks (nbr.h), and every list starts at the same alignment, so
 * the vectorised partial sums are formed in the same order everywhere.
 */
#include <math.h>
#include <omp.h>
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#include <immintrin.h>
#endif

#include "pair.h"
#include "records.h"
#include "sph.h"
#include "timers.h"
#include "turb.h"
#include "wall.h"

/** The viscous operator of a loop; VK_LES_LAG: the LES loop that also forms the velocity-gradient
    sums of the next step's eddy viscosity (les.strain_lag). */
enum visc_kind { VK_MORRIS, VK_VIOLEAU, VK_LES, VK_LES_LAG, VK_N };

/** What every loop reads. */
struct fctx {
  const struct model *M;
  const struct particles *P;
  const struct nbr *nb;
  const struct walls *W;
  double fx;                  /*!< driving acceleration (time-step limit only) [m/s^2] */
  double *wall_ax;            /*!< x-acceleration from the walls, or NULL */
  double *sx;                 /*!< parts of the x-acceleration (enum part_sx), or NULL */
  double *nur_next, *kr_next; /*!< VK_LES_LAG: nu_r and k_r of the next step */
};

/** Pair sums of one particle over one part of its neighbour list. */
struct fsums {
  struct v3 gp;    /*!< pressure, symmetric form */
  struct v3 vis;   /*!< viscous operator */
  struct v3 mom;   /*!< moments: r^2, y^2, y (term_moments) */
  double diff;     /*!< volume diffusion (fluid part only) */
  double m1x, m2x; /*!< Violeau's wall moments, x part */
  double m1z, m2z; /*!< and z part */
  struct sym3 A;   /*!< moment matrix of the corrected gradient */
  struct v3 gc;    /*!< corrected pressure difference gradient */
};

/* pair_sums (double) and pair_sums_f (sph.precision = mixed: float pair terms, double sums),
   one source: forces_pair.h. */
#define R double
#define PF(name) name
#include "forces_pair.h"
#undef R
#undef PF
#define R float
#define PF(name) name##_f
#include "forces_pair.h"
#undef R
#undef PF

/** les.strain_lag: the corrected velocity-gradient sums of particle a over its whole list (n
    neighbours), A = -sum_b V_b F_ab r_ab (x) r_ab and B = sum_b (v_b - v_a) (x) V_b F_ab r_ab
    (thesis Eq. 2.88-2.90, k = 0; as turb_strain_gradient takes them), from the pair geometry
    the pair loops kept in geo (V_b F_ab in field 0, r_ab in 1-3, ld apart) and the
    neighbours' velocities (gathered or through the list): no distance, kernel or gather again. */
static inline __attribute__((always_inline)) void strain_sums(const struct fctx *C, size_t a,
                                                              const double *bf, int ld,
                                                              const int32_t *restrict nl, int n,
                                                              const int gathered,
                                                              double ab[][TURB_CHUNK], int i) {
  const struct particles *P = C->P;
  const double *restrict u = gathered ? bf + (size_t)REC_U * ld : P->u;
  const double *restrict v = gathered ? bf + (size_t)REC_V * ld : P->v;
  const double *restrict w = gathered ? bf + (size_t)REC_W * ld : P->w;
  const double *restrict geo = bf + (size_t)PAIRBUF_RECORDS * ld;
  const double *restrict vf = geo, *restrict dx = geo + ld, *restrict dy = geo + 2 * (size_t)ld;
  const double *restrict dz = geo + 3 * (size_t)ld;
  const double ua = P->u[a], va = P->v[a], wa = P->w[a];
  double axx = 0, axy = 0, axz = 0, ayy = 0, ayz = 0, azz = 0;
  double bxx = 0, bxy = 0, bxz = 0, byx = 0, byy = 0, byz = 0, bzx = 0, bzy = 0, bzz = 0;
#pragma omp simd reduction(+ : axx, axy, axz, ayy, ayz, azz, bxx, bxy, bxz, byx, byy, byz, bzx, \
                               bzy, bzz)
  for (int j = 0; j < n; j++) {
    const int32_t b = gathered ? j : nl[j];
    const double qx = vf[j] * dx[j], qy = vf[j] * dy[j], qz = vf[j] * dz[j];
    axx -= qx * dx[j], axy -= qx * dy[j], axz -= qx * dz[j];
    ayy -= qy * dy[j], ayz -= qy * dz[j], azz -= qz * dz[j];
    const double du = u[b] - ua, dv = v[b] - va, dw = w[b] - wa;
    bxx += du * qx, bxy += du * qy, bxz += du * qz;
    byx += dv * qx, byy += dv * qy, byz += dv * qz;
    bzx += dw * qx, bzy += dw * qy, bzz += dw * qz;
  }
  const double sums[15] = {axx, axy, axz, ayy, ayz, azz, bxx, bxy,
                           bxz, byx, byy, byz, bzx, bzy, bzz};
  for (int k = 0; k < 15; k++) ab[k][i] = sums[k];
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
/** strain_sums over the gathered records (only used where the processor has AVX-512: records.h),
    written with AVX-512 intrinsics: the list is padded to whole vectors (gather_padded), the
    products are added with fused multiply-adds (21 vector operations per 8 pairs instead of
    36; every processor that takes this path has them, so a run's results do not depend on the
    path), and the 15 sums are reduced each with a shuffle tree instead of the compiler's
    reduction of an `omp simd` loop, which goes through memory lane by lane (30% of the loop's
    time). */
__attribute__((target("avx512f"), noinline)) static void strain_sums_gathered(
    const struct fctx *C, size_t a, const double *bf, int ld, const int32_t *restrict nl, int n,
    double ab[][TURB_CHUNK], int i) {
  (void)nl;
  const double *u = bf + (size_t)REC_U * ld, *v = bf + (size_t)REC_V * ld;
  const double *w = bf + (size_t)REC_W * ld, *geo = bf + (size_t)PAIRBUF_RECORDS * ld;
  const __m512d ua = _mm512_set1_pd(C->P->u[a]), va = _mm512_set1_pd(C->P->v[a]);
  const __m512d wa = _mm512_set1_pd(C->P->w[a]);
  const __m512d zero = _mm512_setzero_pd();
  __m512d axx = zero, axy = zero, axz = zero, ayy = zero, ayz = zero, azz = zero;
  __m512d bxx = zero, bxy = zero, bxz = zero, byx = zero, byy = zero, byz = zero;
  __m512d bzx = zero, bzy = zero, bzz = zero;
  for (int j = 0; j < n; j += 8) { /* n is a multiple of 8: whole vectors, aligned */
    const __m512d vf = _mm512_load_pd(geo + j), dx = _mm512_load_pd(geo + ld + j);
    const __m512d dy = _mm512_load_pd(geo + 2 * (size_t)ld + j);
    const __m512d dz = _mm512_load_pd(geo + 3 * (size_t)ld + j);
    const __m512d qx = _mm512_mul_pd(vf, dx), qy = _mm512_mul_pd(vf, dy);
    const __m512d qz = _mm512_mul_pd(vf, dz);
    axx = _mm512_fnmadd_pd(qx, dx, axx); /* A = -sum V_b F r (x) r */
    axy = _mm512_fnmadd_pd(qx, dy, axy);
    axz = _mm512_fnmadd_pd(qx, dz, axz);
    ayy = _mm512_fnmadd_pd(qy, dy, ayy);
    ayz = _mm512_fnmadd_pd(qy, dz, ayz);
    azz = _mm512_fnmadd_pd(qz, dz, azz);
    const __m512d du = _mm512_sub_pd(_mm512_load_pd(u + j), ua); /* B = sum (v_b - v_a) (x) */
    const __m512d dv = _mm512_sub_pd(_mm512_load_pd(v + j), va); /* V_b F r */
    const __m512d dw = _mm512_sub_pd(_mm512_load_pd(w + j), wa);
    bxx = _mm512_fmadd_pd(du, qx, bxx);
    bxy = _mm512_fmadd_pd(du, qy, bxy);
    bxz = _mm512_fmadd_pd(du, qz, bxz);
    byx = _mm512_fmadd_pd(dv, qx, byx);
    byy = _mm512_fmadd_pd(dv, qy, byy);
    byz = _mm512_fmadd_pd(dv, qz, byz);
    bzx = _mm512_fmadd_pd(dw, qx, bzx);
    bzy = _mm512_fmadd_pd(dw, qy, bzy);
    bzz = _mm512_fmadd_pd(dw, qz, bzz);
  }
  const __m512d acc[15] = {axx, axy, axz, ayy, ayz, azz, bxx, bxy,
                           bxz, byx, byy, byz, bzx, bzy, bzz};
  for (int k = 0; k < 15; k++) ab[k][i] = _mm512_reduce_add_pd(acc[k]);
}
#else
static CHANSPH_CLONES __attribute__((noinline)) void strain_sums_gathered(
    const struct fctx *C, size_t a, const double *bf, int ld, const int32_t *restrict nl, int n,
    double ab[][TURB_CHUNK], int i) {
  strain_sums(C, a, bf, ld, nl, n, 1, ab, i);
}
#endif

static CHANSPH_CLONES __attribute__((noinline)) void strain_sums_arrays(
    const struct fctx *C, size_t a, const double *bf, int ld, const int32_t *restrict nl, int n,
    double ab[][TURB_CHUNK], int i) {
  strain_sums(C, a, bf, ld, nl, n, 0, ab, i);
}

/** LES: the x part of Violeau's sum over the fluid neighbours of a with the molecular viscosity
    only (mu_ab = rho_ab nu), the same terms as pair_sums (the statistics' budget, on sampled
    steps only; vectorised, so its sum is in a different order from pair_sums'). */
static CHANSPH_CLONES double molecular_x(const struct fctx *C, size_t a) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  const struct kernel K = M->k;
  const int32_t *restrict nl = C->nb->list + a * (size_t)C->nb->stride;
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict u = P->u, *restrict v = P->v, *restrict w = P->w;
  const double *restrict vol = P->vol, *restrict rho = P->rho;
  const double xa = x[a], ya = y[a], za = z[a], ra = rho[a], ua = u[a], va = v[a], wa = w[a];
  const double lx = M->lx, lz = M->lz, nu = M->nu, np2 = M->dim + 2.0, eta2 = M->eta2;
  const int d3 = M->dim == 3, nf = C->nb->nfluid[a];
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (int j = 0; j < nf; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_geom(&K, lx, lz, d3, xa - x[b], ya - y[b], za - z[b]);
    const struct v3 uab = {ua - u[b], va - v[b], wa - w[b]};
    sum += term_violeau(&g, vol[b], 0.5 * (ra + rho[b]) * nu, np2, eta2, uab).x;
  }
  return sum;
}

/** The x-acceleration of particle a by its fluid neighbours, split by term into
    sx[SX_PRESSURE .. SX_MODEL]: the expressions of force_finish applied to the fluid part s of
    the sums (sv: the vertex part, for the matrix of the corrected gradient, which both parts
    share); visk: the viscous prefactor with its normalisation. The rest of ax is the walls'. */
static void budget_parts(const struct fctx *C, size_t a, const struct fsums *s,
                         const struct fsums *sv, double visk, double *sx) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  if (M->pgrad == PGRAD_CORRECTED) { /* -(1/rho_a) L_a g, g of the fluid neighbours only */
    const double A[6] = {s->A.xx + sv->A.xx, s->A.xy + sv->A.xy, s->A.xz + sv->A.xz,
                         s->A.yy + sv->A.yy, s->A.yz + sv->A.yz, s->A.zz + sv->A.zz};
    const double gc[3] = {s->gc.x, s->gc.y, s->gc.z};
    double gr[3];
    sph_solve_sym(M->dim, A, gc, gr);
    sx[SX_PRESSURE] = -gr[0] / P->rho[a];
  } else {
    sx[SX_PRESSURE] = -s->gp.x / P->gam[a];
  }
  /* with LES the viscous sum holds rho (nu + nu_r): its part with rho nu from one more pass
     over the fluid neighbours, on the sampled steps only (not in the hot loop) */
  sx[SX_VISCOUS] = visk * (M->les ? molecular_x(C, a) : s->vis.x);
  sx[SX_MODEL] = M->les ? visk * s->vis.x - sx[SX_VISCOUS] : 0.0;
}

/** What the wall terms of force_finish take from it. */
struct wall_ctx {
  double ig, ira, pa;    /*!< 1/gamma_a, 1/rho_a, p_a/rho_a^2 */
  double lap, kx, kz;    /*!< nu/gamma_a normalised; the normalisations of x and z */
  double m1x, m1z, mom1; /*!< first moments: Violeau's x and z parts, the full one */
};

/** The wall terms of fluid particle a added to acc = {ax, ay, az, ax from the walls}: the
    pressure wall term (Eq. 3.17, k = 1) and the wall shear (Eq. 2.147-2.148, or the wall law);
    returns max over the walls of |grad gamma_as . v_a| for the time step. */
static double wall_terms(const struct fctx *C, size_t a, const struct wall_ctx *wc, double acc[4]) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  const struct walls *W = C->W;
  const double ih = M->k.inv_h, nu = M->nu, ig = wc->ig, ira = wc->ira, pa = wc->pa;
  const double lap = wc->lap, kx = wc->kx, kz = wc->kz, m1x = wc->m1x, m1z = wc->m1z;
  const double mom1 = wc->mom1, ya = P->y[a], ua = P->u[a], va = P->v[a], wa = P->w[a];
  const int violeau = M->viscous == VISCOUS_VIOLEAU;
  const int corrected = M->pgrad == PGRAD_CORRECTED;
  const int discrete = M->wall_weight == WALL_WEIGHT_DISCRETE;
  double axa = acc[0], aya = acc[1], aza = acc[2], awall = acc[3];
  double gv = 0.0;
  for (int wall = 0; wall < 2; wall++) {
    const double d = wall ? M->ly - ya : ya;
    const double q = d * ih;
    if (q >= 2.0) continue;
    const double dg = wall_dgamma(M->dim, q) * ih; /* |grad gamma_as| */
    const double ny = wall ? -1.0 : 1.0;           /* inward normal */
    const struct foot ft = sph_foot(M, W, wall, P->x[a], P->z[a]);
    const double rs = sph_foot_value(M, &ft, W->rho), ps = sph_foot_value(M, &ft, W->p);
    /* pressure wall term: |grad gamma_as| plus the excess of the discrete first moment on
       the particle lattice (so that a uniform pressure leaves the lattice in equilibrium yet
       pushes a displaced particle back), or of the current particles, or nothing
       (docs/theory.md) */
    const double pw = M->wall_pressure == WALL_PRESSURE_LATTICE
                          ? dg + sph_lattice_table(M, M->lat_e, q)
                      : M->wall_pressure == WALL_PRESSURE_CONSISTENT ? fmax(dg, ny * mom1)
                                                                     : dg;
    if (!corrected) aya += ig * rs * (pa + ps / (rs * rs)) * pw * ny;
    if (M->law.law != WALL_LAW_LAMINAR) {
      /* -(2 / gamma_a) rho_s u_tau,s u_tau,s |grad gamma_as| / rho_a (Eq. 2.144-2.145) with
         the vertex values of Ferrand Eq. 38 at the foot */
      const double sw = 2.0 * ig * dg * ira;
      const double tx = sw * sph_foot_value(M, &ft, W->tx);
      axa -= tx, aza -= sw * sph_foot_value(M, &ft, W->tz);
      awall -= tx;
    } else {
      /* |grad gamma_as|, or the discrete first moment that makes the Morris operator exact
         for a velocity varying linearly with the wall distance (docs/theory.md) */
      const double dist = d > M->wall_dmin ? d : M->wall_dmin;
      if (violeau) { /* half the first moment of its x and z parts */
        const double dw = 2.0 * nu * ig / dist;
        const double wx = discrete ? 0.5 * fmax(0.0, ny * m1x) : dg;
        const double wz = discrete ? 0.5 * fmax(0.0, ny * m1z) : dg;
        axa -= dw * kx * wx * ua, aza -= dw * kz * wz * wa;
        awall -= dw * kx * wx * ua;
      } else {
        const double weight = discrete ? fmax(0.0, ny * mom1) : dg;
        const double shear = 2.0 * lap * weight / dist;
        axa -= shear * ua, aza -= shear * wa;
        awall -= shear * ua;
      }
    }
    const double g = fabs(dg * va);
    if (g > gv) gv = g;
  }
  acc[0] = axa, acc[1] = aya, acc[2] = aza, acc[3] = awall;
  return gv;
}

/** Acceleration of fluid particle a from its pair sums (fluid part s, vertex part sv): the
    normalisation of the viscous sum, the wall terms, the body force; the time-step maxima go to
    mx[0] (max |a|^2) and mx[1] (max |grad gamma . v|). */
static void force_finish(const struct fctx *C, size_t a, const struct fsums *s,
                         const struct fsums *sv, double mx[2]) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  const double ih = M->k.inv_h, nu = M->nu, ra = P->rho[a], ira = 1.0 / ra, pa = P->pr2[a];
  const double ya = P->y[a];
  const int violeau = M->viscous == VISCOUS_VIOLEAU, les = M->les;
  const int corrected = M->pgrad == PGRAD_CORRECTED;
  const double ig = 1.0 / P->gam[a];
  const double mom2 = s->mom.x + sv->mom.x, momyy = s->mom.y + sv->mom.y;
  const double mom1 = s->mom.z + sv->mom.z;
  const double m1x = s->m1x + sv->m1x, m2x = s->m2x + sv->m2x;
  const double m1z = s->m1z + sv->m1z, m2z = s->m2z + sv->m2z;
  const double vx = s->vis.x + sv->vis.x, vy = s->vis.y + sv->vis.y, vz = s->vis.z + sv->vis.z;
  double axa, aya, aza;
  if (corrected) { /* -(1/rho_a) L_a g, L_a = A^-1 (Eq. 2.88, 2.90 with k = 0) */
    const double A[6] = {s->A.xx + sv->A.xx, s->A.xy + sv->A.xy, s->A.xz + sv->A.xz,
                         s->A.yy + sv->A.yy, s->A.yz + sv->A.yz, s->A.zz + sv->A.zz};
    const double gc[3] = {s->gc.x + sv->gc.x, s->gc.y + sv->gc.y, s->gc.z + sv->gc.z};
    double gr[3];
    sph_solve_sym(M->dim, A, gc, gr);
    axa = -gr[0] * ira, aya = -gr[1] * ira, aza = -gr[2] * ira;
  } else {
    axa = -ig * (s->gp.x + sv->gp.x), aya = -ig * (s->gp.y + sv->gp.y);
    aza = -ig * (s->gp.z + sv->gp.z);
  }
  double kappa = 1.0, kx = 1.0, kz = 1.0; /* normalisation; Violeau: of the x and z parts */
  if (M->lap_norm != LAPNORM_NONE) {      /* discrete + analytic part behind the walls */
    const double qb = ya * ih, qt = (M->ly - ya) * ih;
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
  double awall = vis * kx * sv->vis.x; /* x-acceleration from the walls, for the statistics */
  /* wall terms: pressure (Eq. 3.17, k = 1) and wall shear (Eq. 2.147-2.148) */
  const struct wall_ctx wc = {ig, ira, pa, lap, kx, kz, m1x, m1z, mom1};
  double acc[4] = {axa, aya, aza, awall};
  const double gv = wall_terms(C, a, &wc, acc);
  axa = acc[0], aya = acc[1], aza = acc[2], awall = acc[3];
  aya += M->gy;
  if (C->sx) budget_parts(C, a, s, sv, vis * kx, C->sx + a * SX_LEN);
  P->ax[a] = axa, P->ay[a] = aya, P->az[a] = aza;
  if (C->sx)
    C->sx[a * SX_LEN + SX_WALL] = axa - C->sx[a * SX_LEN + SX_PRESSURE] -
                                  C->sx[a * SX_LEN + SX_VISCOUS] - C->sx[a * SX_LEN + SX_MODEL];
  if (C->wall_ax) C->wall_ax[a] = awall;
  P->ddiff[a] = s->diff * M->inv_xi; /* enters gamma rho directly (Eq. 3.64): no 1/gamma */
  const double ax2 = (axa + C->fx) * (axa + C->fx) + aya * aya + aza * aza;
  if (ax2 > mx[0]) mx[0] = ax2;
  if (gv > mx[1]) mx[1] = gv;
}

/** Zero the fields a pair loop reads (records.h: fields 0-7 of half 0 and REC_M .. REC_NUR of
    half 1) at entries j .. j+7 of a pair buffer: zero records, whose pair terms are exact
    zeros (V_b = m_b = rho_b = 0 and finite geometry). */
static inline void pad_zero(double *bf, int ld, int j) {
  for (int f = 0; f < REC_NUR + 1; f++)
    for (int k = 0; k < 8; k++) bf[(size_t)f * ld + j + k] = 0.0;
}

/** Gather the records of a list of n neighbours, nf of them fluid, with each part padded by
    zero records to a multiple of 8 entries, so that the pair loops over the parts run in whole
    vectors (no scalar remainder): the fluid part at 0 .. nf8-1, the vertices from nf8 on;
    returns the end of the padded vertex part. The buffer's ld (nbr.h pairbuf_ld) holds them. */
static inline int gather_padded(const double *rec, const int32_t *nl, int nf, int n, double *bf,
                                int ld, int *nf8) {
  const int nv = n - nf;
  *nf8 = (nf + 7) & ~7;
  records_gather(rec, nl, nf, 0, bf, ld);
  records_gather(rec, nl, nf, 1, bf + 8 * (size_t)ld, ld);
  pad_zero(bf, ld, nf);
  if (nv > 0) {
    records_gather(rec, nl + nf, nv, 0, bf + *nf8, ld);
    records_gather(rec, nl + nf, nv, 1, bf + 8 * (size_t)ld + *nf8, ld);
    pad_zero(bf, ld, *nf8 + nv);
  }
  return *nf8 + ((nv + 7) & ~7);
}

/** One specialised loop over the fluid particles a0 .. a1-1. */
typedef void (*force_loop)(const struct fctx *C, size_t a0, size_t a1, double mx[2]);

/* The loop over particles a0 .. a1-1 for one combination; `gathered`: read the neighbours'
   gathered records (AVX-512), else the particle arrays through the list; `sp`: float pair
   terms (sph.precision = mixed). */
static inline __attribute__((always_inline)) void force_range(const struct fctx *C, size_t a0,
                                                              size_t a1, double mx[2],
                                                              const int visc, const int corr,
                                                              const int gathered, const int sp) {
  const struct nbr *nb = C->nb;
  const struct particles *P = C->P;
  const int ld = nb->pairbuf_ld;
  double *bf = nb->pairbuf[omp_get_thread_num()];
  double ab[15][TURB_CHUNK]; /* VK_LES_LAG: the strain sums of the chunk */
  for (size_t a = a0; a < a1; a++) {
    if (P->kind[a] != KIND_FLUID) {
      if (visc == VK_LES_LAG)
        for (int k = 0; k < 15; k++) ab[k][a - a0] = 0.0;
      continue;
    }
    const int32_t *nl = nb->list + a * (size_t)nb->stride;
    /* the fluid part of the list is 0 .. nf-1, the vertices nf .. n-1; gathered, each part
       padded to whole vectors (gather_padded) */
    int nf = nb->nfluid[a], n = nb->count[a];
    if (gathered) n = gather_padded(P->rec, nl, nf, n, bf, ld, &nf);
    struct fsums s, sv;
    if (sp) {
      pair_sums_f(C, a, bf, ld, nl, 0, nf, gathered, 1, visc, corr, &s);
      pair_sums_f(C, a, bf, ld, nl, nf, n, gathered, 0, visc, corr, &sv);
    } else {
      pair_sums(C, a, bf, ld, nl, 0, nf, gathered, 1, visc, corr, &s);
      pair_sums(C, a, bf, ld, nl, nf, n, gathered, 0, visc, corr, &sv);
    }
    force_finish(C, a, &s, &sv, mx);
    if (visc == VK_LES_LAG) { /* the strain sums of this state, for the next step */
      if (gathered)
        strain_sums_gathered(C, a, bf, ld, nl, n, ab, (int)(a - a0));
      else
        strain_sums_arrays(C, a, bf, ld, nl, n, ab, (int)(a - a0));
    }
  }
  if (visc == VK_LES_LAG) /* and the model of the whole chunk */
    turb_model_chunk(C->M, P, C->W, a0, (int)(a1 - a0), (const double(*)[TURB_CHUNK])ab,
                     C->nur_next + a0, C->kr_next + a0);
}

/* One function per combination, each built for several instruction sets (pair.h): for one
   precision (suffix, sp) and data path (gathered), the four viscous operators by the two
   pressure-gradient forms, and their row of the table `loops`. */
#define FORCE_LOOP(name, visc, corr, gathered, sp)                                            \
  static CHANSPH_CLONES void name(const struct fctx *C, size_t a0, size_t a1, double mx[2]) { \
    force_range(C, a0, a1, mx, visc, corr, gathered, sp);                                     \
  }
#define FORCE_LOOPS(sfx, gathered, sp)                                   \
  FORCE_LOOP(forces_morris##sfx, VK_MORRIS, 0, gathered, sp)             \
  FORCE_LOOP(forces_morris_corrected##sfx, VK_MORRIS, 1, gathered, sp)   \
  FORCE_LOOP(forces_violeau##sfx, VK_VIOLEAU, 0, gathered, sp)           \
  FORCE_LOOP(forces_violeau_corrected##sfx, VK_VIOLEAU, 1, gathered, sp) \
  FORCE_LOOP(forces_les##sfx, VK_LES, 0, gathered, sp)                   \
  FORCE_LOOP(forces_les_corrected##sfx, VK_LES, 1, gathered, sp)         \
  FORCE_LOOP(forces_les_lag##sfx, VK_LES_LAG, 0, gathered, sp)           \
  FORCE_LOOP(forces_les_lag_corrected##sfx, VK_LES_LAG, 1, gathered, sp)
#define FORCE_ROW(sfx)                                        \
  {                                                           \
    {forces_morris##sfx, forces_morris_corrected##sfx},       \
        {forces_violeau##sfx, forces_violeau_corrected##sfx}, \
        {forces_les##sfx, forces_les_corrected##sfx}, {       \
      forces_les_lag##sfx, forces_les_lag_corrected##sfx      \
    }                                                         \
  }
FORCE_LOOPS(, 0, 0)
FORCE_LOOPS(_rec, 1, 0)
FORCE_LOOPS(_sp, 0, 1)
FORCE_LOOPS(_rec_sp, 1, 1)

/** The loops by precision (double, mixed), data path (particle arrays, gathered records),
    viscous operator and pressure-gradient form (standard, corrected). */
static const force_loop loops[2][2][VK_N][2] = {{FORCE_ROW(), FORCE_ROW(_rec)},
                                                {FORCE_ROW(_sp), FORCE_ROW(_rec_sp)}};

/** Particles per task of the force loop. */
enum { FORCE_CHUNK = TURB_CHUNK };

void sph_forces(const struct model *M, struct particles *P, const struct nbr *nb,
                const struct walls *W, double fx, struct force_info *info) {
  timer_push("forces");
  const int visc = M->strain_lag                   ? VK_LES_LAG
                   : M->les                        ? VK_LES
                   : M->viscous == VISCOUS_VIOLEAU ? VK_VIOLEAU
                                                   : VK_MORRIS;
  const force_loop loop =
      loops[M->precision == PRECISION_MIXED][records_fast()][visc][M->pgrad == PGRAD_CORRECTED];
  const struct fctx C = {M, P, nb, W, fx, info->wall_ax, info->sx, P->nur_next, P->kr_next};
  const size_t n = P->n, nchunk = (n + FORCE_CHUNK - 1) / FORCE_CHUNK;
  double amax2 = 0.0, gvmax = 0.0;
#pragma omp parallel for schedule(dynamic, 4) reduction(max : amax2, gvmax)
  for (size_t k = 0; k < nchunk; k++) {
    double mx[2] = {0.0, 0.0};
    const size_t a0 = k * FORCE_CHUNK, a1 = a0 + FORCE_CHUNK < n ? a0 + FORCE_CHUNK : n;
    loop(&C, a0, a1, mx);
    if (mx[0] > amax2) amax2 = mx[0];
    if (mx[1] > gvmax) gvmax = mx[1];
  }
  info->amax = sqrt(amax2);
  info->gvmax = gvmax;
  timer_pop();
}
