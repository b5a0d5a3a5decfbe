/** @file dd.c @brief Implementation of dd.h. */
#include "dd.h"

#include <math.h>
#include <mpi.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "reduce.h"
#include "timers.h"

/* A particle on the wire: its fields of one role (PF_MIGRATE: migration; PF_GHOST: a ghost of
   the halo), in table order (part.h), width values each (an id's bytes in one double, a kind
   as a double); a field not in use or not live travels as zeros and is not unpacked. F_LEN
   bounds the record. */
enum { F_LEN = 48 };

static int record_len(int role) {
  static int len[2] = {0, 0};
  const int k = role == PF_GHOST;
  if (len[k]) return len[k];
  int n = 0;
  for (int i = 0; i < part_n_fields; i++)
    if (part_fields[i].roles & role) n += part_fields[i].width;
  if (n > F_LEN) die("a particle record of %d values exceeds F_LEN (dd.c)", n);
  return len[k] = n;
}

/* tags: a message going below (to the lower neighbour) and above, along x and along z; the
   migration's counts and records */
enum { TAG_LEFT = 11, TAG_RIGHT = 12, TAG_ZLO = 13, TAG_ZHI = 14, TAG_MCNT = 15, TAG_MREC = 16 };

static void reserve_buf(double **buf, size_t *cap, size_t n) {
  if (n <= *cap) return;
  *cap = n + n / 2;
  *buf = mem_realloc(*buf, *cap, sizeof(double), "domain decomposition");
}

/* The fields of one role as they travel, resolved once per exchange: each live field's array
   (NULL: travels as zeros, not unpacked), width and type, in table order. */
struct wire {
  int n;
  void *arr[F_LEN];
  int width[F_LEN], type[F_LEN];
};

static void wire_fields(const struct particles *P, int role, struct wire *w) {
  w->n = 0;
  for (int i = 0; i < part_n_fields; i++) {
    const struct part_field *f = &part_fields[i];
    if (!(f->roles & role)) continue;
    w->arr[w->n] = part_field_live(P, f) ? part_field_ptr(P, f) : NULL;
    w->width[w->n] = f->width, w->type[w->n] = f->type, w->n++;
  }
}

/* pack() and unpack() of slot a with the fields resolved (the same record). */
static inline void wire_pack(const struct wire *w, size_t a, double *r) {
  for (int i = 0; i < w->n; i++) {
    const void *arr = w->arr[i];
    if (w->type[i] == PT_I64)
      memcpy(r, (const int64_t *)arr + a, sizeof(double));
    else if (w->type[i] == PT_U8)
      r[0] = ((const uint8_t *)arr)[a];
    else
      for (int k = 0; k < w->width[i]; k++)
        r[k] = arr ? ((const double *)arr)[a * w->width[i] + k] : 0.0;
    r += w->width[i];
  }
}

static inline void wire_unpack(const struct wire *w, size_t a, const double *r) {
  for (int i = 0; i < w->n; i++) {
    void *arr = w->arr[i];
    if (w->type[i] == PT_I64)
      memcpy((int64_t *)arr + a, r, sizeof(double));
    else if (w->type[i] == PT_U8)
      ((uint8_t *)arr)[a] = (uint8_t)r[0];
    else if (arr)
      for (int k = 0; k < w->width[i]; k++) ((double *)arr)[a * w->width[i] + k] = r[k];
    r += w->width[i];
  }
}

/* The share [i0, i1) of thread t of nt in n items. */
static void thread_share(size_t n, int t, int nt, size_t *i0, size_t *i1) {
  *i0 = n * (size_t)t / (size_t)nt, *i1 = n * (size_t)(t + 1) / (size_t)nt;
}

/* wire_pack of the slots slots[0 .. n-1] into records of len values at buf, field by field
   (each field's loop over the particles is a plain strided copy; the per-record loop over the
   fields, with a type test per field, took 4-5 times the instructions). Called by each thread
   on its share. */
static void wire_pack_list(const struct wire *w, const size_t *restrict slots, size_t n,
                           double *restrict buf, int len) {
  int off = 0;
  for (int i = 0; i < w->n; i++) {
    const int W = w->width[i];
    double *restrict r = buf + off;
    if (w->type[i] == PT_I64) {
      const int64_t *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++) memcpy(r + j * len, arr + slots[j], sizeof(double));
    } else if (w->type[i] == PT_U8) {
      const uint8_t *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++) r[j * len] = arr[slots[j]];
    } else if (!w->arr[i]) {
      for (size_t j = 0; j < n; j++)
        for (int k = 0; k < W; k++) r[j * len + k] = 0.0;
    } else if (W == 1) {
      const double *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++) r[j * len] = arr[slots[j]];
    } else {
      const double *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++)
        for (int k = 0; k < W; k++) r[j * len + k] = arr[slots[j] * W + k];
    }
    off += W;
  }
}

/* wire_unpack of records of len values at buf into the slots slots[0 .. n-1] (or first + j
   where slots is NULL), field by field; a field not live is skipped. Each thread its share. */
static void wire_unpack_list(const struct wire *w, const size_t *restrict slots, size_t first,
                             size_t n, const double *restrict buf, int len) {
  int off = 0;
  for (int i = 0; i < w->n; i++) {
    const int W = w->width[i];
    const double *restrict r = buf + off;
    off += W;
    if (w->type[i] == PT_I64) {
      int64_t *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++)
        memcpy(arr + (slots ? slots[j] : first + j), r + j * len, sizeof(double));
    } else if (w->type[i] == PT_U8) {
      uint8_t *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++) arr[slots ? slots[j] : first + j] = (uint8_t)r[j * len];
    } else if (w->arr[i]) {
      double *restrict arr = w->arr[i];
      for (size_t j = 0; j < n; j++) {
        const size_t a = slots ? slots[j] : first + j;
        for (int k = 0; k < W; k++) arr[a * W + k] = r[j * len + k];
      }
    }
  }
}

static void pack(const struct particles *P, size_t a, double *r, int role) {
  struct wire w;
  wire_fields(P, role, &w);
  wire_pack(&w, a, r);
}

static void copy_slot(struct particles *P, size_t to, size_t from) {
  double r[F_LEN];
  struct wire w;
  wire_fields(P, PF_MIGRATE, &w);
  wire_pack(&w, from, r);
  wire_unpack(&w, to, r);
}

/* Even cuts of n cells over p parts. */
static void cut_even(int *first, int p, int n) {
  for (int r = 0; r <= p; r++) first[r] = (int)((long)r * n / p);
}

/* Ghost cells per rank of Px x Pz blocks (the halo's volume, in pencils), or -1 if a block
   would be thinner than 2 NBR_REACH in a cut direction. */
