/** @file term_gradient.c @brief The out-of-line velocity-gradient sums of term_gradient.h. */
#include "term_gradient.h"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#include <immintrin.h>
#define GRADIENT_AVX512 1
#else
#define GRADIENT_AVX512 0
#endif

#if GRADIENT_AVX512
/** gradient_sums_t (kept geometry, gathered records) in AVX-512 intrinsics, used only where the
    processor has AVX-512 (records_fast): the list is padded to whole vectors (n a multiple of
    8, records_gather_padded), the products are added with fused multiply-adds (21 vector
    operations per 8 pairs instead of 36; every processor that takes this path has them, so a
    run's results do not depend on the path), and the 15 sums are reduced each with a shuffle
    tree instead of the compiler's reduction of an `omp simd` loop, which goes through memory
    lane by lane (30% of the loop's time). */
__attribute__((target("avx512f"), noinline)) static void gradient_sums_avx512(
    const struct gradient_src *src, const struct pair_view *V, int n, double s[GRADIENT_SUMS]) {
  const double *u = V->f[REC_U], *v = V->f[REC_V], *w = V->f[REC_W], *vol = V->f[REC_VOL];
  const double *geo = src->geo;
  const size_t ld = (size_t)src->ld;
  const __m512d ua = _mm512_set1_pd(src->ua), va = _mm512_set1_pd(src->va);
  const __m512d wa = _mm512_set1_pd(src->wa);
  const __m512d zero = _mm512_setzero_pd();
  __m512d axx = zero, axy = zero, axz = zero, ayy = zero, ayz = zero, azz = zero;
  __m512d bxx = zero, bxy = zero, bxz = zero, byx = zero, byy = zero, byz = zero;
  __m512d bzx = zero, bzy = zero, bzz = zero;
  for (int j = 0; j < n; j += 8) { /* whole vectors, aligned */
    const __m512d vf = _mm512_mul_pd(_mm512_load_pd(vol + j), _mm512_load_pd(geo + j));
    const __m512d dx = _mm512_load_pd(geo + GEO_X * ld + j);
    const __m512d dy = _mm512_load_pd(geo + GEO_Y * ld + j);
    const __m512d dz = _mm512_load_pd(geo + GEO_Z * ld + j);
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
  const __m512d acc[GRADIENT_SUMS] = {axx, axy, axz, ayy, ayz, azz, bxx, bxy,
                                      bxz, byx, byy, byz, bzx, bzy, bzz};
  for (int k = 0; k < GRADIENT_SUMS; k++) s[k] = _mm512_reduce_add_pd(acc[k]);
}
#endif

/** gradient_sums_t from the kept geometry, gathered records or the arrays through the list. */
static CHANSPH_CLONES void kept_gathered(const struct gradient_src *src, const struct pair_view *V,
                                         int n, double s[GRADIENT_SUMS]) {
  gradient_sums_t(src, V, n, 1, 1, s);
}

static CHANSPH_CLONES void kept_arrays(const struct gradient_src *src, const struct pair_view *V,
                                       int n, double s[GRADIENT_SUMS]) {
  gradient_sums_t(src, V, n, 0, 1, s);
}

void gradient_sums_kept(const struct gradient_src *src, const struct pair_view *V, int n,
                        int gathered, double s[GRADIENT_SUMS]) {
#if GRADIENT_AVX512
  if (gathered && records_fast()) { /* the gathered path is taken only with AVX-512 */
    gradient_sums_avx512(src, V, n, s);
    return;
  }
#endif
  if (gathered)
    kept_gathered(src, V, n, s);
  else
    kept_arrays(src, V, n, s);
}

/** gradient_sums_t with the geometry computed, gathered records or the arrays. */
static CHANSPH_CLONES void computed_gathered(const struct gradient_src *src,
                                             const struct pair_view *V, int n,
                                             double s[GRADIENT_SUMS]) {
  gradient_sums_t(src, V, n, 1, 0, s);
}

static CHANSPH_CLONES void computed_arrays(const struct gradient_src *src,
                                           const struct pair_view *V, int n,
                                           double s[GRADIENT_SUMS]) {
  gradient_sums_t(src, V, n, 0, 0, s);
}

void gradient_sums_of(const struct model *M, const struct particles *P, const struct nbr *nb,
                      size_t a, const struct pair_view *arrays, double s[GRADIENT_SUMS]) {
  const struct gradient_src src = {pair_frame_of(M), NULL,    0,       P->x[a], P->y[a],
                                   P->z[a],          P->u[a], P->v[a], P->w[a]};
  const int n = nb->count[a];
  if (!arrays) {
    double *bf = pair_buffer(nb);
    records_gather(P->rec, pair_list(nb, a), n, 0, bf, nb->pairbuf_ld);
    const struct pair_view V = pair_view_gathered(bf, nb->pairbuf_ld);
    computed_gathered(&src, &V, n, s);
  } else {
    struct pair_view V = *arrays;
    V.nl = pair_list(nb, a);
    computed_arrays(&src, &V, n, s);
  }
}
