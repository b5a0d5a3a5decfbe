/** @file nbr.c @brief Implementation of nbr.h. */
#include "nbr.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "kernel.h"
#include "timers.h"

void nbr_init(struct nbr *nb, const struct scene *s, size_t n) {
  memset(nb, 0, sizeof *nb);
  const double two_h = 2.0 * scene_h(s), cell = two_h / NBR_REACH;
  nb->dim = s->dim;
  nb->lx = s->lx, nb->ly = 2.0 * s->delta, nb->lz = s->dim == 3 ? s->lz : 1.0;
  nb->nx = (int)floor(nb->lx / cell * (1.0 + 1e-12));
  nb->ny = (int)floor(nb->ly / cell * (1.0 + 1e-12));
  nb->nz = s->dim == 3 ? (int)floor(nb->lz / cell * (1.0 + 1e-12)) : 1;
  if (nb->ny < 1) nb->ny = 1;
  if (nb->nx < 2 * NBR_REACH + 1 || (s->dim == 3 && nb->nz < 2 * NBR_REACH + 1))
    die("periodic directions need at least %d cells of size 2h/%d (validated in scene.c)",
        2 * NBR_REACH + 1, NBR_REACH);
  nb->cx = nb->nx / nb->lx, nb->cy = nb->ny / nb->ly, nb->cz = nb->nz / nb->lz;
  nb->support2 = two_h * two_h;
  nb->ncell = (size_t)nb->nx * nb->ny * nb->nz;
  nb->start = part_alloc("cell_start", (nb->ncell + 1) * sizeof(size_t));
  nb->pos = part_alloc("cell_fill", nb->ncell * sizeof(size_t));
  nb->cap = n;
  nb->perm = part_alloc("sort_perm", n * sizeof(size_t));
  nb->cell = part_alloc("cell_of", n * sizeof(int));
  nb->count = part_alloc("nbr_count", n * sizeof(int));
  /* expected neighbours in the support, with head room; nbr_build grows it if needed */
  const double per = s->dim == 3 ? 4.0 / 3.0 * M_PI * pow(2.0 * s->h_over_dr, 3)
                                 : M_PI * pow(2.0 * s->h_over_dr, 2);
  nb->stride = (int)(1.5 * per) + 8;
  nb->list = part_alloc("nbr_list", n * (size_t)nb->stride * sizeof(int32_t));
}

void nbr_free(struct nbr *nb) {
  part_free(nb->start), part_free(nb->pos), part_free(nb->perm), part_free(nb->cell);
  part_free(nb->count), part_free(nb->list);
  memset(nb, 0, sizeof *nb);
}

static inline int clampi(int i, int n) {
  return i < 0 ? 0 : i >= n ? n - 1 : i;
}

void nbr_sort(struct nbr *nb, struct particles *P) {
  timer_push("sort");
  const size_t n = P->n;
  int *restrict cell = nb->cell;
  size_t *restrict start = nb->start;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < n; a++) {
    double x = P->x[a], z = P->z[a];
    if (x < 0.0 || x >= nb->lx) {
      x -= nb->lx * floor(x / nb->lx);
      if (x >= nb->lx) x -= nb->lx; /* a tiny negative x rounds to lx above */
      P->x[a] = x;
    }
    if (nb->dim == 3 && (z < 0.0 || z >= nb->lz)) {
      z -= nb->lz * floor(z / nb->lz);
      if (z >= nb->lz) z -= nb->lz;
      P->z[a] = z;
    }
    /* clamped in floating point first: a NaN or huge coordinate (a failing run, reported by
       the health check after this step) must not overflow the integer conversion */
    const int ix = clampi((int)fmin(fmax(x * nb->cx, 0.0), nb->nx), nb->nx);
    const int iy = clampi((int)fmin(fmax(P->y[a] * nb->cy, 0.0), nb->ny), nb->ny);
    const int iz = nb->dim == 3 ? clampi((int)fmin(fmax(z * nb->cz, 0.0), nb->nz), nb->nz) : 0;
    cell[a] = (iz * nb->ny + iy) * nb->nx + ix;
  }
  memset(start, 0, (nb->ncell + 1) * sizeof *start);
  for (size_t a = 0; a < n; a++) start[cell[a] + 1]++;
  for (size_t c = 0; c < nb->ncell; c++) start[c + 1] += start[c];
  /* stable scatter, then order each cell by id (insertion sort: cells are small and their
     content changes little from one step to the next) */
  size_t *restrict perm = nb->perm;
  size_t *restrict pos = nb->pos;
  memcpy(pos, start, nb->ncell * sizeof *pos);
  for (size_t a = 0; a < n; a++) perm[pos[cell[a]]++] = a;
  const int64_t *id = P->id;