static double ghost_pencils(int px, int pz, int ncol, int nplane) {
  const int R = NBR_REACH, hx = px > 1 ? R : 0, hz = pz > 1 ? R : 0;
  if ((px > 1 && ncol < 2 * R * px) || (pz > 1 && nplane < 2 * R * pz)) return -1.0;
  const double nxo = (double)ncol / px, nzo = (double)nplane / pz;
  return 2.0 * hx * nzo + 2.0 * hz * (nxo + 2.0 * hx);
}

/* Px x Pz: run.ranks, or the factorisation with the fewest ghosts (ties: more slabs along x). */
static int choose_blocks(struct dd *d, const struct scene *sc) {
  const char *path = sc->path[0] ? sc->path : "(scene)";
  const int R = NBR_REACH;
  if (sc->ranks.n > 0) {
    const int px = sc->ranks.n == 2 ? (int)sc->ranks.v[0] : 0,
              pz = sc->ranks.n == 2 ? (int)sc->ranks.v[1] : 0;
    if (px < 1 || pz < 1 || (double)px * pz != (double)d->size) {
      error_input(
          "%s: key 'run.ranks': %s; this run has %d MPI ranks, so Px x Pz = %d "
          "(or leave it empty for the factorisation with the fewest ghosts; on resume: "
          "--set run.ranks=Px,Pz or --set run.ranks=)",
          path, sc->ranks.n == 2 ? "Px x Pz differs from the ranks" : "two entries Px,Pz", d->size,
          d->size);
      return CHANSPH_ERR;
    }
    if (sc->dim == 2 && pz > 1) {
      error_input("%s: key 'run.ranks': a 2-D scene is cut along x only (Pz = 1, got %d)", path,
                  pz);
      return CHANSPH_ERR;
    }
    if (ghost_pencils(px, pz, d->ncol, d->nplane) < 0.0) {
      error_input(
          "%s: key 'run.ranks': %d x %d blocks of %d columns (domain.lx) and %d planes "
          "(domain.lz) of size h: each block needs at least %d columns and %d planes "
          "along a cut direction, so at most %d x %d ranks",
          path, px, pz, d->ncol, d->nplane, 2 * R, 2 * R, d->ncol / (2 * R),
          sc->dim == 3 ? d->nplane / (2 * R) : 1);
      return CHANSPH_ERR;
    }
    d->px = px, d->pz = pz;
    return CHANSPH_OK;
  }
  double best = -1.0;
  for (int px = d->size; px >= 1; px--) {
    if (d->size % px) continue;
    const int pz = d->size / px;
    if (sc->dim == 2 && pz > 1) continue;
    const double g = ghost_pencils(px, pz, d->ncol, d->nplane);
    if (g >= 0.0 && (best < 0.0 || g < best - 1e-9)) best = g, d->px = px, d->pz = pz;
  }
  if (best < 0.0) {
    const int mx = d->ncol / (2 * R), mz = sc->dim == 3 ? d->nplane / (2 * R) : 1;
    if (sc->dim == 3)
      error_input(
          "%s: keys 'domain.lx', 'domain.lz': %d cell columns and %d planes of size h; "
          "a block needs at least %d columns along x and %d planes along z where "
          "they are cut, so at most %d x %d = %d ranks; this run has %d",
          path, d->ncol, d->nplane, 2 * R, 2 * R, mx, mz, mx * mz, d->size);
    else
      error_input(
          "%s: key 'domain.lx': %d cell columns of size h; a slab needs at least %d, "
          "so at most %d ranks; this run has %d",
          path, d->ncol, 2 * R, mx, d->size);
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

/* The neighbours of the block: along x and z for the halo, and the distinct ranks of the 3 x 3
   blocks around it (not itself) for the migration. */
static void set_neighbours(struct dd *d) {
  const int px = d->px, pz = d->pz;
  d->dir[0].width = px > 1 ? NBR_REACH : 0, d->dir[1].width = pz > 1 ? NBR_REACH : 0;
  d->dir[0].lo = d->bz * px + (d->bx + px - 1) % px, d->dir[0].hi = d->bz * px + (d->bx + 1) % px;
  d->dir[1].lo = ((d->bz + pz - 1) % pz) * px + d->bx,
  d->dir[1].hi = ((d->bz + 1) % pz) * px + d->bx;
  d->nnb = 0;
  for (int dz = -1; dz <= 1; dz++)
    for (int dx = -1; dx <= 1; dx++) {
      const int r = ((d->bz + dz + pz) % pz) * px + (d->bx + dx + px) % px;
      int seen = r == d->rank;
      for (int k = 0; k < d->nnb; k++) seen |= d->nb_rank[k] == r;
      if (!seen) d->nb_rank[d->nnb++] = r;
    }
}

int dd_init(struct dd *d, const struct scene *sc, dd_reserve_fn reserve, void *ctx) {
  memset(d, 0, sizeof *d);
  MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &d->size);
  const struct nbr_range whole = nbr_whole(sc);
  d->ncol = whole.nxo, d->nplane = whole.nzo;
  d->reserve = reserve, d->ctx = ctx;
  d->px = d->pz = 1;
  if (d->size > 1 && choose_blocks(d, sc)) return CHANSPH_ERR;
  d->bx = d->rank % d->px, d->bz = d->rank / d->px;
  d->fx = mem_alloc((size_t)(d->px + d->pz + 2), sizeof(int), "domain decomposition");
  d->fz = d->fx + d->px + 1;
  cut_even(d->fx, d->px, d->ncol), cut_even(d->fz, d->pz, d->nplane);
  set_neighbours(d);
  d->comm_x = d->comm_z = MPI_COMM_NULL;
  if (d->pz > 1) {
    CHECK_MPI(MPI_Comm_split(MPI_COMM_WORLD, d->bx, d->bz, &d->comm_z));
    if (d->px > 1) CHECK_MPI(MPI_Comm_split(MPI_COMM_WORLD, d->bz, d->bx, &d->comm_x));
  }
  const struct scene_list *L = &sc->partition;
  if (L->n > 0) { /* columns per rank from the scene: slabs */
    const int minw = 2 * NBR_REACH;
    int sum = 0, ok = L->n == d->size && d->pz == 1;
    for (int r = 0; r < L->n; r++) sum += (int)L->v[r], ok = ok && (int)L->v[r] >= minw;
    if (!ok || sum != d->ncol) {
      error_input(
          "%s: key 'run.partition': %d entries summing to %d; this run needs %d entries "
          "(one per rank, with slabs: run.ranks = %d,1), each at least %d, summing to the %d "
          "cell columns",
          sc->path[0] ? sc->path : "(scene)", L->n, sum, d->size, d->size, minw, d->ncol);
      return CHANSPH_ERR;
    }
    for (int r = 0; r < d->size; r++) d->fx[r + 1] = d->fx[r] + (int)L->v[r];
  }
  return CHANSPH_OK;
}

double dd_share(const struct dd *d) {
  if (d->size == 1) return 1.0;
  const double nxo = d->fx[d->bx + 1] - d->fx[d->bx], nzo = d->fz[d->bz + 1] - d->fz[d->bz];
  const double hx = d->dir[0].width, hz = d->dir[1].width;
  const double pencils = (nxo + 2.0 * hx) * (nzo + 2.0 * hz);
  return 1.5 * pencils / ((double)d->ncol * (double)d->nplane); /* sim_distribute's room */
}

struct nbr_range dd_range(const struct dd *d) {
  return (struct nbr_range){d->fx[d->bx], d->fx[d->bx + 1] - d->fx[d->bx], d->dir[0].width,
                            d->fz[d->bz], d->fz[d->bz + 1] - d->fz[d->bz], d->dir[1].width};
}

void dd_free(struct dd *d) {
  int fin = 0;
  MPI_Finalized(&fin);
  if (!fin && d->comm_x != MPI_COMM_NULL) MPI_Comm_free(&d->comm_x);
  if (!fin && d->comm_z != MPI_COMM_NULL) MPI_Comm_free(&d->comm_z);
  free(d->fx), free(d->ghost), free(d->row);
  for (int k = 0; k < 2; k++) {
    free(d->dir[k].send[0]), free(d->dir[k].send[1]);
    for (int s = 0; s < 4; s++) free(d->dir[k].cnt[s]);
  }
  free(d->sbuf), free(d->rbuf);
  memset(d, 0, sizeof *d);
}

/* The part p with first[p] <= i < first[p+1] (n parts). */
static int part_of(const int *first, int n, int i) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (first[mid] <= i)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

int dd_owner(const struct dd *d, int col, int plane) {
  return part_of(d->fz, d->pz, plane) * d->px + part_of(d->fx, d->px, col);
}

static int owned(const struct dd *d, int col, int plane) {
  return col >= d->fx[d->bx] && col < d->fx[d->bx + 1] && plane >= d->fz[d->bz] &&
         plane < d->fz[d->bz + 1];
}

void dd_keep_owned(struct dd *d, struct particles *P, const struct nbr *nb) {
  size_t k = 0;
  for (size_t a = 0; a < P->n; a++) {
    nbr_wrap_position(nb, &P->x[a], &P->z[a]);
    if (!owned(d, nbr_column(nb, P->x[a]), nbr_plane(nb, P->z[a]))) continue;
    if (k != a) copy_slot(P, k, a);
    k++;
  }
  P->n = k, P->n_ghost = 0;
}

void dd_take_block(struct dd *d, struct particles *P, const struct nbr *nb, size_t lo, size_t n) {
  for (size_t a = 0; a < n; a++)
    if (a != lo + a) copy_slot(P, a, lo + a);
  P->n = n, P->n_ghost = 0;
  dd_migrate(d, P, nb);
  d->seconds = d->bytes = d->ghosts = 0.0; /* the run's counters start here */
  d->messages = d->migrated = d->halos = 0;
}

/* The slots of the particles this rank keeps (dest[a] < 0) or sends (dest[a] >= 0), each list
   in slot order: threads count their share, then fill their part of the lists. */
static void split_slots(const int *dest, size_t n, size_t *leave, size_t *nleave) {
  const int nt = omp_get_max_threads();
  size_t *cnt = mem_calloc((size_t)nt + 1, sizeof(size_t), "domain decomposition");
#pragma omp parallel num_threads(nt)
  {
    const int t = omp_get_thread_num(), th = omp_get_num_threads();
    const size_t a0 = n * (size_t)t / (size_t)th, a1 = n * (size_t)(t + 1) / (size_t)th;
    size_t k = 0;
    for (size_t a = a0; a < a1; a++) k += dest[a] >= 0;
    cnt[t + 1] = k;
#pragma omp barrier
#pragma omp single
    for (int s = 0; s < th; s++) cnt[s + 1] += cnt[s];
    k = cnt[t];
    for (size_t a = a0; a < a1; a++)
      if (dest[a] >= 0) leave[k++] = a;
  }
  *nleave = cnt[nt];
  free(cnt);
}

/* The exchange of dd_migrate when every leaving particle goes to a neighbouring block (packed
   by destination rank at sdisp, scount values each): the counts, then the records, with the
   distinct neighbours only (at most 8 messages each way whatever the number of ranks, where
   the all-to-all costs O(ranks)). The arrivals land in neighbour order in d->rbuf; their
   order is free (nbr_sort orders the particles by cell and id). Returns the values received. */
static size_t migrate_near(struct dd *d, const int *scount, const int *sdisp) {
  const int n = d->nnb;
  int rc[8] = {0};
  MPI_Request req[16];
  timer_push("halo:wait");
  for (int k = 0; k < n; k++) {
    CHECK_MPI(MPI_Irecv(&rc[k], 1, MPI_INT, d->nb_rank[k], TAG_MCNT, MPI_COMM_WORLD, &req[k]));
    CHECK_MPI(MPI_Isend(&scount[d->nb_rank[k]], 1, MPI_INT, d->nb_rank[k], TAG_MCNT, MPI_COMM_WORLD,
                        &req[n + k]));
  }
  CHECK_MPI(MPI_Waitall(2 * n, req, MPI_STATUSES_IGNORE));
  size_t total = 0, off[8];
  for (int k = 0; k < n; k++) off[k] = total, total += (size_t)rc[k];
  reserve_buf(&d->rbuf, &d->cap_rbuf, total);
  for (int k = 0; k < n; k++) {
    const int r = d->nb_rank[k];
    CHECK_MPI(MPI_Irecv(d->rbuf + off[k], rc[k], MPI_DOUBLE, r, TAG_MREC, MPI_COMM_WORLD, &req[k]));
    CHECK_MPI(MPI_Isend(d->sbuf + sdisp[r], scount[r], MPI_DOUBLE, r, TAG_MREC, MPI_COMM_WORLD,
                        &req[n + k]));
  }
  CHECK_MPI(MPI_Waitall(2 * n, req, MPI_STATUSES_IGNORE));
  timer_pop();
  return total;
}

/* The rank each of the n0 owned particles goes to (-1: stays), positions wrapped. A local copy
   of the grid and the owned range: the stores of the wrapped positions cannot alias them. */
static void migrate_dest(const struct dd *d, struct particles *P, const struct nbr *nb, size_t n0,
                         int *dest) {
  const struct nbr g = *nb;
  const int c0 = d->fx[d->bx], c1 = d->fx[d->bx + 1], z0 = d->fz[d->bz], z1 = d->fz[d->bz + 1];
  double *restrict px = P->x, *restrict pz = P->z;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < n0; a++) {
    nbr_wrap_position(&g, &px[a], &pz[a]);
    const int col = nbr_column(&g, px[a]), plane = nbr_plane(&g, pz[a]);
    dest[a] = col >= c0 && col < c1 && plane >= z0 && plane < z1 ? -1 : dd_owner(d, col, plane);
  }
}

