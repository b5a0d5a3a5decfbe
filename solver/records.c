/** @file records.c @brief Implementation of records.h. */
#include "records.h"

#include <stdlib.h>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define REC_AVX512 1
#include <immintrin.h>
#else
#define REC_AVX512 0
#endif

static int use_avx512;

void records_init(void) {
  const char *e = getenv("CHANSPH_SCALAR_SCAN"); /* the portable paths, for comparisons */
#if REC_AVX512
  use_avx512 = !(e && *e == '1') && __builtin_cpu_supports("avx512f");
#else
  (void)e;
  use_avx512 = 0;
#endif
}

int records_fast(void) {
  return use_avx512;
}

const double *records_field_array(const struct particles *P, int k) {
  for (int i = 0; i < part_n_fields; i++)
    if ((part_fields[i].roles & PF_PAIR) && part_fields[i].rec == k)
      return part_field_ptr(P, &part_fields[i]);
  return NULL;
}

void records_pack(struct particles *P, size_t n) {
  const double *src[REC_FIELDS];
  for (int k = 0; k < REC_FIELDS; k++) src[k] = records_field_array(P, k);
  double *restrict rec = P->rec;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < n; a++) { /* one pass over the records, a record at a time */
    double *r = rec + a * REC_LEN;
    for (int k = 0; k < REC_FIELDS; k++) r[k] = src[k] ? src[k][a] : 0.0;
    for (int k = REC_FIELDS; k < REC_LEN; k++) r[k] = 0.0;
  }
}

static void gather_scalar(const double *restrict rec, const int32_t *restrict nl, int cnt, int half,
                          double *restrict out, int ld) {
  for (int f = 0; f < 8; f++) {
    const double *restrict src = rec + 8 * half + f;
    double *restrict dst = out + (size_t)f * ld;
    for (int j = 0; j < cnt; j++) dst[j] = src[(size_t)nl[j] * REC_LEN];
  }
}

#if REC_AVX512
/* Eight half-records (rows) to eight fields (columns): unpack pairs of rows, then two rounds of
   128-bit lane shuffles. */
__attribute__((target("avx512f"))) static void gather_avx512(const double *restrict rec,
                                                             const int32_t *restrict nl, int cnt,
                                                             int half, double *restrict out,
                                                             int ld) {
  const double *base = rec + 8 * half;
  int j = 0;
  for (; j + 8 <= cnt; j += 8) {
    __m512d r[8], t[8], s[8];
    for (int k = 0; k < 8; k++) r[k] = _mm512_load_pd(base + (size_t)nl[j + k] * REC_LEN);
    for (int k = 0; k < 8; k += 2) {
      t[k] = _mm512_unpacklo_pd(r[k], r[k + 1]);     /* a0 b0 | a2 b2 | a4 b4 | a6 b6 */
      t[k + 1] = _mm512_unpackhi_pd(r[k], r[k + 1]); /* a1 b1 | a3 b3 | a5 b5 | a7 b7 */
    }
    for (int k = 0; k < 8; k += 4) {
      s[k] = _mm512_shuffle_f64x2(t[k], t[k + 2], 0x88);         /* a0b0 a4b4 c0d0 c4d4 */
      s[k + 1] = _mm512_shuffle_f64x2(t[k], t[k + 2], 0xdd);     /* a2b2 a6b6 c2d2 c6d6 */
      s[k + 2] = _mm512_shuffle_f64x2(t[k + 1], t[k + 3], 0x88); /* a1b1 a5b5 c1d1 c5d5 */
      s[k + 3] = _mm512_shuffle_f64x2(t[k + 1], t[k + 3], 0xdd); /* a3b3 a7b7 c3d3 c7d7 */
    }
    double *o = out + j;
    _mm512_store_pd(o + 0 * (size_t)ld, _mm512_shuffle_f64x2(s[0], s[4], 0x88));
    _mm512_store_pd(o + 4 * (size_t)ld, _mm512_shuffle_f64x2(s[0], s[4], 0xdd));
    _mm512_store_pd(o + 2 * (size_t)ld, _mm512_shuffle_f64x2(s[1], s[5], 0x88));
    _mm512_store_pd(o + 6 * (size_t)ld, _mm512_shuffle_f64x2(s[1], s[5], 0xdd));
    _mm512_store_pd(o + 1 * (size_t)ld, _mm512_shuffle_f64x2(s[2], s[6], 0x88));
    _mm512_store_pd(o + 5 * (size_t)ld, _mm512_shuffle_f64x2(s[2], s[6], 0xdd));
    _mm512_store_pd(o + 3 * (size_t)ld, _mm512_shuffle_f64x2(s[3], s[7], 0x88));
    _mm512_store_pd(o + 7 * (size_t)ld, _mm512_shuffle_f64x2(s[3], s[7], 0xdd));
  }
  if (j < cnt) gather_scalar(rec, nl + j, cnt - j, half, out + j, ld);
}
#endif

