/** @file nbr.c @brief Implementation of nbr.h. */
#include "nbr.h"
#include "alloc.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "kernel.h"
#include "pair.h"
#include "timers.h"

/* The candidate scan has an AVX-512 version (compress stores) for GCC on x86-64, chosen at run
   time; elsewhere, or on a processor without it, the portable scalar scan. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define NBR_AVX512 1
#include <immintrin.h>
#else
#define NBR_AVX512 0
#endif

/* Whether this processor runs the AVX-512 scan (CHANSPH_SCALAR_SCAN=1 in the environment turns
   it off, for comparisons); asked once, in nbr_init. */
static int nbr_cpu_avx512(void) {
  const char *e = getenv("CHANSPH_SCALAR_SCAN");
  if (e && *e == '1') return 0;
#if NBR_AVX512
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
#else
  return 0;
#endif
}

int nbr_columns(const struct scene *s) {
  const double cell = 2.0 * scene_h(s) / NBR_REACH;
  return (int)floor(s->lx / cell * (1.0 + 1e-12));
}

/* List slots per particle: at least n, a multiple of NBR_ALIGN. */
static int nbr_round_stride(int n) {
  return (n + NBR_ALIGN - 1) / NBR_ALIGN * NBR_ALIGN;
}

int nbr_stride(const struct scene *s) {
  /* expected neighbours in the support, with head room; nbr_build grows it if needed */
  const double per = s->dim == 3 ? 4.0 / 3.0 * M_PI * pow(2.0 * s->h_over_dr, 3)
                                 : M_PI * pow(2.0 * s->h_over_dr, 2);
  return nbr_round_stride((int)(1.5 * per) + 8);
}

struct nbr_range nbr_whole(const struct scene *s) {
  const double cell = 2.0 * scene_h(s) / NBR_REACH;
  const int nz = s->dim == 3 ? (int)floor(s->lz / cell * (1.0 + 1e-12)) : 1;
  return (struct nbr_range){0, nbr_columns(s), 0, 0, nz, 0};
}

void nbr_init(struct nbr *nb, const struct scene *s, size_t n, const struct nbr_range *r) {
  memset(nb, 0, sizeof *nb);
  const double two_h = 2.0 * scene_h(s), cell = two_h / NBR_REACH;
  nb->dim = s->dim;
  nb->lx = s->lx, nb->ly = 2.0 * s->delta, nb->lz = s->dim == 3 ? s->lz : 1.0;
  nb->nx = nbr_columns(s);
  nb->ny = (int)floor(nb->ly / cell * (1.0 + 1e-12));
  nb->nz = nbr_whole(s).nzo;
  if (nb->ny < 1) nb->ny = 1;
  if (nb->nx < 2 * NBR_REACH + 1 || (s->dim == 3 && nb->nz < 2 * NBR_REACH + 1))
    die("periodic directions need at least %d cells of size 2h/%d (validated in scene.c)",
        2 * NBR_REACH + 1, NBR_REACH);
  nb->cx = nb->nx / nb->lx, nb->cy = nb->ny / nb->ly, nb->cz = nb->nz / nb->lz;
  nb->support2 = two_h * two_h;
  nb->avx512 = nbr_cpu_avx512();
  nbr_set_range(nb, r);
  nb->stride = nbr_stride(s);
  nbr_reserve(nb, n);
}

void nbr_set_range(struct nbr *nb, const struct nbr_range *r) {
  nb->ix0 = r->ix0, nb->nxo = r->nxo, nb->hx = r->hx;
  nb->iz0 = r->iz0, nb->nzo = r->nzo, nb->hz = r->hz;
  const size_t ny = (size_t)nb->ny, nxe = (size_t)nb->nxo + 2 * (size_t)nb->hx;
  nb->ncell_own = (size_t)nb->nxo * ny * (size_t)nb->nzo;
  nb->ncell_x = nb->ncell_own + 2 * (size_t)nb->hx * ny * (size_t)nb->nzo;
  nb->ncell = nb->ncell_x + 2 * (size_t)nb->hz * ny * nxe;
  part_free(nb->start), part_free(nb->tcount);
  nb->start = part_alloc("cell_start", (nb->ncell + 1) * sizeof(size_t));
  nb->tcount_threads = omp_get_max_threads(), nb->tcount_cells = nb->ncell_own;
  nb->tcount =
      part_alloc("sort_counts", (size_t)nb->tcount_threads * nb->ncell_own * sizeof(uint32_t));
}