void dd_migrate(struct dd *d, struct particles *P, const struct nbr *nb) {
  P->n_ghost = 0;
  if (d->size == 1) return;
  timer_push("halo:migrate");
  const double t0 = MPI_Wtime();
  const int np = d->size, rl = record_len(PF_MIGRATE);
  int *scount = mem_calloc((size_t)np, sizeof(int), "domain decomposition"),
      *rcount = mem_calloc((size_t)np, sizeof(int), "domain decomposition");
  int *sdisp = mem_calloc((size_t)np + 1, sizeof(int), "domain decomposition"),
      *rdisp = mem_calloc((size_t)np + 1, sizeof(int), "domain decomposition");
  const size_t n0 = P->n;
  int *dest = mem_alloc(1, (n0 ? n0 : 1) * sizeof(int), "domain decomposition");
  size_t *leave = mem_alloc(1, (n0 ? n0 : 1) * sizeof(size_t), "domain decomposition");
  migrate_dest(d, P, nb, n0, dest);
  size_t leaving;
  split_slots(dest, n0, leave, &leaving);
  for (size_t i = 0; i < leaving; i++) scount[dest[leave[i]]] += rl;
  for (int r = 0; r < np; r++) sdisp[r + 1] = sdisp[r] + scount[r];
  reserve_buf(&d->sbuf, &d->cap_sbuf, (size_t)sdisp[np]);
  /* pack the leaving particles by destination, each in slot order */
  int *fill = mem_calloc((size_t)np, sizeof(int), "domain decomposition");
  for (size_t i = 0; i < leaving; i++) {
    const int r = dest[leave[i]];
    pack(P, leave[i], d->sbuf + sdisp[r] + fill[r], PF_MIGRATE);
    fill[r] += rl;
  }
  /* fill the holes they leave with the last staying particles (the order of the slots is
     free: nbr_sort orders them by cell and id whatever order they come in) */
  size_t end = n0;
  for (size_t i = 0; i < leaving; i++) {
    const size_t hole = leave[i];
    while (end > hole && dest[end - 1] >= 0) end--; /* leaving too: dropped, not moved */
    if (end <= hole) break;                         /* no staying particle after this hole */
    copy_slot(P, hole, --end);
  }
  P->n = n0 - leaving;
  /* the usual step: every particle that leaves goes to a neighbouring block */
  int near = 1;
  for (int r = 0; r < np && near; r++) {
    if (!scount[r]) continue;
    int k = 0;
    while (k < d->nnb && d->nb_rank[k] != r) k++;
    near = k < d->nnb;
  }
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &near, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD));
  size_t arrived;
  if (near) {
    arrived = migrate_near(d, scount, sdisp);
  } else { /* after a re-partition or the start: anywhere */
    CHECK_MPI(MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, MPI_COMM_WORLD));
    for (int r = 0; r < np; r++) rdisp[r + 1] = rdisp[r] + rcount[r];
    reserve_buf(&d->rbuf, &d->cap_rbuf, (size_t)rdisp[np]);
    timer_push("halo:wait");
    CHECK_MPI(MPI_Alltoallv(d->sbuf, scount, sdisp, MPI_DOUBLE, d->rbuf, rcount, rdisp, MPI_DOUBLE,
                            MPI_COMM_WORLD));
    timer_pop();
    arrived = (size_t)rdisp[np];
  }
  const size_t arriving = arrived / (size_t)rl;
  d->reserve(d->ctx, P->n + arriving);
  struct wire w;
  wire_fields(P, PF_MIGRATE, &w);
  const size_t first = P->n;
