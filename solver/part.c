/** @file part.c @brief Implementation of part.h. */
#include "part.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

/* Every per-particle array of part.h with its label and element size; `core` arrays exist in
   every run, the others (turbulence model) only when turb_init allocated them. */
struct array {
  void **p;
  const char *label;
  size_t elem;
  int core;
};

static size_t arrays(struct particles *P, struct array *t) {
  const size_t d = sizeof(double);
  const struct array all[] = {{(void **)&P->x, "x", d, 1},
                              {(void **)&P->y, "y", d, 1},
                              {(void **)&P->z, "z", d, 1},
                              {(void **)&P->u, "u", d, 1},
                              {(void **)&P->v, "v", d, 1},
                              {(void **)&P->w, "w", d, 1},
                              {(void **)&P->rho, "rho", d, 1},
                              {(void **)&P->m, "mass", d, 1},
                              {(void **)&P->gam, "gamma", d, 1},
                              {(void **)&P->ksum, "kernel_sum", d, 1},
                              {(void **)&P->ddiff, "diffusion", d, 1},
                              {(void **)&P->p, "pressure", d, 1},
                              {(void **)&P->c, "sound", d, 1},
                              {(void **)&P->pr2, "p_over_rho2", d, 1},
                              {(void **)&P->vol, "volume", d, 1},
                              {(void **)&P->rec, "pair_records", 16 * d, 1},
                              {(void **)&P->ax, "ax", d, 1},
                              {(void **)&P->ay, "ay", d, 1},
                              {(void **)&P->az, "az", d, 1},
                              {(void **)&P->sx, "stress_ax", SX_LEN * d, 0},
                              {(void **)&P->tmp, "sort_scratch", d, 1},
                              {(void **)&P->id, "id", sizeof(int64_t), 1},
                              {(void **)&P->tmp_i, "sort_scratch_i", sizeof(int64_t), 1},
                              {(void **)&P->kind, "kind", 1, 1},
                              {(void **)&P->nur, "nu_r", d, 0},
                              {(void **)&P->kr, "k_r", d, 0},
                              {(void **)&P->nur_next, "nu_r_next", d, 0},
                              {(void **)&P->kr_next, "k_r_next", d, 0},
                              {(void **)&P->twx, "wall_law_tx", d, 0},
                              {(void **)&P->twz, "wall_law_tz", d, 0},
                              {(void **)&P->shift_dy, "shift_dy", d, 0}};
  const size_t n = sizeof all / sizeof all[0];
  memcpy(t, all, sizeof all);
  return n;
}

enum { N_ARRAYS_MAX = 32 };

int part_check_memory(const struct scene *s) {
  const double nx = floor(s->lx / s->dr + 0.5), ny = floor(2.0 * s->delta / s->dr + 0.5);
  const double nz = s->dim == 3 ? floor(s->lz / s->dr + 0.5) : 1.0;
  const double n = nx * (ny - 1.0) * nz + 2.0 * nx * nz;
  /* a lower bound per particle: the arrays every run has, the step's scratch arrays (4
     diagnostics, the new kernel sum), the neighbour search's sort and counts, and the
     neighbour list at the expected number of neighbours within 2h */
  struct particles P;
  struct array t[N_ARRAYS_MAX];
  double per = 5.0 * sizeof(double) + sizeof(size_t) + 2.0 * sizeof(int);
  for (size_t i = 0, na = arrays(&P, t); i < na; i++)
    if (t[i].core) per += (double)t[i].elem;
  const double q = 2.0 * scene_h(s) / s->dr, pi = 3.14159265358979323846;
  per += sizeof(int32_t) * (s->dim == 3 ? 4.0 / 3.0 * pi * q * q * q : pi * q * q);
  const double need = n * per;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  const double have = pages > 0 && page > 0 ? (double)pages * (double)page : INFINITY;
  if (need <= have) return 0;
  error_input(
      "%s: keys 'domain.lx', 'domain.delta', 'domain.lz', 'domain.dr': %.4g particles need at "
      "least %.3g GB per MPI rank (every rank builds the initial lattice), more than the %.3g "
      "GB of memory of this machine: use a smaller domain or a larger dr",
      s->path[0] ? s->path : "(scene)", n, need / 1e9, have / 1e9);
  return 1;
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
  struct array t[N_ARRAYS_MAX];
  for (size_t i = 0, na = arrays(P, t); i < na; i++)
    if (t[i].core) *t[i].p = part_alloc(t[i].label, P->n * t[i].elem);

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
  struct array t[N_ARRAYS_MAX];
  for (size_t i = 0, na = arrays(P, t); i < na; i++)
    if (t[i].core) part_free(*t[i].p), *t[i].p = NULL; /* the others: turb_free, sim_free */
  part_free(W->rho), part_free(W->p);
  W->rho = W->p = NULL;
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
  const size_t used = P->n + P->n_ghost;
  if (cap < used) cap = used;
  struct array t[N_ARRAYS_MAX];
  for (size_t i = 0, na = arrays(P, t); i < na; i++) grow(t[i].p, t[i].label, t[i].elem, used, cap);
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
  if (P->sx && P->sx_live) /* the budget parts of a sampled step, one column at a time */
    for (int k = 0; k < SX_LEN; k++) {
      double *restrict col = P->tmp;
      for (size_t i = 0; i < n; i++) col[i] = P->sx[(i0 + perm[i]) * SX_LEN + k];
      for (size_t i = 0; i < n; i++) P->sx[(i0 + i) * SX_LEN + k] = col[i];
    }
  if (P->shift_dy) permute_d(P->shift_dy, P->tmp, i0, n, perm);
  if (P->nur_live) permute_d(P->nur, P->tmp, i0, n, perm), permute_d(P->kr, P->tmp, i0, n, perm);
  int64_t *restrict id = P->tmp_i;
  uint8_t *restrict kind = (uint8_t *)P->tmp; /* P->tmp is free after the doubles */
  for (size_t i = 0; i < n; i++) id[i] = P->id[i0 + perm[i]], kind[i] = P->kind[i0 + perm[i]];
  memcpy(P->id + i0, id, n * sizeof(int64_t));
  memcpy(P->kind + i0, kind, n);
}