void nbr_reserve(struct nbr *nb, size_t n) {
  if (n <= nb->cap) return;
  const size_t cap = nb->cap ? n + n / 2 : n;
  part_free(nb->perm), part_free(nb->cell), part_free(nb->count), part_free(nb->list);
  part_free(nb->nfluid);
  nb->cap = cap;
  nb->nfluid = part_alloc("nbr_nfluid", cap * sizeof(int));
  nb->perm = part_alloc("sort_perm", cap * sizeof(size_t));
  nb->cell = part_alloc("cell_of", cap * sizeof(int));
  nb->count = part_alloc("nbr_count", cap * sizeof(int));
  nb->list = part_alloc("nbr_list", cap * (size_t)nb->stride * sizeof(int32_t));
}

void nbr_free(struct nbr *nb) {
  part_free(nb->start), part_free(nb->tcount), part_free(nb->perm), part_free(nb->cell);
  part_free(nb->count), part_free(nb->list), part_free(nb->nfluid);
  for (int t = 0; t < nb->scratch_threads; t++)
    part_free(nb->scratch[t]), part_free(nb->pairbuf[t]), part_free(nb->blocks[t]);
  free(nb->scratch), free(nb->pairbuf), free(nb->blocks);
  memset(nb, 0, sizeof *nb);
}

static inline int clampi(int i, int n) {
  return i < 0 ? 0 : i >= n ? n - 1 : i;
}

/* Threads' shares of the owned particles for the counting sort: slots [n t / nt, n (t+1) / nt). */
static size_t sort_chunk(size_t n, int t, int nt) {
  return n * (size_t)t / (size_t)nt;
}

/* Per-thread cell counts of the counting sort (nt x ncell_own), made with the grid (in the
   place of the allocations of the serial sort's scratch, so the other arrays keep their cache
   colours, part_alloc) and again if the threads grow; each thread touches only the cells
   between the first and last of its share. */
static void sort_counts(struct nbr *nb, int nt) {
  if (nb->tcount && nb->tcount_threads >= nt && nb->tcount_cells == nb->ncell_own) return;
  part_free(nb->tcount);
  nb->tcount = part_alloc("sort_counts", (size_t)nt * nb->ncell_own * sizeof(uint32_t));
  nb->tcount_threads = nt, nb->tcount_cells = nb->ncell_own;
}

/* Counting sort of the owned slots [0, n) by nb->cell[], then by id within each cell; sets
   start[] of the owned cells and leaves the permutation in nb->perm[0 .. n-1] (slot i of the
   new order takes old slot perm[i]). Threaded and bitwise the order of a serial stable
   counting sort: thread t counts its share of the slots (in the cells between the first and
   the last of its share: the slots come mostly in cell order, from the previous step), the
   threads' counts of a cell are laid out in thread order after the cells before it, and each
   thread scatters its share in slot order. Every cell is then put in id order (insertion sort:
   cells are small and their content changes little from one step to the next); ids are unique,
   so the result does not depend on the order the slots came in either. */