#pragma omp parallel
  {
    size_t i0, i1;
    thread_share(arriving, omp_get_thread_num(), omp_get_num_threads(), &i0, &i1);
    wire_unpack_list(&w, NULL, first + i0, i1 - i0, d->rbuf + i0 * (size_t)rl, rl);
  }
  P->n += arriving;
  for (int r = 0; r < np; r++)
    if (scount[r]) d->messages++;
  d->bytes += (double)sdisp[np] * sizeof(double);
  d->migrated += (long)leaving;
  free(scount), free(rcount), free(sdisp), free(rdisp), free(dest), free(fill), free(leave);
  d->seconds += MPI_Wtime() - t0;
  timer_pop();
}

/* The edge cells of direction k on side s (0: the lowest columns or planes of the block, sent
   to the lower neighbour; 1: the highest), in the receiver's halo cell order (nbr.h): x, per
   row (izl, iy) the width columns; z, per plane k and row iy the extended columns (the x halo
   included: the corners). Returns the local cell of edge cell i. */
static size_t edge_cell(const struct nbr *nb, int k, int side, size_t i) {
  const size_t ny = (size_t)nb->ny;
  if (k == 0) {
    const int R = nb->hx;
    const size_t row = i / (size_t)R;
    const int h = (int)(i % (size_t)R);
    const int izl = (int)(row / ny), iy = (int)(row % ny);
    return nbr_owned_cell(nb, side ? nb->nxo - R + h : h, iy, izl);
  }
  const size_t nxe = (size_t)nb->nxo + 2 * (size_t)nb->hx;
  const int ixe = (int)(i % nxe), iy = (int)(i / nxe % ny), p = (int)(i / (nxe * ny));
  return nbr_local_cell(nb, ixe - nb->hx, iy, side ? nb->nzo - nb->hz + p : p);
}

/* Edge cells per side of direction k. */
static size_t edge_cells(const struct nbr *nb, int k) {
  return k == 0 ? (size_t)nb->nzo * nb->ny * nb->hx
                : (size_t)nb->hz * nb->ny * ((size_t)nb->nxo + 2 * (size_t)nb->hx);
}

static void reserve_row(struct dd *d, size_t n) {
  if (n <= d->cap_row) return;
  d->cap_row = n + n / 2;
  d->row = mem_realloc(d->row, d->cap_row, sizeof(size_t), "domain decomposition");
}

/* The send list of one side of direction k: the slots of the edge cells in their order (a
   cell's particles in id order), and the particles of each of those cells (cnt[side]), which
   tell the neighbour where each ghost goes. */
