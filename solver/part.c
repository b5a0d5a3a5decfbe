/** @file part.c @brief Implementation of part.h. */
#include "part.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"

enum { MAX_LABELS = 64 };
static struct {
  const char *label;
  size_t bytes;
  void *ptr;
} allocs[MAX_LABELS];
static int n_allocs;

void *part_alloc(const char *label, size_t bytes) {
  void *ptr = NULL;
  const size_t rounded = ((bytes ? bytes : 1) + 63) / 64 * 64;
  ptr = aligned_alloc(64, rounded);
  if (!ptr) die("out of memory allocating %s (%zu bytes)", label, bytes);
  memset(ptr, 0, rounded);
  for (int i = 0; i < n_allocs; i++)
    if (!allocs[i].ptr) {
      allocs[i].label = label, allocs[i].bytes = bytes, allocs[i].ptr = ptr;
      return ptr;
    }
  if (n_allocs < MAX_LABELS)
    allocs[n_allocs].label = label, allocs[n_allocs].bytes = bytes, allocs[n_allocs++].ptr = ptr;
  return ptr;
}

void part_free(void *ptr) {
  if (!ptr) return;
  for (int i = 0; i < n_allocs; i++)
    if (allocs[i].ptr == ptr) allocs[i].ptr = NULL, allocs[i].bytes = 0;
  free(ptr);
}

void part_memory_report(FILE *f) {
  size_t total = 0;
  fprintf(f, "memory per array:\n");
  for (int i = 0; i < n_allocs; i++) {
    if (!allocs[i].ptr) continue;
    fprintf(f, "  %-12s %10.2f MB\n", allocs[i].label, allocs[i].bytes / 1048576.0);
    total += allocs[i].bytes;
  }
  fprintf(f, "  %-12s %10.2f MB\n", "total", total / 1048576.0);
}

void part_create(struct particles *P, struct walls *W, const struct scene *s) {
  const int nx = (int)floor(s->lx / s->dr + 0.5);
  const int ny = (int)floor(2.0 * s->delta / s->dr + 0.5);
  const int nz = s->dim == 3 ? (int)floor(s->lz / s->dr + 0.5) : 1;
  memset(P, 0, sizeof *P);
  P->n_fluid = (size_t)nx * (size_t)(ny - 1) * (size_t)nz;
  P->n_vertex = 2 * (size_t)nx * (size_t)nz;
  P->n = P->n_fluid + P->n_vertex;
  P->cap = P->n;
  const size_t nd = P->n * sizeof(double);
  P->x = part_alloc("x", nd), P->y = part_alloc("y", nd), P->z = part_alloc("z", nd);
  P->u = part_alloc("u", nd), P->v = part_alloc("v", nd), P->w = part_alloc("w", nd);
  P->rho = part_alloc("rho", nd), P->m = part_alloc("mass", nd), P->gam = part_alloc("gamma", nd);
  P->ksum = part_alloc("kernel_sum", nd), P->ddiff = part_alloc("diffusion", nd);
  P->p = part_alloc("pressure", nd), P->c = part_alloc("sound", nd);
  P->pr2 = part_alloc("p_over_rho2", nd), P->vol = part_alloc("volume", nd);
  P->ax = part_alloc("ax", nd), P->ay = part_alloc("ay", nd), P->az = part_alloc("az", nd);
  P->id = part_alloc("id", P->n * sizeof(int64_t));
  P->kind = part_alloc("kind", P->n);
  P->tmp = part_alloc("sort_scratch", nd);
  P->tmp_i = part_alloc("sort_scratch_i", P->n * sizeof(int64_t));

  const double dr = s->dr, mass = s->rho0 * pow(dr, s->dim);
  const double zc = s->dim == 3 ? 0.5 * dr : 0.0;
  size_t a = 0;
  for (int i = 0; i < nx; i++)
    for (int j = 1; j < ny; j++)
      for (int k = 0; k < nz; k++, a++) {
        P->x[a] = (i + 0.5) * dr, P->y[a] = j * dr, P->z[a] = k * dr + zc;
        P->rho[a] = s->rho0, P->m[a] = mass, P->gam[a] = 1.0;
        P->id[a] = (int64_t)a, P->kind[a] = KIND_FLUID;
      }
  W->nx = nx, W->nz = nz;
  W->rho = part_alloc("wall_rho", P->n_vertex * sizeof(double));
  W->p = part_alloc("wall_p", P->n_vertex * sizeof(double));
  for (int wall = 0; wall < 2; wall++)
    for (int i = 0; i < nx; i++)
      for (int k = 0; k < nz; k++, a++) {
        P->x[a] = (i + 0.5) * dr, P->y[a] = wall ? 2.0 * s->delta : 0.0, P->z[a] = k * dr + zc;
        P->rho[a] = s->rho0, P->m[a] = 0.5 * mass, P->gam[a] = 0.5;
        P->id[a] = (int64_t)a, P->kind[a] = KIND_VERTEX;
        W->rho[a - P->n_fluid] = s->rho0;
      }
}