static void sort_cells(struct nbr *nb, const struct particles *P, size_t n) {
  const int nt = omp_get_max_threads();
  const size_t nc = nb->ncell_own;
  sort_counts(nb, nt);
  int *lo = mem_alloc((size_t)nt * 2, sizeof(int), "cell sort"), *hi = lo + nt; /* cell ranges */
  size_t *part = mem_alloc((size_t)nt + 1, sizeof(size_t), "cell sort"); /* slots per share */
  const int *restrict cell = nb->cell;
  size_t *restrict start = nb->start, *restrict perm = nb->perm;
  const int64_t *restrict id = P->id;
#pragma omp parallel num_threads(nt)
  {
    const int t = omp_get_thread_num(), th = omp_get_num_threads();
    /* 1. count my share of the slots */
    const size_t a0 = sort_chunk(n, t, th), a1 = sort_chunk(n, t + 1, th);
    int l = INT32_MAX, h = -1;
    for (size_t a = a0; a < a1; a++) l = cell[a] < l ? cell[a] : l, h = cell[a] > h ? cell[a] : h;
    uint32_t *restrict cnt = nb->tcount + (size_t)t * nc;
    if (h >= l) memset(cnt + l, 0, (size_t)(h - l + 1) * sizeof *cnt);
    for (size_t a = a0; a < a1; a++) cnt[cell[a]]++;
    lo[t] = l, hi[t] = h;
#pragma omp barrier
    /* 2. slots per cell over the threads, summed over my share of the cells */
    const size_t c0 = sort_chunk(nc, t, th), c1 = sort_chunk(nc, t + 1, th);
    size_t sum = 0;
    for (size_t c = c0; c < c1; c++) {
      size_t k = 0;
      for (int s = 0; s < th; s++)
        if ((int)c >= lo[s] && (int)c <= hi[s]) k += nb->tcount[(size_t)s * nc + c];
      start[c] = k, sum += k;
    }
    part[t + 1] = sum;
#pragma omp barrier
#pragma omp single
    {
      part[0] = 0;
      for (int s = 0; s < th; s++) part[s + 1] += part[s];
      start[nc] = n;
    }
    /* 3. the cells' starts, and each thread's first slot in each cell */
    size_t off = part[t];
    for (size_t c = c0; c < c1; c++) {
      start[c] = off;
      for (int s = 0; s < th; s++)
        if ((int)c >= lo[s] && (int)c <= hi[s]) {
          uint32_t *q = &nb->tcount[(size_t)s * nc + c];
          const uint32_t m = *q;
          *q = (uint32_t)(off - start[c]), off += m;
        }
    }
#pragma omp barrier
    /* 4. scatter my share in slot order */
    for (size_t a = a0; a < a1; a++) {
      const int c = cell[a];
      perm[start[c] + cnt[c]++] = a;
    }
#pragma omp barrier
    /* 5. id order in each cell */
#pragma omp for schedule(static)
    for (size_t c = 0; c < nc; c++)
      for (size_t i = start[c] + 1; i < start[c + 1]; i++) {
        const size_t key = perm[i];
        size_t j = i;
        while (j > start[c] && id[perm[j - 1]] > id[key]) perm[j] = perm[j - 1], j--;
        perm[j] = key;
      }
  }
  free(lo), free(part);
}

void nbr_sort(struct nbr *nb, struct particles *P) {
  timer_push("sort");
  const size_t n = P->n;
  int *restrict cell = nb->cell;
  int stray = 0;
  const struct nbr g = *nb; /* a local copy: the position stores cannot alias it */
  double *restrict px = P->x, *restrict pz = P->z;
  const double *restrict py = P->y;
#pragma omp parallel for schedule(static) reduction(max : stray)
  for (size_t a = 0; a < n; a++) {
    nbr_wrap_position(&g, &px[a], &pz[a]);
    /* clamped before the integer conversion (nbr_cell_index): a NaN or huge coordinate of a
       failing run must not overflow it */
    const int lc = nbr_column(&g, px[a]) - g.ix0, lz = nbr_plane(&g, pz[a]) - g.iz0;
    const int iy = nbr_cell_index(py[a] * g.cy, g.ny);
    if (lc < 0 || lc >= g.nxo || lz < 0 || lz >= g.nzo) stray = 1;
    cell[a] = (int)nbr_owned_cell(&g, clampi(lc, g.nxo), iy, clampi(lz, g.nzo));
  }
  if (stray) die("nbr_sort: a particle outside this rank's block (migration missed it)");
  sort_cells(nb, P, n);
  timer_push("sort:permute");
  part_permute(P, 0, n, nb->perm);
  timer_pop();
  timer_pop();
}