static void edge_slots(struct dd *d, const struct nbr *nb, int k, int side) {
  struct dd_dir *D = &d->dir[k];
  const size_t ne = edge_cells(nb, k);
  if (ne > D->cap_cnt) {
    D->cap_cnt = ne;
    for (int s = 0; s < 4; s++)
      D->cnt[s] = mem_realloc(D->cnt[s], ne ? ne : 1, sizeof(uint32_t), "domain decomposition");
  }
  D->ncnt = ne;
  reserve_row(d, ne + 1);
  uint32_t *cnt = D->cnt[side];
  size_t *off = d->row; /* first entry of each edge cell in the list */
  off[0] = 0;
  for (size_t i = 0; i < ne; i++) {
    const size_t c = edge_cell(nb, k, side, i);
    cnt[i] = (uint32_t)(nb->start[c + 1] - nb->start[c]);
    off[i + 1] = off[i] + cnt[i];
  }
  const size_t n = off[ne];
  if (n > D->cap_send[side]) {
    D->cap_send[side] = n + n / 2;
    D->send[side] =
        mem_realloc(D->send[side], D->cap_send[side], sizeof(size_t), "domain decomposition");
  }
  size_t *out = D->send[side];
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < ne; i++) {
    const size_t c = edge_cell(nb, k, side, i);
    size_t j = off[i];
    for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++) out[j++] = a;
  }
  D->nsend[side] = n;
}

/* Send nf values per entry of direction k's send lists to both its neighbours and receive
   theirs into d->rbuf (the lower side's first). pack_fn fills the records of n slots; each
   thread packs its share. */
typedef void (*pack_list_fn)(const void *arg, const size_t *slots, size_t n, double *buf, int nf);
static void exchange(struct dd *d, int k, int nf, pack_list_fn pack_fn, const void *arg) {
  struct dd_dir *D = &d->dir[k];
  const int tlo = k ? TAG_ZLO : TAG_LEFT, thi = k ? TAG_ZHI : TAG_RIGHT;
  const size_t ns = D->nsend[0] + D->nsend[1], nr = D->nrecv[0] + D->nrecv[1];
  reserve_buf(&d->sbuf, &d->cap_sbuf, ns * (size_t)nf);
  reserve_buf(&d->rbuf, &d->cap_rbuf, nr * (size_t)nf);
  MPI_Request req[4];
  /* my lower halo comes from the lower neighbour's message upwards, and vice versa */
  CHECK_MPI(
      MPI_Irecv(d->rbuf, (int)(D->nrecv[0] * nf), MPI_DOUBLE, D->lo, thi, MPI_COMM_WORLD, &req[0]));
  CHECK_MPI(MPI_Irecv(d->rbuf + D->nrecv[0] * nf, (int)(D->nrecv[1] * nf), MPI_DOUBLE, D->hi, tlo,
                      MPI_COMM_WORLD, &req[1]));
  for (int s = 0, off = 0; s < 2; off += (int)D->nsend[s], s++) {
    const size_t *restrict slots = D->send[s];
    double *restrict buf = d->sbuf + (size_t)off * nf;
    const size_t ns_s = D->nsend[s];
#pragma omp parallel
    {
      size_t i0, i1;
      thread_share(ns_s, omp_get_thread_num(), omp_get_num_threads(), &i0, &i1);
      pack_fn(arg, slots + i0, i1 - i0, buf + i0 * nf, nf);
    }
    /* the lower message goes while the upper one is packed */
    CHECK_MPI(MPI_Isend(buf, (int)(D->nsend[s] * nf), MPI_DOUBLE, s == 0 ? D->lo : D->hi,
                        s == 0 ? tlo : thi, MPI_COMM_WORLD, &req[2 + s]));
  }
  timer_push("halo:wait");
  CHECK_MPI(MPI_Waitall(4, req, MPI_STATUSES_IGNORE));
  timer_pop();
  d->messages += 2;
  d->bytes += (double)ns * nf * sizeof(double);
}

/* A ghost on the wire: its PF_GHOST fields (positions, velocities, mass for the neighbour
   search and kernel sums, id and kind). Density, pressure and the model terms follow in the
   refreshes (dd_refresh); nothing reads a ghost's kernel sum or acceleration, and its gamma
   only the budget's conservative split (PR_BUDGET). */
static void pack_ghost(const void *arg, const size_t *slots, size_t n, double *buf, int nf) {
  wire_pack_list(arg, slots, n, buf, nf);
}

/* Exchange the particles per edge cell of direction k with both neighbours: what the lower
   neighbour sends upwards (its upper edge) is my lower halo. */
static void exchange_counts(struct dd *d, int k) {
  struct dd_dir *D = &d->dir[k];
  const int tlo = k ? TAG_ZLO : TAG_LEFT, thi = k ? TAG_ZHI : TAG_RIGHT, n = (int)D->ncnt;
  MPI_Request req[4];
  CHECK_MPI(MPI_Irecv(D->cnt[2], n, MPI_UINT32_T, D->lo, thi, MPI_COMM_WORLD, &req[0]));
  CHECK_MPI(MPI_Irecv(D->cnt[3], n, MPI_UINT32_T, D->hi, tlo, MPI_COMM_WORLD, &req[1]));
  CHECK_MPI(MPI_Isend(D->cnt[0], n, MPI_UINT32_T, D->lo, tlo, MPI_COMM_WORLD, &req[2]));
  CHECK_MPI(MPI_Isend(D->cnt[1], n, MPI_UINT32_T, D->hi, thi, MPI_COMM_WORLD, &req[3]));
  timer_push("halo:wait");
  CHECK_MPI(MPI_Waitall(4, req, MPI_STATUSES_IGNORE));
  timer_pop();
  d->messages += 2;
  d->bytes += 2.0 * (double)n * sizeof(uint32_t);
}

/* The halo of direction k: the edge cells' counts, the halo cells' ranges from the slot
   `first` on, each received ghost's slot (the messages hold their cells in the order of
   nbr_halo_cells, so the ghosts of a message fill consecutive slots from its first cell's
   start), then the ghosts. Returns the slot after the last ghost. */