#if REC_AVX512
/* Half 1 holds only four fields (REC_M .. REC_NUR): 256-bit loads of eight records, paired
   into 512-bit rows, then one round of unpacks and one of two-source permutes. */
__attribute__((target("avx512f"))) static void gather4_avx512(const double *restrict rec,
                                                              const int32_t *restrict nl, int cnt,
                                                              double *restrict out, int ld) {
  const double *base = rec + 8;
  const __m512i lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
  const __m512i hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  int j = 0;
  for (; j + 8 <= cnt; j += 8) {
    __m512d z[4];
    for (int k = 0; k < 4; k++) /* records k and k + 4: a0 a1 a2 a3 | e0 e1 e2 e3 */
      z[k] = _mm512_insertf64x4(
          _mm512_castpd256_pd512(_mm256_load_pd(base + (size_t)nl[j + k] * REC_LEN)),
          _mm256_load_pd(base + (size_t)nl[j + k + 4] * REC_LEN), 1);
    const __m512d t0 = _mm512_unpacklo_pd(z[0], z[1]); /* a0 b0 a2 b2 | e0 f0 e2 f2 */
    const __m512d t1 = _mm512_unpackhi_pd(z[0], z[1]); /* a1 b1 a3 b3 | e1 f1 e3 f3 */
    const __m512d t2 = _mm512_unpacklo_pd(z[2], z[3]); /* c0 d0 c2 d2 | g0 h0 g2 h2 */
    const __m512d t3 = _mm512_unpackhi_pd(z[2], z[3]); /* c1 d1 c3 d3 | g1 h1 g3 h3 */
    double *o = out + j;
    _mm512_store_pd(o + 0 * (size_t)ld, _mm512_permutex2var_pd(t0, lo, t2));
    _mm512_store_pd(o + 2 * (size_t)ld, _mm512_permutex2var_pd(t0, hi, t2));
    _mm512_store_pd(o + 1 * (size_t)ld, _mm512_permutex2var_pd(t1, lo, t3));
    _mm512_store_pd(o + 3 * (size_t)ld, _mm512_permutex2var_pd(t1, hi, t3));
  }
  for (; j < cnt; j++)
    for (int f = 0; f < 4; f++) out[(size_t)f * ld + j] = base[(size_t)nl[j] * REC_LEN + f];
}
#endif

void records_gather(const double *rec, const int32_t *nl, int cnt, int half, double *out, int ld) {
#if REC_AVX512
  if (use_avx512) {
    if (half == 1)
      gather4_avx512(rec, nl, cnt, out, ld); /* fields 8 + 4 .. 15 are spare: not gathered */
    else
      gather_avx512(rec, nl, cnt, half, out, ld);
    return;
  }
#endif
  gather_scalar(rec, nl, cnt, half, out, ld);
}

/** Zero the fields a pair loop reads (0 .. REC_FIELDS-1) at entries j .. j+7 of a pair buffer. */
static inline void pad_zero(double *bf, int ld, int j) {
  for (int f = 0; f < REC_FIELDS; f++)
    for (int k = 0; k < 8; k++) bf[(size_t)f * ld + j + k] = 0.0;
}

int records_gather_padded(const double *rec, const int32_t *nl, int nf, int n, double *bf, int ld,
                          int *nf8) {
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