size_t nbr_halo_cells(struct nbr *nb, int dir, size_t first, const uint32_t *const cnt[2]) {
  const size_t ny = (size_t)nb->ny;
  size_t k = first;
  if (dir == 0) { /* x: per row of the block, the hx columns below, then the hx above */
    const size_t R = (size_t)nb->hx;
    for (size_t row = 0; row < (size_t)nb->nzo * ny; row++)
      for (size_t h = 0; h < 2 * R; h++) {
        nb->start[nb->ncell_own + row * 2 * R + h] = k;
        k += h < R ? cnt[0][row * R + h] : cnt[1][row * R + h - R];
      }
    nb->start[nb->ncell_x] = k; /* the end of the last x halo cell (= ncell without a z halo) */
    return k;
  }
  /* z: the planes below, then the planes above, each over the extended columns */
  const size_t per = (size_t)nb->hz * ny * ((size_t)nb->nxo + 2 * (size_t)nb->hx);
  for (size_t s = 0; s < 2; s++)
    for (size_t i = 0; i < per; i++) {
      nb->start[nb->ncell_x + s * per + i] = k;
      k += cnt[s][i];
    }
  nb->start[nb->ncell] = k;
  return k;
}

/* Append the particles of [b0, b1), shifted by (sx, 0, sz), that lie within the support of a
   to the scratch list (lb, r2b), without branches: every candidate is written, and the count
   advances only for a neighbour (slot `stride` takes the writes of a list that overflows). */
static inline __attribute__((always_inline)) int scan_scalar(
    const struct particles *restrict P, size_t a, size_t b0, size_t b1, double sx, double sz,
    double support2, int32_t *restrict lb, double *restrict r2b, int cnt, int stride) {
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double xa = x[a] - sx, ya = y[a], za = z[a] - sz;
  for (size_t b = b0; b < b1; b++) {
    const double dx = xa - x[b], dy = ya - y[b], dz = za - z[b];
    const double r2 = dx * dx + dy * dy + dz * dz;
    const int k = cnt < stride ? cnt : stride;
    lb[k] = (int32_t)b, r2b[k] = r2;
    cnt += (r2 < support2) & (b != a);
  }
  return cnt;
}

#if NBR_AVX512
/* The same with AVX-512 over a whole cell's stencil at once: its candidate ranges cut into
   blocks of 8 (cand_blocks), scanned in one loop, with no branch per row. The neighbours are
   appended by compress in the order of the candidates, and the distances are computed with the
   same operations in the same order as scan_scalar's ((x_a - sx) - x_b, the shifted coordinates
   of a formed once for each of the three shifts), so the list and its distances are the same
   as the portable scan's. Per block the shuffle port does only the comparison and the two
   compresses (the slots and shifts are loaded, not broadcast). cap: scratch slots (stride +
   16); lx, lz: the periods. */
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx512cd"))) static inline int
scan_blocks_avx512(const struct particles *restrict P, size_t a, const struct nbr_block *restrict B,
                   int nblock, double lx, double lz, double support2, int32_t *restrict lb,
                   double *restrict r2b, int cap) {
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  double xs[3][8] __attribute__((aligned(64))), zs[3][8] __attribute__((aligned(64)));
  const double shift_x[3] = {-lx, 0.0, lx}, shift_z[3] = {-lz, 0.0, lz};
  for (int k = 0; k < 3; k++) {
    _mm512_store_pd(xs[k], _mm512_set1_pd(x[a] - shift_x[k]));
    _mm512_store_pd(zs[k], _mm512_set1_pd(z[a] - shift_z[k]));
  }
  const __m512d ya = _mm512_set1_pd(y[a]), s2 = _mm512_set1_pd(support2);
  int cnt = 0;
  for (int k = 0; k < nblock; k++) {
    const struct nbr_block *restrict bk = &B[k];
    const int32_t b = bk->id[0];
    const __mmask8 live = (__mmask8)bk->live;
    const __m512d dx =
        _mm512_sub_pd(_mm512_load_pd(xs[bk->sx]), _mm512_maskz_loadu_pd(live, x + b));
    const __m512d dy = _mm512_sub_pd(ya, _mm512_maskz_loadu_pd(live, y + b));
    const __m512d dz =
        _mm512_sub_pd(_mm512_load_pd(zs[bk->sz]), _mm512_maskz_loadu_pd(live, z + b));
    const __m512d r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                     _mm512_mul_pd(dz, dz));
    const uint32_t d = (uint32_t)a - (uint32_t)b; /* a itself: lane d of this block */
    const __mmask8 hit =
        _mm512_mask_cmp_pd_mask(live, r2, s2, _CMP_LT_OQ) & (__mmask8) ~(d < 8 ? 1u << d : 0u);
    if (cnt + 8 <= cap) {
      /* compress in registers, then plain stores (a compress store to memory is slow on
         several processors); the slots past the hits are scratch */
      _mm256_storeu_si256(
          (__m256i *)(lb + cnt),
          _mm256_maskz_compress_epi32(hit, _mm256_load_si256((const __m256i *)bk->id)));
      _mm512_storeu_pd(r2b + cnt, _mm512_maskz_compress_pd(hit, r2));
    }
    cnt += __builtin_popcount(hit);
  }
  return cnt;
}
#endif

