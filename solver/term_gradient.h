/**
 * @file term_gradient.h
 * @brief The first-order corrected gradient (thesis Eq. 2.88-2.90, k = 0): its moment matrix
 *        A_a = -sum_b V_b F_ab r_ab (x) r_ab (L_a = A_a^-1), its difference sums
 *        sum_b V_b (f_b - f_a) F_ab r_ab, and the velocity-gradient sums built from them.
 *
 * The pair terms serve the corrected pressure gradient (term_pressure.h) and the velocity
 * gradient of the LES strain rate and of the Q criterion (turb.c). The velocity-gradient sums
 * are defined once, gradient_sums_t(), over a view of the neighbours (pair_loop.h) with the
 * pair geometry either computed or kept by the force loop; where the processor has AVX-512 the
 * force loop's kept geometry and gathered records are summed by gradient_sums_avx512(), the
 * same sums written in intrinsics behind the same signature (gradient_sums_kept).
 */
#ifndef CHANSPH_TERM_GRADIENT_H
#define CHANSPH_TERM_GRADIENT_H

#include "pair_loop.h"

/** Moment matrix term of the first-order correction (thesis Eq. 2.88): -V_b F_ab r_ab (x) r_ab;
    its sum is A_a, with L_a = A_a^-1. */
static inline struct sym3 gradient_moment(const struct pair *g, double vb) {
  const double vf = -vb * g->f;
  return (struct sym3){vf * g->dx * g->dx, vf * g->dx * g->dy, vf * g->dx * g->dz,
                       vf * g->dy * g->dy, vf * g->dy * g->dz, vf * g->dz * g->dz};
}

/** Corrected difference gradient of a scalar (thesis Eq. 2.90, k = 0, before L_a):
    V_b (f_b - f_a) F_ab r_ab. */
static inline struct v3 gradient_difference(const struct pair *g, double vb, double dfba) {
  const double s = vb * dfba * g->f;
  return (struct v3){s * g->dx, s * g->dy, s * g->dz};
}

/** The velocity-gradient sums of one particle, as turb_strain_gradient takes them:
    A = s[0..5] ({xx, xy, xz, yy, yz, zz}) and B = s[6..14] (B_ij = sum_b V_b (v_b - v_a)_i
    F_ab (r_ab)_j, row-major). */
enum { GRADIENT_SUMS = 15 };

/** Fields of the pair geometry the force loop keeps for the velocity-gradient sums (nbr.h
    PAIRBUF_GEOM, at PAIRBUF_RECORDS of the pair buffer): F_ab and r_ab. */
enum { GEO_F, GEO_X, GEO_Y, GEO_Z };

/** Where the pair geometry of gradient_sums_t comes from. */
struct gradient_src {
  struct pair_frame F; /*!< to compute it (kept = 0) */
  const double *geo;   /*!< kept = 1: field k (enum GEO_F ...) of neighbour j at geo[k ld + j] */
  int ld;              /*!< leading dimension of geo */
  double xa, ya, za;   /*!< position of particle a [m] */
  double ua, va, wa;   /*!< velocity of particle a [m/s] */
};

/**
 * @brief The velocity-gradient sums s[GRADIENT_SUMS] of one particle over the neighbours
 *        0 .. n-1 of the view V, with the geometry computed (`kept` = 0) or read from the pair
 *        geometry the force loop kept (`kept` = 1); `gathered` as for the view. Always inlined
 *        with constant flags: one specialised loop per use.
 */
static inline __attribute__((always_inline)) void gradient_sums_t(const struct gradient_src *src,
                                                                  const struct pair_view *V, int n,
                                                                  const int gathered,
                                                                  const int kept,
                                                                  double s[GRADIENT_SUMS]) {
  const struct pair_frame F = src->F;
  const double *restrict x = V->f[REC_X], *restrict y = V->f[REC_Y], *restrict z = V->f[REC_Z];
  const double *restrict u = V->f[REC_U], *restrict v = V->f[REC_V], *restrict w = V->f[REC_W];
  const double *restrict vol = V->f[REC_VOL];
  const int32_t *restrict nl = V->nl;
  const int ld = src->ld;
  const double *restrict gf = src->geo + (size_t)GEO_F * ld;
  const double *restrict gx = src->geo + (size_t)GEO_X * ld;
  const double *restrict gy = src->geo + (size_t)GEO_Y * ld;
  const double *restrict gz = src->geo + (size_t)GEO_Z * ld;
  const double xa = src->xa, ya = src->ya, za = src->za, ua = src->ua, va = src->va;
  const double wa = src->wa;
  double axx = 0, axy = 0, axz = 0, ayy = 0, ayz = 0, azz = 0;
  double bxx = 0, bxy = 0, bxz = 0, byx = 0, byy = 0, byz = 0, bzx = 0, bzy = 0, bzz = 0;
#pragma omp simd reduction(+ : axx, axy, axz, ayy, ayz, azz, bxx, bxy, bxz, byx, byy, byz, bzx, \
                               bzy, bzz)
  for (int j = 0; j < n; j++) {
    const int32_t b = pair_index(gathered, nl, j);
    const struct pair g = kept ? (struct pair){gx[j], gy[j], gz[j], 0.0, 0.0, gf[j]}
                               : pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    const struct sym3 t = gradient_moment(&g, vol[b]);
    axx += t.xx, axy += t.xy, axz += t.xz, ayy += t.yy, ayz += t.yz, azz += t.zz;
    const struct v3 gu = gradient_difference(&g, vol[b], u[b] - ua);
    const struct v3 gv = gradient_difference(&g, vol[b], v[b] - va);
    const struct v3 gw = gradient_difference(&g, vol[b], w[b] - wa);
    bxx += gu.x, bxy += gu.y, bxz += gu.z, byx += gv.x, byy += gv.y, byz += gv.z;
    bzx += gw.x, bzy += gw.y, bzz += gw.z;
  }
  const double sums[GRADIENT_SUMS] = {axx, axy, axz, ayy, ayz, azz, bxx, bxy,
                                      bxz, byx, byy, byz, bzx, bzy, bzz};
  for (int k = 0; k < GRADIENT_SUMS; k++) s[k] = sums[k];
}

/**
 * @brief gradient_sums_t from the kept geometry (`kept` = 1) over n neighbours of the view V,
 *        for the force loop (les.strain_lag): with `gathered` records and AVX-512, the list
 *        padded to whole vectors, the same sums in intrinsics (term_gradient.c); otherwise
 *        gradient_sums_t itself.
 */
void gradient_sums_kept(const struct gradient_src *src, const struct pair_view *V, int n,
                        int gathered, double s[GRADIENT_SUMS]);

/**
 * @brief gradient_sums_t with the geometry computed, over the whole list of particle a of P:
 *        the eddy viscosity at the current state and the Q criterion (turb.c): from the view
 *        `arrays` of the particle arrays (pair_view_arrays) through the list, or, with arrays
 *        NULL, from the list's records (packed and current) gathered into the calling thread's
 *        pair buffer.
 */
void gradient_sums_of(const struct model *M, const struct particles *P, const struct nbr *nb,
                      size_t a, const struct pair_view *arrays, double s[GRADIENT_SUMS]);

#endif