static size_t halo_dir(struct dd *d, struct particles *P, struct nbr *nb, int k, size_t first) {
  struct dd_dir *D = &d->dir[k];
  edge_slots(d, nb, k, 0);
  edge_slots(d, nb, k, 1);
  exchange_counts(d, k);
  const uint32_t *const rc[2] = {D->cnt[2], D->cnt[3]};
  D->nrecv[0] = D->nrecv[1] = 0;
  for (size_t i = 0; i < D->ncnt; i++) D->nrecv[0] += rc[0][i], D->nrecv[1] += rc[1][i];
  const size_t ng = D->nrecv[0] + D->nrecv[1];
  d->reserve(d->ctx, first + ng);
  const size_t end = nbr_halo_cells(nb, k, first, rc);
  D->first = first;
  const size_t done = first - P->n; /* ghosts of the directions before */
  if (done + ng > d->cap_ghost) {
    d->cap_ghost = done + ng + (done + ng) / 2;
    d->ghost = mem_realloc(d->ghost, d->cap_ghost, sizeof(size_t), "domain decomposition");
  }
  size_t *ghost = d->ghost + done;
  if (k == 0) { /* x: the halo cells interleave the two sides row by row */
    const int R = nb->hx;
    const size_t rows = (size_t)nb->nzo * nb->ny;
    reserve_row(d, 2 * (rows + 1));
    for (int s = 0; s < 2; s++) {
      size_t *row_off = d->row + (size_t)s * (rows + 1); /* first ghost of each row */
      row_off[0] = s == 0 ? 0 : D->nrecv[0];
      for (size_t row = 0; row < rows; row++) {
        size_t j = 0;
        for (int h = 0; h < R; h++) j += rc[s][row * R + h];
        row_off[row + 1] = row_off[row] + j;
      }
    }
#pragma omp parallel for schedule(static)
    for (size_t row = 0; row < rows; row++)
      for (int s = 0; s < 2; s++) {
        size_t g = d->row[(size_t)s * (rows + 1) + row];
        for (int h = 0; h < R; h++) {
          const size_t c = nb->ncell_own + row * 2 * R + (size_t)(s * R + h);
          for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++) ghost[g++] = a;
        }
      }
  } else { /* z: the lower side's cells, then the upper side's: the slots in message order */
#pragma omp parallel for schedule(static)
    for (size_t g = 0; g < ng; g++) ghost[g] = first + g;
  }
  const int hl = record_len(PF_GHOST);
  struct wire w;
  wire_fields(P, PF_GHOST, &w);
  exchange(d, k, hl, pack_ghost, &w);
#pragma omp parallel
  {
    size_t g0, g1;
    thread_share(ng, omp_get_thread_num(), omp_get_num_threads(), &g0, &g1);
    wire_unpack_list(&w, ghost + g0, 0, g1 - g0, d->rbuf + g0 * (size_t)hl, hl);
  }
  P->n_ghost = end - P->n;
  return end;
}

void dd_halo(struct dd *d, struct particles *P, struct nbr *nb) {
  P->n_ghost = 0;
  if (d->size == 1) return;
  timer_push("halo");
  const double t0 = MPI_Wtime();
  size_t next = P->n;
  for (int k = 0; k < 2; k++)
    if (d->dir[k].width) next = halo_dir(d, P, nb, k, next);
  d->seconds += MPI_Wtime() - t0;
  d->ghosts += (double)P->n_ghost, d->halos++;
  timer_pop();
}

/* The arrays of one refresh: np per-particle arrays, then nw wall arrays (by vertex slot). */
struct fields {
  const struct particles *P;
  int np, nw;
  double *f[32];
};

static void pack_fields(const void *arg, const size_t *restrict slots, size_t n,
                        double *restrict buf, int nf) {
  const struct fields *F = arg;
  for (int k = 0; k < F->np; k++) { /* field by field */
    const double *restrict f = F->f[k];
    for (size_t j = 0; j < n; j++) buf[j * nf + k] = f[slots[j]];
  }
  if (F->nw == 0) return;
  for (size_t j = 0; j < n; j++) {
    const size_t a = slots[j];
    const int vertex = F->P->kind[a] == KIND_VERTEX;
    const size_t slot = vertex ? part_vertex_slot(F->P, F->P->id[a]) : 0;
    for (int k = F->np; k < nf; k++) buf[j * nf + k] = vertex ? F->f[k][slot] : 0.0;
  }
}

/* The allocated arrays of the tables marked for stage. */
static void stage_fields(const struct particles *P, const struct walls *W, int stage,
                         struct fields *F) {
  F->P = P, F->np = F->nw = 0;
  for (int i = 0; i < part_n_fields; i++)
    if ((part_fields[i].refresh & stage) && part_field_ptr(P, &part_fields[i]))
      F->f[F->np++] = part_field_ptr(P, &part_fields[i]);
  for (int i = 0; i < wall_n_fields; i++)
    if ((wall_fields[i].refresh & stage) && wall_field_ptr(W, &wall_fields[i]))
      F->f[F->np + F->nw++] = wall_field_ptr(W, &wall_fields[i]);
}

void dd_refresh(struct dd *d, const struct particles *P, const struct walls *W, int stage) {
  if (d->size == 1) return;
  struct fields F;
  stage_fields(P, W, stage, &F);
  const int nf = F.np + F.nw;
  if (nf == 0) return;
  timer_push("halo:refresh");
  const double t0 = MPI_Wtime();
  for (int k = 0; k < 2; k++) { /* x, then z: the z edges carry the x ghosts just refreshed */
    const struct dd_dir *D = &d->dir[k];
    if (!D->width) continue;
    exchange(d, k, nf, pack_fields, &F);
    const size_t ng = D->nrecv[0] + D->nrecv[1], *ghost = d->ghost + (D->first - P->n);
    const double *restrict rbuf = d->rbuf;
#pragma omp parallel
    {
      size_t g0, g1;
      thread_share(ng, omp_get_thread_num(), omp_get_num_threads(), &g0, &g1);
      for (int j = 0; j < F.np; j++) { /* field by field */
        double *restrict f = F.f[j];
        for (size_t g = g0; g < g1; g++) f[ghost[g]] = rbuf[g * (size_t)nf + j];
      }
      for (size_t g = g0; g < g1 && F.nw; g++) {
        const size_t a = ghost[g];
        if (P->kind[a] != KIND_VERTEX) continue;
        const size_t slot = part_vertex_slot(P, P->id[a]);
        for (int j = F.np; j < nf; j++) F.f[j][slot] = rbuf[g * (size_t)nf + j];
      }
    }
  }
  d->seconds += MPI_Wtime() - t0;
  timer_pop();
}

/* Gather per-pencil records of len doubles (this rank's block, (izl nxo + lc) len each) from
   every rank into all[(ix nplane + iz) len]: the global pencils, x-major. */