/* Kernel sum S_a = m_a w(0) + sum_b m_b w_ab over the list found (vectorised; the order of the
   list is the same on any decomposition and the scratch list is aligned, so the sum is too);
   the kernel shape is a constant of each inlined copy (pair.h). */
static inline __attribute__((always_inline)) double kernel_sum(
    const struct kernel *K, const int shape, const double *restrict m, size_t a,
    const int32_t *restrict lb, const double *restrict r2b, int cnt) {
  double s = 0.0;
  const double ih = K->inv_h;
#pragma omp simd reduction(+ : s)
  for (int j = 0; j < cnt; j++) s += m[lb[j]] * kernel_w_of(K, shape, sqrt(r2b[j]) * ih);
  return m[a] * kernel_w_of(K, shape, 0.0) + s;
}

/* Copy the list lb[0 .. cnt-1] to out, fluid particles first, then the vertices, each in the
   order found; returns the number of fluid neighbours. */
static int fluid_first(const uint8_t *restrict kind, const int32_t *restrict lb,
                       int32_t *restrict out, int cnt) {
  int nf = 0;
  for (int j = 0; j < cnt; j++) nf += kind[lb[j]] == KIND_FLUID;
  int f = 0, v = nf;
  for (int j = 0; j < cnt; j++) {
    const int32_t b = lb[j];
    if (kind[b] == KIND_FLUID)
      out[f++] = b;
    else
      out[v++] = b;
  }
  return nf;
}

/* Periodic shift of the cells of global index g (outside [0, n): the image across the
   boundary) in a direction of length l. */
static inline double stencil_shift(int g, int n, double l) {
  return g < 0 ? -l : g >= n ? l : 0.0;
}

/* Gap between a coordinate and the cell interval [j, j + 1) / c: a lower bound of the distance
   to any particle of the cell (particles outside the grid are clamped into the edge cells, on
   the far side from the interior, so the bound still holds). */
static inline double cell_gap(double p, int j, double w) {
  const double lo = j * w, hi = lo + w; /* w: the cell width (rounding is inside the margin) */
  return p < lo ? lo - p : p > hi ? p - hi : 0.0;
}

/* A run of candidates: the particles [b0, b1) of consecutive cells of one row of the stencil,
   shifted by (sx, 0, sz), in row jy and plane jz of the grid. */
struct cand_range {
  size_t b0, b1;
  double sx, sz;
  int jy, jz;
};
enum { NBR_RANGES = (2 * NBR_REACH + 1) * (2 * NBR_REACH + 1) * (2 * NBR_REACH + 1) };