void part_destroy(struct particles *P, struct walls *W) {
  double **d[] = {&P->x,   &P->y,   &P->z,    &P->u,     &P->v,   &P->w,   &P->rho,
                  &P->m,   &P->gam, &P->ksum, &P->ddiff, &P->p,   &P->c,   &P->pr2,
                  &P->vol, &P->ax,  &P->ay,   &P->az,    &P->tmp, &W->rho, &W->p};
  for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) part_free(*d[i]), *d[i] = NULL;
  part_free(P->id), part_free(P->kind), part_free(P->tmp_i);
  P->id = NULL, P->kind = NULL, P->tmp_i = NULL;
}

static void grow(void *pp, const char *label, size_t elem, size_t used, size_t cap) {
  void **p = pp;
  if (!*p) return; /* an optional array that is not in use */
  void *fresh = part_alloc(label, cap * elem);
  memcpy(fresh, *p, used * elem);
  part_free(*p);
  *p = fresh;
}

void part_reserve(struct particles *P, size_t n) {
  if (n > P->cap) part_resize(P, n + n / 2);
}

void part_resize(struct particles *P, size_t cap) {
  const size_t used = P->n + P->n_ghost, d = sizeof(double);
  if (cap < used) cap = used;
  struct {
    double **a;
    const char *label;
  } const f[] = {{&P->x, "x"},
                 {&P->y, "y"},
                 {&P->z, "z"},
                 {&P->u, "u"},
                 {&P->v, "v"},
                 {&P->w, "w"},
                 {&P->rho, "rho"},
                 {&P->m, "mass"},
                 {&P->gam, "gamma"},
                 {&P->ksum, "kernel_sum"},
                 {&P->ddiff, "diffusion"},
                 {&P->p, "pressure"},
                 {&P->c, "sound"},
                 {&P->pr2, "p_over_rho2"},
                 {&P->vol, "volume"},
                 {&P->ax, "ax"},
                 {&P->ay, "ay"},
                 {&P->az, "az"},
                 {&P->nur, "nu_r"},
                 {&P->kr, "k_r"},
                 {&P->twx, "wall_law_tx"},
                 {&P->twz, "wall_law_tz"},
                 {&P->tmp, "sort_scratch"}};
  for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) grow(f[i].a, f[i].label, d, used, cap);
  grow(&P->id, "id", sizeof(int64_t), used, cap);
  grow(&P->tmp_i, "sort_scratch_i", sizeof(int64_t), used, cap);
  grow(&P->kind, "kind", 1, used, cap);
  P->cap = cap;
}

static void permute_d(double *arr, double *tmp, size_t i0, size_t n, const size_t *perm) {
  const double *restrict src = arr + i0;
  double *restrict dst = tmp;
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < n; i++) dst[i] = src[perm[i]];
  memcpy(arr + i0, tmp, n * sizeof(double));
}

void part_permute(struct particles *P, size_t i0, size_t n, const size_t *perm) {
  /* the accelerations too: the statistics sample them after the re-sort */
  double *arrs[] = {P->x, P->y,   P->z,    P->u,     P->v,  P->w,  P->rho,
                    P->m, P->gam, P->ksum, P->ddiff, P->ax, P->ay, P->az};
  for (size_t i = 0; i < sizeof arrs / sizeof arrs[0]; i++) permute_d(arrs[i], P->tmp, i0, n, perm);
  int64_t *restrict id = P->tmp_i;
  uint8_t *restrict kind = (uint8_t *)P->tmp; /* P->tmp is free after the doubles */
  for (size_t i = 0; i < n; i++) id[i] = P->id[i0 + perm[i]], kind[i] = P->kind[i0 + perm[i]];
  memcpy(P->id + i0, id, n * sizeof(int64_t));
  memcpy(P->kind + i0, kind, n);
}