static void gather_pencils(const struct dd *d, const double *mine, size_t len, double *all) {
  const size_t npen = (size_t)d->ncol * d->nplane;
  const int nxo = d->fx[d->bx + 1] - d->fx[d->bx], nzo = d->fz[d->bz + 1] - d->fz[d->bz];
  if (d->size == 1) {
    for (int izl = 0; izl < nzo; izl++)
      for (int lc = 0; lc < nxo; lc++)
        memcpy(all + ((size_t)lc * d->nplane + izl) * len, mine + ((size_t)izl * nxo + lc) * len,
               len * sizeof(double));
    return;
  }
  int *cnt = mem_alloc(2 * (size_t)d->size, sizeof(int), "domain decomposition"),
      *dsp = cnt + d->size;
  for (int r = 0, off = 0; r < d->size; r++) {
    const int bx = r % d->px, bz = r / d->px;
    cnt[r] = (d->fx[bx + 1] - d->fx[bx]) * (d->fz[bz + 1] - d->fz[bz]) * (int)len;
    dsp[r] = off, off += cnt[r];
  }
  double *buf = mem_alloc(npen * len, sizeof(double), "domain decomposition");
  CHECK_MPI(
      MPI_Allgatherv(mine, cnt[d->rank], MPI_DOUBLE, buf, cnt, dsp, MPI_DOUBLE, MPI_COMM_WORLD));
  for (int r = 0; r < d->size; r++) {
    const int bx = r % d->px, bz = r / d->px;
    const int x0 = d->fx[bx], nx = d->fx[bx + 1] - x0, z0 = d->fz[bz], nz = d->fz[bz + 1] - z0;
    for (int izl = 0; izl < nz; izl++)
      for (int lc = 0; lc < nx; lc++)
        memcpy(all + ((size_t)(x0 + lc) * d->nplane + (size_t)(z0 + izl)) * len,
               buf + dsp[r] + ((size_t)izl * nx + lc) * len, len * sizeof(double));
  }
  free(buf), free(cnt);
}

void dd_sum(const struct dd *d, const struct nbr *nb, int nv, const double *const *x, double *out) {
  if (nv > 8) die("dd_sum: at most 8 arrays (got %d)", nv);
  const size_t npen = (size_t)d->ncol * d->nplane, nmine = (size_t)nb->nxo * nb->nzo;
  double *mine = mem_alloc(nmine * nv, sizeof(double), "domain decomposition");
#pragma omp parallel for schedule(static)
  for (size_t p = 0; p < nmine; p++) {
    const int lc = (int)(p % (size_t)nb->nxo), izl = (int)(p / (size_t)nb->nxo);
    double s[8] = {0};
    for (int iy = 0; iy < nb->ny; iy++) {
      const size_t c = nbr_owned_cell(nb, lc, iy, izl);
      for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++)
        for (int v = 0; v < nv; v++) s[v] += x[v][a];
    }
    for (int v = 0; v < nv; v++) mine[p * nv + v] = s[v];
  }
  double *all = mem_alloc(npen * nv, sizeof(double), "domain decomposition");
  gather_pencils(d, mine, (size_t)nv, all);
  double *col = mem_alloc(npen, sizeof(double), "domain decomposition");
  for (int v = 0; v < nv; v++) {
    for (size_t p = 0; p < npen; p++) col[p] = all[p * nv + v];
    out[v] = reduce_pairwise(col, npen);
  }
  free(col), free(all), free(mine);
}

/* New cuts of n cells with counts cnt over p parts, each at least minw cells wide: cut where
   the running count passes r times the mean. */
static void cut_balanced(const double *cnt, int n, int p, int minw, int *nf) {
  double total = 0.0;
  for (int c = 0; c < n; c++) total += cnt[c];
  const double mean = total / p;
  nf[0] = 0, nf[p] = n;
  double run = 0.0;
  int c = 0;
  for (int r = 1; r < p; r++) {
    const double target = r * mean;
    const int cut = nf[r - 1] + minw;
    while (c < cut) run += cnt[c++];
    while (c < n - (p - r) * minw && run + 0.5 * cnt[c] < target) run += cnt[c++];
    nf[r] = c;
  }
}

/* The largest block's particles for cuts fx, fz of the pencil counts pc (x-major). */
static double most_loaded(const struct dd *d, const double *pc, const int *fx, const int *fz) {
  double most = 0.0;
  for (int bz = 0; bz < d->pz; bz++)
    for (int bx = 0; bx < d->px; bx++) {
      double n = 0.0;
      for (int ix = fx[bx]; ix < fx[bx + 1]; ix++)
        for (int iz = fz[bz]; iz < fz[bz + 1]; iz++) n += pc[(size_t)ix * d->nplane + iz];
      most = fmax(most, n);
    }
  return most;
}

int dd_balance(struct dd *d, struct nbr *nb, double threshold) {
  if (d->size == 1) return 0;
  /* particles per pencil, gathered (integers: exact in any order) */
  const size_t npen = (size_t)d->ncol * d->nplane, nmine = (size_t)nb->nxo * nb->nzo;
  double *mine = mem_alloc(nmine, sizeof(double), "domain decomposition");
  for (size_t p = 0; p < nmine; p++) {
    const int lc = (int)(p % (size_t)nb->nxo), izl = (int)(p / (size_t)nb->nxo);
    size_t n = 0;
    for (int iy = 0; iy < nb->ny; iy++) {
      const size_t c = nbr_owned_cell(nb, lc, iy, izl);
      n += nb->start[c + 1] - nb->start[c];
    }
    mine[p] = (double)n;
  }
  double *pc = mem_alloc(npen, sizeof(double), "domain decomposition");
  gather_pencils(d, mine, 1, pc);
  double total = 0.0;
  for (size_t p = 0; p < npen; p++) total += pc[p];
  const double mean = total / d->size, most = most_loaded(d, pc, d->fx, d->fz);
  d->imbalance = mean > 0.0 ? most / mean : 1.0;
  int changed = 0;
  if (d->imbalance > 1.0 + threshold) {
    /* the columns' and the planes' counts, each cut direction balanced on its own */
    double *cx = mem_calloc((size_t)d->ncol + d->nplane, sizeof(double), "domain decomposition");
    double *cz = cx + d->ncol;
    for (int ix = 0; ix < d->ncol; ix++)
      for (int iz = 0; iz < d->nplane; iz++)
        cx[ix] += pc[(size_t)ix * d->nplane + iz], cz[iz] += pc[(size_t)ix * d->nplane + iz];
    int *nf = mem_alloc((size_t)(d->px + d->pz + 2), sizeof(int), "domain decomposition");
    int *nz = nf + d->px + 1;
    memcpy(nf, d->fx, (size_t)(d->px + d->pz + 2) * sizeof(int));
    if (d->px > 1) cut_balanced(cx, d->ncol, d->px, 2 * NBR_REACH, nf);
    if (d->pz > 1) cut_balanced(cz, d->nplane, d->pz, 2 * NBR_REACH, nz);
    /* keep the cuts unless the new ones lower the largest load by at least half the excess
       over the mean: no flipping between equivalent cuts */
    const double new_most = most_loaded(d, pc, nf, nz);
    changed = new_most < mean + 0.5 * (most - mean) &&
              memcmp(nf, d->fx, (size_t)(d->px + d->pz + 2) * sizeof(int)) != 0;
    if (changed) memcpy(d->fx, nf, (size_t)(d->px + d->pz + 2) * sizeof(int));
    free(nf), free(cx);
  }
  free(pc), free(mine);
  if (!changed) return 0;
  const struct nbr_range r = dd_range(d);
  nbr_set_range(nb, &r);
  d->rebalances++;
  return 1;
}