/* The candidate ranges of owned cell c's stencil, in stencil order (planes, rows, columns),
   each the same global cells with the same shifts on any decomposition; returns their count. */
static int stencil_ranges(const struct nbr *nb, size_t c, struct cand_range *r) {
  const int R = NBR_REACH;
  const int dz_lo = nb->dim == 3 ? -R : 0, dz_hi = nb->dim == 3 ? R : 0;
  const int lc = (int)(c % (size_t)nb->nxo);
  const int iy = (int)(c / (size_t)nb->nxo % (size_t)nb->ny);
  const int izl = (int)(c / ((size_t)nb->nxo * nb->ny));
  const int gx = nb->ix0 + lc;
  /* the x cells of the stencil are one unshifted run of local cells (owned, or of one row of
     the z halo) away from the ends of the block along x and of the grid */
  const int inner = lc >= R && lc < nb->nxo - R && gx >= R && gx < nb->nx - R;
  const int ylo = iy - R < 0 ? 0 : iy - R, yhi = iy + R >= nb->ny ? nb->ny - 1 : iy + R;
  int n = 0;
  for (int dz = dz_lo; dz <= dz_hi; dz++) {
    const int gz = nb->iz0 + izl + dz;
    const double sz = stencil_shift(gz, nb->nz, nb->lz);
    const int jz = gz < 0 ? gz + nb->nz : gz >= nb->nz ? gz - nb->nz : gz; /* global plane */
    int zl = izl + dz; /* local plane, wrapped where the block is the whole grid in z */
    if (!nb->hz) zl = jz;
    if (inner) { /* one run of 2R + 1 cells a row: the rows are an arithmetic sequence */
      const size_t c0 = nbr_local_cell(nb, lc - R, ylo, zl), st = nbr_row_stride(nb, lc - R, zl);
      for (int jy = ylo; jy <= yhi; jy++) {
        const size_t c = c0 + (size_t)(jy - ylo) * st;
        r[n++] = (struct cand_range){nb->start[c], nb->start[c + 2 * R + 1], 0.0, sz, jy, jz};
      }
      continue;
    }
    size_t cc[2 * NBR_REACH + 1], st[2 * NBR_REACH + 1];
    double sx[2 * NBR_REACH + 1];
    for (int dx = -R; dx <= R; dx++) {
      int xl = lc + dx; /* local column, wrapped where the block is the whole grid in x */
      if (!nb->hx)
        while (xl < 0 || xl >= nb->nx) xl += xl < 0 ? nb->nx : -nb->nx;
      cc[dx + R] = nbr_local_cell(nb, xl, ylo, zl);
      st[dx + R] = nbr_row_stride(nb, xl, zl);
      sx[dx + R] = stencil_shift(gx + dx, nb->nx, nb->lx);
    }
    for (int jy = ylo; jy <= yhi; jy++)
      for (int k = 0; k < 2 * R + 1; k++) {
        const size_t c = cc[k] + (size_t)(jy - ylo) * st[k];
        r[n++] = (struct cand_range){nb->start[c], nb->start[c + 1], sx[k], sz, jy, jz};
      }
  }
  return n;
}

/* The list of particle a from the ranges: the portable scan, skipping the ranges whose cells
   are farther than 2h in y and z (with a margin: the skipped candidates are outside the
   support by far more than the rounding of the cell edges). */
static inline __attribute__((always_inline)) int scan_ranges(const struct nbr *nb,
                                                             const struct particles *P, size_t a,
                                                             const struct cand_range *r, int nr,
                                                             int32_t *lb, double *r2b) {
  const double prune2 = nb->support2 * (1.0 + 1e-9);
  const double wy = 1.0 / nb->cy, wz = 1.0 / nb->cz; /* cell widths */
  int cnt = 0;
  for (int k = 0; k < nr; k++) {
    const double gz = nb->dim == 3 ? cell_gap(P->z[a] - r[k].sz, r[k].jz, wz) : 0.0;
    const double gy = cell_gap(P->y[a], r[k].jy, wy);
    if (gy * gy + gz * gz >= prune2) continue;
    cnt = scan_scalar(P, a, r[k].b0, r[k].b1, r[k].sx, r[k].sz, nb->support2, lb, r2b, cnt,
                      nb->stride);
  }
  return cnt;
}

