/** @file part.c @brief Implementation of part.h. */
#include "part.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "error.h"
#include "euler.h"
#include "nbr.h"
#include "records.h"

enum { MAX_LABELS = 64 };
static struct {
  const char *label;
  size_t bytes;
  void *ptr;
} allocs[MAX_LABELS];
static int n_allocs;

/* Colouring. Arrays larger than malloc's mmap threshold all begin at the same offset within a
   page, so a loop that streams many of them at one index maps them onto the same L1 cache sets
   (4K aliasing): after a mere change of the allocation order the neighbour build ran 8% slower
   (docs/performance.md). Each array therefore begins one cache line further into its page than
   the last (cycling over COLOURS lines); the start of its block is kept just before it, for
   part_free. */
enum { COLOURS = 32 };
static unsigned colour;

void *part_alloc(const char *label, size_t bytes) {
  const size_t rounded = ((bytes ? bytes : 1) + 63) / 64 * 64;
  const size_t shift = 64 * (1 + __atomic_fetch_add(&colour, 1, __ATOMIC_RELAXED) % COLOURS);
  char *base = aligned_alloc(64, rounded + shift);
  if (!base) die("out of memory allocating %s (%zu bytes)", label, bytes);
  void *ptr = base + shift;
  ((void **)ptr)[-1] = base;
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
  free(((void **)ptr)[-1]);
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

#define F(member) offsetof(struct particles, member)
#define ALL (PF_PERMUTE | PF_MIGRATE | PF_CKPT | PF_WRITE | PF_HEALTH)
/* Every per-particle array of part.h: what it takes part in (enum part_role), in the order of
   the files (particles.nc, checkpoint) and of the memory report. */
const struct part_field part_fields[] = {
    {F(x), "x", "x", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "m",
     "position x (streamwise)", REC_X, 0},
    {F(y), "y", "y", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "m",
     "position y (wall-normal)", REC_Y, 0},
    {F(z), "z", "z", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "m",
     "position z (spanwise)", REC_Z, 0},
    {F(u), "u", "u", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "m/s",
     "velocity u (streamwise)", REC_U, 0},
    {F(v), "v", "v", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "m/s",
     "velocity v (wall-normal)", REC_V, 0},
    {F(w), "w", "w", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "m/s",
     "velocity w (spanwise)", REC_W, 0},
    {F(rho), "rho", "rho", PT_F64, 1, ALL | PF_PAIR, PN_CORE, 0, 0, "kg/m^3", "density", REC_RHO,
     PR_DENSITY | PR_WALLS},
    {F(p), "pressure", "p", PT_F64, 1, PF_CKPT | PF_WRITE | PF_HEALTH, PN_CORE, 0, 0, "Pa",
     "pressure", 0, PR_DENSITY | PR_WALLS},
    {F(gam), "gamma", "gamma", PT_F64, 1, ALL, PN_CORE, 0, 0, "1", "wall renormalisation factor", 0,
     PR_BUDGET},
    {F(m), "mass", "mass", PT_F64, 1, ALL | PF_GHOST | PF_PAIR, PN_CORE, 0, 0, "kg",
     "mass (per metre of span in 2-D)", REC_M, 0},
    {F(ksum), "kernel_sum", "kernel_sum", PT_F64, 1, ALL & ~PF_WRITE, PN_CORE, 0, 0, "kg/m^dim",
     "kernel sum S of the continuity equation", 0, 0},
    {F(ddiff), "diffusion", NULL, PT_F64, 1, PF_PERMUTE | PF_MIGRATE, PN_CORE, 0, 0, NULL, NULL, 0,
     0},
    {F(drate), "density_rate", "density_rate", PT_F64, 1,
     PF_PERMUTE | PF_MIGRATE | PF_CKPT | PF_HEALTH, PN_DAMPER, 0, 1, "1/s",
     "(1/rho) D rho/Dt of the last step, = -div u (the acoustic damper)", 0, 0},
    {F(c), "sound", NULL, PT_F64, 1, PF_PAIR, PN_CORE, 0, 0, NULL, NULL, REC_C,
     PR_DENSITY | PR_WALLS},
    {F(pr2), "p_over_rho2", NULL, PT_F64, 1, PF_PAIR, PN_CORE, 0, 0, NULL, NULL, REC_PR2,
     PR_DENSITY | PR_WALLS | PR_KR},
    {F(vol), "volume", NULL, PT_F64, 1, PF_PAIR, PN_CORE, 0, 0, NULL, NULL, REC_VOL,
     PR_DENSITY | PR_WALLS},
    {F(rec), "pair_records", NULL, PT_F64, 16, 0, PN_CORE, 0, 0, NULL, NULL, 0, 0},
    {F(ax), "ax", "ax", PT_F64, 1, PF_PERMUTE | PF_MIGRATE | PF_HEALTH, PN_CORE, 0, 0, NULL, NULL,
     0, 0},
    {F(ay), "ay", "ay", PT_F64, 1, PF_PERMUTE | PF_MIGRATE | PF_HEALTH, PN_CORE, 0, 0, NULL, NULL,
     0, 0},
    {F(az), "az", "az", PT_F64, 1, PF_PERMUTE | PF_MIGRATE | PF_HEALTH, PN_CORE, 0, 0, NULL, NULL,
     0, 0},
    {F(sx), "stress_ax", NULL, PT_F64, SX_STRIDE, PF_PERMUTE | PF_MIGRATE, PN_EULERIAN, F(sx_live),
     0, NULL, NULL, 0, 0},
    {F(sxn), "stress_ax_noise", NULL, PT_F64, 3, PF_PERMUTE | PF_MIGRATE, PN_EULERIAN, F(sx_live),
     0, NULL, NULL, 0, 0},
    {F(vfx), "budget_vf_x", NULL, PT_F64, 1, 0, PN_EULERIAN, 0, 0, NULL, NULL, 0, PR_BUDGET},
    {F(vfy), "budget_vf_y", NULL, PT_F64, 1, 0, PN_EULERIAN, 0, 0, NULL, NULL, 0, PR_BUDGET},
    {F(vfz), "budget_vf_z", NULL, PT_F64, 1, 0, PN_EULERIAN, 0, 0, NULL, NULL, 0, PR_BUDGET},
    {F(kgc_xx), "kgc_b_xx", NULL, PT_F64, 1, 0, PN_KGC, 0, 0, NULL, NULL, 0, PR_KGC},
    {F(kgc_xy), "kgc_b_xy", NULL, PT_F64, 1, 0, PN_KGC, 0, 0, NULL, NULL, 0, PR_KGC},
    {F(kgc_xz), "kgc_b_xz", NULL, PT_F64, 1, 0, PN_KGC, 0, 0, NULL, NULL, 0, PR_KGC},
    {F(kgc_yy), "kgc_b_yy", NULL, PT_F64, 1, 0, PN_KGC, 0, 0, NULL, NULL, 0, PR_KGC},
    {F(kgc_yz), "kgc_b_yz", NULL, PT_F64, 1, 0, PN_KGC, 0, 0, NULL, NULL, 0, PR_KGC},
    {F(kgc_zz), "kgc_b_zz", NULL, PT_F64, 1, 0, PN_KGC, 0, 0, NULL, NULL, 0, PR_KGC},
    {F(tmp), "sort_scratch", NULL, PT_F64, 1, 0, PN_CORE, 0, 0, NULL, NULL, 0, 0},
    {F(id), "id", NULL, PT_I64, 1, PF_PERMUTE | PF_MIGRATE | PF_GHOST, PN_CORE, 0, 0, NULL, NULL, 0,
     0},
    {F(tmp_i), "sort_scratch_i", NULL, PT_I64, 1, 0, PN_CORE, 0, 0, NULL, NULL, 0, 0},
    {F(kind), "kind", NULL, PT_U8, 1, PF_PERMUTE | PF_MIGRATE | PF_GHOST, PN_CORE, 0, 0, NULL, NULL,
     0, 0},
    {F(nur), "nu_r", "nu_r", PT_F64, 1, PF_PERMUTE | PF_MIGRATE | PF_CKPT | PF_HEALTH | PF_PAIR,
     PN_LES, F(nur_live), 1, "m^2/s", "eddy viscosity of the next step", REC_NUR, PR_MODEL},
    {F(kr), "k_r", "k_r", PT_F64, 1, PF_PERMUTE | PF_MIGRATE | PF_CKPT | PF_HEALTH, PN_LES,
     F(nur_live), 1, "m^2/s^2", "residual kinetic energy of the next step", 0, PR_MODEL},
    {F(nur_next), "nu_r_next", NULL, PT_F64, 1, 0, PN_STRAIN_LAG, 0, 0, NULL, NULL, 0, 0},
    {F(kr_next), "k_r_next", NULL, PT_F64, 1, 0, PN_STRAIN_LAG, 0, 0, NULL, NULL, 0, 0},
    {F(twx), "wall_law_tx", NULL, PT_F64, 1, 0, PN_WALL_TAU, 0, 0, NULL, NULL, 0, 0},
    {F(twz), "wall_law_tz", NULL, PT_F64, 1, 0, PN_WALL_TAU, 0, 0, NULL, NULL, 0, 0},
    {F(shift_dx), "shift_dx", NULL, PT_F64, 1, PF_PERMUTE | PF_MIGRATE, PN_SHIFTING, 0, 0, NULL,
     NULL, 0, PR_SHIFT},
    {F(shift_dy), "shift_dy", NULL, PT_F64, 1, PF_PERMUTE | PF_MIGRATE, PN_SHIFTING, 0, 0, NULL,
     NULL, 0, PR_SHIFT},
    {F(shift_dz), "shift_dz", NULL, PT_F64, 1, PF_PERMUTE | PF_MIGRATE, PN_SHIFTING, 0, 0, NULL,
     NULL, 0, PR_SHIFT},
    {F(qcrit), "q_criterion", "q_criterion", PT_F64, 1, PF_WRITE, PN_QCRIT, 0, 0, "1/s^2",
     "Q criterion (|Omega|^2 - |S|^2)/2 of the corrected velocity gradient", 0, 0},
};
#undef ALL
#undef F
const int part_n_fields = sizeof part_fields / sizeof part_fields[0];

#define W(member) offsetof(struct walls, member)
/* Every array of struct walls. */
const struct wall_field wall_fields[] = {
    {W(rho), "wall_rho", PN_CORE, PR_WALLS},
    {W(p), "wall_p", PN_CORE, PR_WALLS | PR_KR},
    {W(tx), "wall_tau_x", PN_WALL_TAU, PR_WALL_LAW},
    {W(tz), "wall_tau_z", PN_WALL_TAU, PR_WALL_LAW},
};
#undef W
const int wall_n_fields = sizeof wall_fields / sizeof wall_fields[0];

int part_needed(enum part_need need, const struct scene *s) {
  switch (need) {
    case PN_CORE:
      return 1;
    case PN_LES:
      return scene_les(s);
    case PN_STRAIN_LAG:
      return scene_strain_lag(s);
    case PN_WALL_TAU:
      return scene_wall_tau(s);
    case PN_EULERIAN:
      return scene_stats_num(s, &euler_key_eulerian) != 0.0;
    case PN_SHIFTING:
      return s->shifting != SHIFT_NONE;
    case PN_QCRIT:
      return s->q_criterion;
    case PN_DAMPER:
      return s->damper > 0.0;
    case PN_KGC:
      return s->pgrad == PGRAD_KGC;
  }
  return 0;
}

static size_t elem_size(const struct part_field *f) {
  return (size_t)f->width * (f->type == PT_F64   ? sizeof(double)
                             : f->type == PT_I64 ? sizeof(int64_t)
                                                 : sizeof(uint8_t));
}

/* The table as the allocation helpers below use it: pointer, label, bytes per particle, core. */
struct array {
  void **p;
  const char *label;
  size_t elem;
  int core; /*!< need == PN_CORE */
};

static size_t arrays(struct particles *P, struct array *t) {
  for (int i = 0; i < part_n_fields; i++)
    t[i] = (struct array){(void **)((char *)P + part_fields[i].off), part_fields[i].label,
                          elem_size(&part_fields[i]), part_fields[i].need == PN_CORE};
  return (size_t)part_n_fields;
}

enum { N_ARRAYS_MAX = 64 };

double part_bytes(const struct scene *s, double *count) {
  const double nx = floor(s->lx / s->dr + 0.5), ny = floor(2.0 * s->delta / s->dr + 0.5);
  const double nz = s->dim == 3 ? floor(s->lz / s->dr + 0.5) : 1.0;
  const double n = nx * (ny - 1.0) * nz + 2.0 * nx * nz;
  /* a lower bound per particle: the arrays every run has, the step's scratch arrays (4
     diagnostics, the new kernel sum), the neighbour search's sort and counts, the neighbour
     list at its starting stride, and the checkpoint's copy of the stored arrays (gathered by
     id, then the writer's buffer) */
  struct particles P;
  struct array t[N_ARRAYS_MAX];
  double per = 5.0 * sizeof(double) + sizeof(size_t) + 2.0 * sizeof(int);
  for (size_t i = 0, na = arrays(&P, t); i < na; i++) {
    if (t[i].core) per += (double)t[i].elem;
    if (t[i].core && (part_fields[i].roles & PF_CKPT)) per += 2.0 * (double)t[i].elem;
  }
  per += sizeof(int32_t) * (double)nbr_stride(s);
  *count = n;
  return n * per;
}

/* The lattice particle of id a, fluid (slot a of the whole lattice, i j k order) or vertex. */
static void lattice_particle(struct particles *P, size_t slot, const struct scene *s, int nx,
                             int ny, int nz, size_t a) {
  const double dr = s->dr, mass = s->rho0 * pow(dr, s->dim);
  const double zc = s->dim == 3 ? 0.5 * dr : 0.0;
  const size_t nf = (size_t)nx * (size_t)(ny - 1) * (size_t)nz;
  if (a < nf) {
    const size_t k = a % (size_t)nz, j = 1 + (a / (size_t)nz) % (size_t)(ny - 1),
                 i = a / ((size_t)nz * (size_t)(ny - 1));
    P->x[slot] = (i + 0.5) * dr, P->y[slot] = j * dr, P->z[slot] = k * dr + zc;
    P->m[slot] = mass, P->gam[slot] = 1.0, P->kind[slot] = KIND_FLUID;
  } else {
    const size_t v = a - nf, k = v % (size_t)nz, i = (v / (size_t)nz) % (size_t)nx,
                 wall = v / ((size_t)nz * (size_t)nx);
    P->x[slot] = (i + 0.5) * dr, P->y[slot] = wall ? 2.0 * s->delta : 0.0;
    P->z[slot] = k * dr + zc;
    P->m[slot] = 0.5 * mass, P->gam[slot] = 0.5, P->kind[slot] = KIND_VERTEX;
  }
  P->rho[slot] = s->rho0, P->id[slot] = (int64_t)a;
}

/* Whether the lattice particle of id a is in the selection (NULL: every particle). */
static int selected(const struct part_select *sel, const struct scene *s, int nx, int ny, int nz,
                    size_t a) {
  if (!sel) return 1;
  if (a < sel->lo || a >= sel->hi) return 0;
  if (!sel->keep) return 1;
  struct particles one;
  double x, y, z, m, g, rho;
  int64_t id;
  uint8_t kind;
  one.x = &x, one.y = &y, one.z = &z, one.m = &m, one.gam = &g, one.rho = &rho, one.id = &id;
  one.kind = &kind;
  lattice_particle(&one, 0, s, nx, ny, nz, a);
  return sel->keep(sel->ctx, x, z);
}

void part_create(struct particles *P, struct walls *W, const struct scene *s) {
  part_create_part(P, W, s, NULL);
}

void part_create_part(struct particles *P, struct walls *W, const struct scene *s,
                      const struct part_select *sel) {
  const int nx = (int)floor(s->lx / s->dr + 0.5);
  const int ny = (int)floor(2.0 * s->delta / s->dr + 0.5);
  const int nz = s->dim == 3 ? (int)floor(s->lz / s->dr + 0.5) : 1;
  memset(P, 0, sizeof *P);
  P->n_fluid = (size_t)nx * (size_t)(ny - 1) * (size_t)nz;
  P->n_vertex = 2 * (size_t)nx * (size_t)nz;
  const size_t N = P->n_fluid + P->n_vertex;
  /* count, allocate, fill: the lattice in id order, each particle tested (no full lattice) */
  size_t n = 0;
  if (!sel) {
    n = N;
  } else if (!sel->keep) {
    n = (sel->hi < N ? sel->hi : N) - (sel->lo < N ? sel->lo : N);
  } else {
    for (size_t a = 0; a < N; a++) n += (size_t)selected(sel, s, nx, ny, nz, a);
  }
  P->n = n, P->cap = n ? n : 1;
  struct array t[N_ARRAYS_MAX];
  for (size_t i = 0, na = arrays(P, t); i < na; i++)
    if (t[i].core) *t[i].p = part_alloc(t[i].label, P->cap * t[i].elem);
  size_t slot = 0;
  const size_t a0 = sel && !sel->keep ? sel->lo : 0,
               a1 = sel && !sel->keep && sel->hi < N ? sel->hi : N;
  for (size_t a = a0; a < a1; a++)
    if (!sel || !sel->keep || selected(sel, s, nx, ny, nz, a))
      lattice_particle(P, slot++, s, nx, ny, nz, a);
  memset(W, 0, sizeof *W); /* the optional wall arrays stay NULL (part_alloc_optional) */
  W->nx = nx, W->nz = nz;
  for (int i = 0; i < wall_n_fields; i++)
    if (wall_fields[i].need == PN_CORE)
      *(double **)((char *)W + wall_fields[i].off) =
          part_alloc(wall_fields[i].label, P->n_vertex * sizeof(double));
  for (size_t v = 0; v < P->n_vertex; v++) W->rho[v] = s->rho0; /* every rank: all walls */
}

void part_move(struct particles *P, size_t to, size_t from, size_t n) {
  struct array t[N_ARRAYS_MAX];
  for (size_t i = 0, na = arrays(P, t); i < na; i++)
    if (*t[i].p)
      memmove((char *)*t[i].p + to * t[i].elem, (char *)*t[i].p + from * t[i].elem, n * t[i].elem);
}

void part_alloc_optional(struct particles *P, struct walls *W, const struct scene *s) {
  for (int i = 0; i < part_n_fields; i++) {
    const struct part_field *f = &part_fields[i];
    if (f->need != PN_CORE && part_needed(f->need, s))
      *(void **)((char *)P + f->off) = part_alloc(f->label, P->cap * elem_size(f));
  }
  for (int i = 0; i < wall_n_fields; i++) {
    const struct wall_field *f = &wall_fields[i];
    if (f->need != PN_CORE && part_needed(f->need, s))
      *(double **)((char *)W + f->off) = part_alloc(f->label, P->n_vertex * sizeof(double));
  }
}

void part_destroy(struct particles *P, struct walls *W) {
  for (int i = 0; i < part_n_fields; i++) {
    void **p = (void **)((char *)P + part_fields[i].off);
    part_free(*p), *p = NULL;
  }
  for (int i = 0; i < wall_n_fields; i++) {
    double **p = (double **)((char *)W + wall_fields[i].off);
    part_free(*p), *p = NULL;
  }
  P->nur_live = P->sx_live = 0;
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

void part_permute(struct particles *P, size_t i0, size_t n, const size_t *perm) {
  /* the doubles first (P->tmp is their scratch, a column at a time), then ids and kinds; every
     thread gathers and writes back the same share of the slots (static schedule), so only the
     gather of a column waits for all threads before its write-back */
  int64_t *restrict id = P->tmp_i;
  uint8_t *restrict kind = (uint8_t *)P->tmp; /* P->tmp is free after the doubles */
#pragma omp parallel
  {
    for (int i = 0; i < part_n_fields; i++) {
      const struct part_field *f = &part_fields[i];
      if (!(f->roles & PF_PERMUTE) || f->type != PT_F64 || !part_field_live(P, f)) continue;
      double *restrict arr = part_field_ptr(P, f), *restrict col = P->tmp;
      const size_t w = (size_t)f->width;
      if (w == 1) { /* contiguous: the loops vectorise */
        const double *restrict src = arr + i0;
#pragma omp for schedule(static)
        for (size_t j = 0; j < n; j++) col[j] = src[perm[j]];
#pragma omp for schedule(static) nowait
        for (size_t j = 0; j < n; j++) arr[i0 + j] = col[j];
        continue;
      }
      for (size_t k = 0; k < w; k++) {
#pragma omp for schedule(static)
        for (size_t j = 0; j < n; j++) col[j] = arr[(i0 + perm[j]) * w + k];
#pragma omp for schedule(static) nowait
        for (size_t j = 0; j < n; j++) arr[(i0 + j) * w + k] = col[j];
      }
    }
#pragma omp barrier /* the kinds' bytes overlap other threads' shares of the last column */
#pragma omp for schedule(static)
    for (size_t j = 0; j < n; j++) id[j] = P->id[i0 + perm[j]], kind[j] = P->kind[i0 + perm[j]];
#pragma omp for schedule(static) nowait
    for (size_t j = 0; j < n; j++) P->id[i0 + j] = id[j], P->kind[i0 + j] = kind[j];
  }
}