#pragma omp parallel for schedule(static)
  for (size_t c = 0; c < nb->ncell; c++)
    for (size_t i = start[c] + 1; i < start[c + 1]; i++) {
      const size_t key = perm[i];
      size_t j = i;
      while (j > start[c] && id[perm[j - 1]] > id[key]) perm[j] = perm[j - 1], j--;
      perm[j] = key;
    }
  part_permute(P, perm);
  timer_pop();
}

/* Append the neighbours of a found in particles [b0, b1) shifted by (sx, 0, sz), and add
   their m_b w_ab to *sum. */
static inline int scan(const struct particles *restrict P, const struct kernel *K, size_t a,
                       size_t b0, size_t b1, double sx, double sz, double support2,
                       int32_t *restrict out, int cnt, int stride, double *sum) {
  const double xa = P->x[a] - sx, ya = P->y[a], za = P->z[a] - sz;
  double s = *sum;
  for (size_t b = b0; b < b1; b++) {
    const double dx = xa - P->x[b], dy = ya - P->y[b], dz = za - P->z[b];
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (r2 < support2 && b != a) {
      if (cnt < stride) out[cnt] = (int32_t)b;
      cnt++;
      s += P->m[b] * kernel_w(K, sqrt(r2));
    }
  }
  *sum = s;
  return cnt;
}

void nbr_build(struct nbr *nb, const struct particles *P, const struct kernel *K, double *ksum) {
  const double w0 = kernel_w(K, 0.0);
  timer_push("neighbours");
  if (P->n > (size_t)INT32_MAX) die("more than 2^31 particles on one rank");
  for (;;) {
    int overflow = 0;
    const int stride = nb->stride;
    const int R = NBR_REACH, dz_lo = nb->dim == 3 ? -R : 0, dz_hi = nb->dim == 3 ? R : 0;
#pragma omp parallel for schedule(static) reduction(max : overflow)
    for (size_t c = 0; c < nb->ncell; c++) {
      const int ix = (int)(c % (size_t)nb->nx);
      const int iy = (int)(c / (size_t)nb->nx % (size_t)nb->ny);
      const int iz = (int)(c / ((size_t)nb->nx * nb->ny));
      for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++) {
        int32_t *out = nb->list + a * (size_t)stride;
        int cnt = 0;
        double sum = P->m[a] * w0;
        for (int dz = dz_lo; dz <= dz_hi; dz++) {
          int jz = iz + dz;
          double sz = 0.0;
          if (jz < 0)
            jz += nb->nz, sz = -nb->lz;
          else if (jz >= nb->nz)
            jz -= nb->nz, sz = nb->lz;
          for (int dy = -R; dy <= R; dy++) {
            const int jy = iy + dy;
            if (jy < 0 || jy >= nb->ny) continue;
            const size_t row = ((size_t)jz * nb->ny + jy) * nb->nx;
            if (ix >= R && ix < nb->nx - R) { /* the x cells of the stencil are contiguous */
              cnt = scan(P, K, a, nb->start[row + ix - R], nb->start[row + ix + R + 1], 0.0, sz,
                         nb->support2, out, cnt, stride, &sum);
              continue;
            }
            for (int dx = -R; dx <= R; dx++) {
              int jx = ix + dx;
              double sx = 0.0;
              if (jx < 0)
                jx += nb->nx, sx = -nb->lx;
              else if (jx >= nb->nx)
                jx -= nb->nx, sx = nb->lx;
              cnt = scan(P, K, a, nb->start[row + jx], nb->start[row + jx + 1], sx, sz,
                         nb->support2, out, cnt, stride, &sum);
            }
          }
        }
        nb->count[a] = cnt;
        ksum[a] = sum;
        if (cnt > stride && cnt > overflow) overflow = cnt;
      }
    }
    if (!overflow) break;
    part_free(nb->list);
    nb->stride = overflow + overflow / 4 + 8;
    nb->list = part_alloc("nbr_list", nb->cap * (size_t)nb->stride * sizeof(int32_t));
  }
  timer_pop();
}