#if NBR_AVX512
/* Cut the candidate ranges into blocks of at most 8 consecutive particles (their slots, the
   mask of the slots inside the range, the index of each shift in -L, 0, L); returns the
   number of blocks. */
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx512cd"))) static inline int
cand_blocks(const struct cand_range *r, int nr, struct nbr_block *B) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  int n = 0;
  for (int k = 0; k < nr; k++) {
    const uint16_t sx = (uint16_t)(r[k].sx < 0.0 ? 0 : r[k].sx > 0.0 ? 2 : 1);
    const uint16_t sz = (uint16_t)(r[k].sz < 0.0 ? 0 : r[k].sz > 0.0 ? 2 : 1);
    for (size_t b = r[k].b0; b < r[k].b1; b += 8) {
      const size_t m = r[k].b1 - b < 8 ? r[k].b1 - b : 8;
      struct nbr_block *bk = &B[n++];
      _mm256_store_si256((__m256i *)bk->id, _mm256_add_epi32(_mm256_set1_epi32((int)b), lane));
      bk->live = (1u << m) - 1u, bk->sx = sx, bk->sz = sz;
    }
  }
  return n;
}
#endif

/* Neighbour lists and kernel sums of the particles of owned cell c; returns the largest count
   that did not fit the stride (0 if all fitted). Instantiated for the AVX-512 scan (avx512 = 1,
   build_cell_avx512: the cell's candidates cut into blocks once, every particle of the cell
   scanning them in one loop) and for the portable one (build_cell: per range, pruned per
   particle). */
static inline __attribute__((always_inline)) int build_cell_t(struct nbr *nb,
                                                              const struct particles *P,
                                                              const struct kernel *K, size_t c,
                                                              double *ksum, const int avx512) {
  const int stride = nb->stride, R = NBR_REACH;
  const int iy = (int)(c / (size_t)nb->nxo % (size_t)nb->ny);
  if (nb->start[c] == nb->start[c + 1]) return 0;
  int overflow = 0;
  const int t = omp_get_thread_num();
  int32_t *lb = nb->scratch[t];
  double *r2b = (double *)(lb + stride + NBR_ALIGN);
  /* only lists that reach the first or last row of cells can hold wall vertices */
  const int wall_rows = iy - R <= 0 || iy + R >= nb->ny - 1;
  struct cand_range r[NBR_RANGES];
  const int nr = stencil_ranges(nb, c, r);
#if NBR_AVX512
  const int nblock = avx512 ? cand_blocks(r, nr, nb->blocks[t]) : 0;
#endif
  for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++) {
    int cnt;
#if NBR_AVX512
    if (avx512)
      cnt = scan_blocks_avx512(P, a, nb->blocks[t], nblock, nb->lx, nb->lz, nb->support2, lb, r2b,
                               stride + NBR_ALIGN);
    else
#endif
      cnt = scan_ranges(nb, P, a, r, nr, lb, r2b);
    nb->count[a] = cnt;
    if (cnt > stride) {
      if (cnt > overflow) overflow = cnt;
      continue;
    }
    ksum[a] = K->shape == KERNEL_C4 ? kernel_sum(K, KERNEL_C4, P->m, a, lb, r2b, cnt)
                                    : kernel_sum(K, KERNEL_C2, P->m, a, lb, r2b, cnt);
    int32_t *out = nb->list + a * (size_t)stride;
    if (wall_rows) {
      nb->nfluid[a] = fluid_first(P->kind, lb, out, cnt);
    } else {
      memcpy(out, lb, (size_t)cnt * sizeof *out);
      nb->nfluid[a] = cnt;
    }
  }
  return overflow;
}