size_t dd_check_ids(const struct dd *d, const struct particles *P, size_t n_total, long step) {
  int cnt = (int)P->n, *cnts = NULL, *disp = NULL;
  int64_t *all = NULL;
  if (d->rank == 0) {
    cnts = mem_alloc((size_t)d->size, sizeof(int), "domain decomposition");
    disp = mem_alloc((size_t)d->size, sizeof(int), "domain decomposition");
  }
  CHECK_MPI(MPI_Gather(&cnt, 1, MPI_INT, cnts, 1, MPI_INT, 0, MPI_COMM_WORLD));
  size_t total = 0;
  if (d->rank == 0) {
    for (int r = 0; r < d->size; r++) disp[r] = (int)total, total += (size_t)cnts[r];
    all = mem_alloc((total ? total : 1), sizeof(int64_t), "domain decomposition");
  }
  CHECK_MPI(MPI_Gatherv(P->id, cnt, MPI_INT64_T, all, cnts, disp, MPI_INT64_T, 0, MPI_COMM_WORLD));
  long long bad = -1;
  int dup = 0;
  if (d->rank == 0) {
    unsigned char *seen = mem_calloc(n_total ? n_total : 1, 1, "domain decomposition");
    for (size_t i = 0; i < total && bad < 0; i++) {
      const int64_t id = all[i];
      if (id < 0 || (size_t)id >= n_total || seen[id])
        bad = (long long)id, dup = 1;
      else
        seen[id] = 1;
    }
    for (size_t id = 0; id < n_total && bad < 0; id++)
      if (!seen[id]) bad = (long long)id;
    free(seen), free(all), free(cnts), free(disp);
  }
  CHECK_MPI(MPI_Bcast(&bad, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD));
  CHECK_MPI(MPI_Bcast(&dup, 1, MPI_INT, 0, MPI_COMM_WORLD));
  unsigned long long t = total;
  CHECK_MPI(MPI_Bcast(&t, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD));
  if (bad >= 0)
    die("run.check_ids: after step %ld particle id %lld is %s (%llu particles on %d ranks, "
        "expected %zu)",
        step, bad, dup ? "held twice or out of range" : "lost", t, d->size, n_total);
  return (size_t)t;
}

int dd_id_owner(int64_t id, int size, size_t N) {
  int r = (int)((unsigned long long)id * (unsigned)size / N); /* a guess, then the exact block */
  size_t lo, hi;
  for (dd_id_block(r, size, N, &lo, &hi); (size_t)id >= hi; dd_id_block(++r, size, N, &lo, &hi)) {
  }
  for (; (size_t)id < lo; dd_id_block(--r, size, N, &lo, &hi)) {
  }
  return r;
}

void dd_block_fluid(const struct dd *d, const struct particles *P, int nf, const double *const *f,
                    size_t lo, size_t hi, double *out) {
  const size_t N = P->n_fluid, R = (size_t)nf + 1, nb = hi - lo;
  size_t mine = 0;
  for (size_t a = 0; a < P->n; a++) mine += P->kind[a] == KIND_FLUID;
  /* records: the id (its bits), then the fields */
  int *dest = mem_alloc(mine ? mine : 1, sizeof(int), "particle output");
  double *rec = part_alloc("output_send", (mine ? mine : 1) * R * sizeof(double));
  for (size_t a = 0, k = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    dest[k] = dd_id_owner(P->id[a], d->size, N);
    memcpy(&rec[k * R], &P->id[a], sizeof(double));
    for (int c = 0; c < nf; c++) rec[k * R + 1 + (size_t)c] = f[c][a];
    k++;
  }
  size_t got;
  double *buf = dd_exchange(d->size, dest, mine, rec, R, &got);
  part_free(rec), free(dest);
  if (got != nb)
    die("particle output: %zu fluid particles arrived for the %zu ids %zu..", got, nb, lo);
  for (size_t i = 0; i < nb; i++) { /* by id: the same rows on any number of ranks */
    int64_t id;
    memcpy(&id, &buf[i * R], sizeof id);
    if (id < (int64_t)lo || id >= (int64_t)hi)
      die("particle output: fluid id %lld outside the block %zu..%zu", (long long)id, lo, hi - 1);
    for (int c = 0; c < nf; c++)
      out[(size_t)c * nb + (size_t)(id - (int64_t)lo)] = buf[i * R + 1 + (size_t)c];
  }
  part_free(buf);
}

double *dd_exchange(int size, const int *dest, size_t n, const double *rec, size_t R, size_t *got) {
  int *cnt = mem_calloc(4 * (size_t)size + 2, sizeof(int), "record exchange");
  int *sdisp = cnt + size, *rcnt = sdisp + size + 1, *rdisp = rcnt + size;
  for (size_t a = 0; a < n; a++) cnt[dest[a]] += (int)R;
  for (int r = 0; r < size; r++) sdisp[r + 1] = sdisp[r] + cnt[r];
  double *send = part_alloc("exchange_send", (n ? n : 1) * R * sizeof(double));
  int *fill = mem_calloc((size_t)size, sizeof(int), "record exchange");
  for (size_t a = 0; a < n; a++) { /* by destination, each in the order given */
    memcpy(send + sdisp[dest[a]] + fill[dest[a]], rec + a * R, R * sizeof(double));
    fill[dest[a]] += (int)R;
  }
  CHECK_MPI(MPI_Alltoall(cnt, 1, MPI_INT, rcnt, 1, MPI_INT, MPI_COMM_WORLD));
  rdisp[0] = 0;
  for (int r = 1; r < size; r++) rdisp[r] = rdisp[r - 1] + rcnt[r - 1];
  *got = (size_t)(rdisp[size - 1] + rcnt[size - 1]) / R;
  double *buf = part_alloc("exchange_recv", (*got ? *got : 1) * R * sizeof(double));
  CHECK_MPI(
      MPI_Alltoallv(send, cnt, sdisp, MPI_DOUBLE, buf, rcnt, rdisp, MPI_DOUBLE, MPI_COMM_WORLD));
  part_free(send), free(fill), free(cnt);
  return buf;
}