static CHANSPH_CLONES int build_cell(struct nbr *nb, const struct particles *P,
                                     const struct kernel *K, size_t c, double *ksum) {
  return build_cell_t(nb, P, K, c, ksum, 0);
}

#if NBR_AVX512
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx512cd"))) static int build_cell_avx512(
    struct nbr *nb, const struct particles *P, const struct kernel *K, size_t c, double *ksum) {
  return build_cell_t(nb, P, K, c, ksum, 1);
}
#endif

/* Per-thread scratch lists of stride + 1 entries and their squared distances, and (AVX-512
   scan) room for the blocks of any stencil: at most NBR_RANGES cells, each holding at most as
   many particles as the fullest cell, in ranges of whole cells cut into blocks of 8 with at most
   one partial block per cell. */
static void nbr_scratch(struct nbr *nb) {
  const int nt = omp_get_max_threads();
  size_t fullest = 0;
  if (nb->avx512)
    for (size_t c = 0; c < nb->ncell; c++)
      if (nb->start[c + 1] - nb->start[c] > fullest) fullest = nb->start[c + 1] - nb->start[c];
  const size_t blocks = nb->avx512 ? NBR_RANGES * (fullest / 8 + 1) : 0;
  if (nb->scratch && nb->scratch_stride == nb->stride && nb->scratch_threads >= nt &&
      nb->block_cap >= blocks)
    return;
  for (int t = 0; t < nb->scratch_threads; t++)
    part_free(nb->scratch[t]), part_free(nb->pairbuf[t]), part_free(nb->blocks[t]);
  free(nb->scratch), free(nb->pairbuf), free(nb->blocks);
  nb->scratch = mem_calloc((size_t)nt, sizeof *nb->scratch, "neighbour lists");
  nb->pairbuf = mem_calloc((size_t)nt, sizeof *nb->pairbuf, "neighbour lists");
  nb->blocks = mem_calloc((size_t)nt, sizeof *nb->blocks, "neighbour lists");
  if (!nb->scratch || !nb->pairbuf || !nb->blocks)
    die("out of memory for the neighbour scratch lists");
  const size_t bytes = (size_t)(nb->stride + NBR_ALIGN) * (sizeof(int32_t) + sizeof(double));
  nb->block_cap = blocks + blocks / 2; /* made again only when a cell fills beyond it */
  for (int t = 0; t < nt; t++) {
    nb->scratch[t] = part_alloc("nbr_scratch", bytes);
    nb->pairbuf[t] = part_alloc("pair_buffer",
                                PAIRBUF_FIELDS * (size_t)(nb->stride + NBR_ALIGN) * sizeof(double));
    if (nb->block_cap)
      nb->blocks[t] = part_alloc("nbr_blocks", nb->block_cap * sizeof(struct nbr_block));
  }
  nb->scratch_threads = nt, nb->scratch_stride = nb->stride;
  nb->pairbuf_ld = nb->stride + NBR_ALIGN;
}

void nbr_build(struct nbr *nb, const struct particles *P, const struct kernel *K, double *ksum) {
  timer_push("neighbours");
  if (P->n + P->n_ghost > (size_t)INT32_MAX) die("more than 2^31 particles on one rank");
  for (;;) {
    int overflow = 0;
    nbr_scratch(nb);
#pragma omp parallel for schedule(dynamic, 64) reduction(max : overflow)
    for (size_t c = 0; c < nb->ncell_own; c++) {
#if NBR_AVX512
      const int o =
          nb->avx512 ? build_cell_avx512(nb, P, K, c, ksum) : build_cell(nb, P, K, c, ksum);
#else
      const int o = build_cell(nb, P, K, c, ksum);
#endif
      if (o > overflow) overflow = o;
    }
    if (!overflow) break;
    part_free(nb->list);
    nb->stride = nbr_round_stride(overflow + overflow / 4 + 8);
    nb->list = part_alloc("nbr_list", nb->cap * (size_t)nb->stride * sizeof(int32_t));
  }
  timer_pop();
}
