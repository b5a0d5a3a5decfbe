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

/* tags: a message going to the left neighbour, one going to the right */
enum { TAG_LEFT = 11, TAG_RIGHT = 12 };

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

static void partition_even(struct dd *d) {
  for (int r = 0; r <= d->size; r++) d->first[r] = (int)((long)r * d->ncol / d->size);
}

int dd_init(struct dd *d, const struct scene *sc, dd_reserve_fn reserve, void *ctx) {
  memset(d, 0, sizeof *d);
  MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &d->size);
  d->ncol = nbr_columns(sc);
  d->halo = d->size > 1 ? NBR_REACH : 0;
  d->reserve = reserve, d->ctx = ctx;
  d->left = (d->rank + d->size - 1) % d->size, d->right = (d->rank + 1) % d->size;
  d->first = mem_alloc((size_t)(d->size + 1), sizeof(int), "domain decomposition");
  if (d->size > 1 && d->ncol < 2 * d->halo * d->size) {
    error_input(
        "%s: key 'domain.lx': lx = %g gives %d cell columns of size h along x; %d MPI "
        "ranks need at least %d (each rank owns %d or more whole columns), so run on at "
        "most %d ranks",
        sc->path[0] ? sc->path : "(scene)", sc->lx, d->ncol, d->size, 2 * d->halo * d->size,
        2 * d->halo, d->ncol / (2 * d->halo));
    return CHANSPH_ERR;
  }
  partition_even(d);
  const struct scene_list *L = &sc->partition;
  if (L->n > 0) { /* columns per rank from the scene */
    int sum = 0, ok = L->n == d->size;
    for (int r = 0; r < L->n; r++) sum += (int)L->v[r], ok = ok && (int)L->v[r] >= 2 * d->halo;
    if (!ok || sum != d->ncol) {
      error_input(
          "%s: key 'run.partition': %d entries summing to %d; this run needs %d entries "
          "(one per rank), each at least %d, summing to the %d cell columns",
          sc->path[0] ? sc->path : "(scene)", L->n, sum, d->size, 2 * d->halo, d->ncol);
      return CHANSPH_ERR;
    }
    for (int r = 0; r < d->size; r++) d->first[r + 1] = d->first[r] + (int)L->v[r];
  }
  return CHANSPH_OK;
}

void dd_free(struct dd *d) {
  free(d->first), free(d->send[0]), free(d->send[1]), free(d->ghost), free(d->row);
  for (int s = 0; s < 4; s++) free(d->cnt[s]);
  free(d->sbuf), free(d->rbuf);
  memset(d, 0, sizeof *d);
}

int dd_owner(const struct dd *d, int col) {
  int lo = 0, hi = d->size - 1; /* the rank r with first[r] <= col < first[r+1] */
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (d->first[mid] <= col)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

static int owned(const struct dd *d, int col) {
  return col >= d->first[d->rank] && col < d->first[d->rank + 1];
}

void dd_keep_owned(struct dd *d, struct particles *P, const struct nbr *nb) {
  size_t k = 0;
  for (size_t a = 0; a < P->n; a++) {
    nbr_wrap_position(nb, &P->x[a], &P->z[a]);
    if (!owned(d, nbr_column(nb, P->x[a]))) continue;
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
  d->seconds = d->bytes = 0.0, d->messages = d->migrated = 0; /* the run's counters start here */
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

/* The exchange of dd_migrate when every leaving particle goes to the left or right neighbour
   (packed by destination rank at sdisp, scount values each): the counts, then the records,
   with the two neighbours only: four messages whatever the number of ranks, where the
   all-to-all costs O(ranks). With 2 ranks the one neighbour is on both sides: all goes in the
   right message. The arrivals land left first in d->rbuf; their order is free (nbr_sort
   orders the particles by cell and id). Returns the values received. */
static size_t migrate_near(struct dd *d, const int *scount, const int *sdisp) {
  const int two = d->left != d->right;
  const int sc[2] = {two ? scount[d->left] : 0, scount[d->right]};
  const int off[2] = {sdisp[d->left], sdisp[d->right]};
  int rc[2] = {0, 0};
  MPI_Request req[4];
  timer_push("halo:wait");
  CHECK_MPI(MPI_Irecv(&rc[0], 1, MPI_INT, d->left, TAG_RIGHT, MPI_COMM_WORLD, &req[0]));
  CHECK_MPI(MPI_Irecv(&rc[1], 1, MPI_INT, d->right, TAG_LEFT, MPI_COMM_WORLD, &req[1]));
  CHECK_MPI(MPI_Isend(&sc[0], 1, MPI_INT, d->left, TAG_LEFT, MPI_COMM_WORLD, &req[2]));
  CHECK_MPI(MPI_Isend(&sc[1], 1, MPI_INT, d->right, TAG_RIGHT, MPI_COMM_WORLD, &req[3]));
  CHECK_MPI(MPI_Waitall(4, req, MPI_STATUSES_IGNORE));
  reserve_buf(&d->rbuf, &d->cap_rbuf, (size_t)rc[0] + (size_t)rc[1]);
  CHECK_MPI(MPI_Irecv(d->rbuf, rc[0], MPI_DOUBLE, d->left, TAG_RIGHT, MPI_COMM_WORLD, &req[0]));
  CHECK_MPI(
      MPI_Irecv(d->rbuf + rc[0], rc[1], MPI_DOUBLE, d->right, TAG_LEFT, MPI_COMM_WORLD, &req[1]));
  CHECK_MPI(
      MPI_Isend(d->sbuf + off[0], sc[0], MPI_DOUBLE, d->left, TAG_LEFT, MPI_COMM_WORLD, &req[2]));
  CHECK_MPI(
      MPI_Isend(d->sbuf + off[1], sc[1], MPI_DOUBLE, d->right, TAG_RIGHT, MPI_COMM_WORLD, &req[3]));
  CHECK_MPI(MPI_Waitall(4, req, MPI_STATUSES_IGNORE));
  timer_pop();
  return (size_t)rc[0] + (size_t)rc[1];
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
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < n0; a++) {
    nbr_wrap_position(nb, &P->x[a], &P->z[a]);
    const int col = nbr_column(nb, P->x[a]);
    dest[a] = owned(d, col) ? -1 : dd_owner(d, col);
  }
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
  /* the usual step: every particle that leaves goes to a neighbouring slab */
  int near = 1;
  for (size_t i = 0; i < leaving && near; i++)
    near = dest[leave[i]] == d->left || dest[leave[i]] == d->right;
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
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < arriving; i++) wire_unpack(&w, P->n + i, d->rbuf + i * (size_t)rl);
  P->n += arriving;
  for (int r = 0; r < np; r++)
    if (scount[r]) d->messages++;
  d->bytes += (double)sdisp[np] * sizeof(double);
  d->migrated += (long)leaving;
  free(scount), free(rcount), free(sdisp), free(rdisp), free(dest), free(fill), free(leave);
  d->seconds += MPI_Wtime() - t0;
  timer_pop();
}

/* The send list of one side: the owned slots of the local columns [c0, c0 + halo) in cell order
   (rows iz * ny + iy, then columns; a cell's particles in id order), and the particles of each
   of those cells (cnt[row * halo + h]), which tell the neighbour where each ghost goes. */
static void edge_slots(struct dd *d, const struct nbr *nb, int side, int c0) {
  const int R = d->halo;
  const size_t rows = (size_t)nb->ny * nb->nz;
  if (rows * (size_t)R > d->cap_cnt) {
    d->cap_cnt = rows * (size_t)R;
    for (int s = 0; s < 4; s++)
      d->cnt[s] = mem_realloc(d->cnt[s], d->cap_cnt, sizeof(uint32_t), "domain decomposition");
    d->row = mem_realloc(d->row, 2 * (rows + 1), sizeof(size_t), "domain decomposition");
  }
  uint32_t *cnt = d->cnt[side];
  size_t *row_off = d->row; /* first entry of each row in the list */
  row_off[0] = 0;
  for (size_t row = 0; row < rows; row++) {
    size_t k = 0;
    for (int h = 0; h < R; h++) {
      const size_t c = row * (size_t)nb->nxo + (size_t)(c0 + h);
      cnt[row * R + h] = (uint32_t)(nb->start[c + 1] - nb->start[c]);
      k += cnt[row * R + h];
    }
    row_off[row + 1] = row_off[row] + k;
  }
  const size_t n = row_off[rows];
  if (n > d->cap_send[side]) {
    d->cap_send[side] = n + n / 2;
    d->send[side] =
        mem_realloc(d->send[side], d->cap_send[side], sizeof(size_t), "domain decomposition");
  }
  size_t *out = d->send[side];
#pragma omp parallel for schedule(static)
  for (size_t row = 0; row < rows; row++) {
    size_t k = row_off[row];
    for (int h = 0; h < R; h++) {
      const size_t c = row * (size_t)nb->nxo + (size_t)(c0 + h);
      for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++) out[k++] = a;
    }
  }
  d->nsend[side] = n;
}

/* Send nf values per entry of the send lists to both neighbours and receive theirs into
   d->rbuf (left halo first). pack_fn fills a record for owned slot a; the threads pack. */
static void exchange(struct dd *d, int nf, void (*pack_fn)(const void *, size_t, double *),
                     const void *arg) {
  const size_t ns = d->nsend[0] + d->nsend[1], nr = d->nrecv[0] + d->nrecv[1];
  reserve_buf(&d->sbuf, &d->cap_sbuf, ns * (size_t)nf);
  reserve_buf(&d->rbuf, &d->cap_rbuf, nr * (size_t)nf);
  MPI_Request req[4];
  /* my left halo comes from the left neighbour's message to the right, and vice versa */
  CHECK_MPI(MPI_Irecv(d->rbuf, (int)(d->nrecv[0] * nf), MPI_DOUBLE, d->left, TAG_RIGHT,
                      MPI_COMM_WORLD, &req[0]));
  CHECK_MPI(MPI_Irecv(d->rbuf + d->nrecv[0] * nf, (int)(d->nrecv[1] * nf), MPI_DOUBLE, d->right,
                      TAG_LEFT, MPI_COMM_WORLD, &req[1]));
  for (int s = 0, off = 0; s < 2; off += (int)d->nsend[s], s++) {
    const size_t *restrict slots = d->send[s];
    double *restrict buf = d->sbuf + (size_t)off * nf;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < d->nsend[s]; i++) pack_fn(arg, slots[i], buf + i * nf);
    /* the left message goes while the right one is packed */
    CHECK_MPI(MPI_Isend(buf, (int)(d->nsend[s] * nf), MPI_DOUBLE, s == 0 ? d->left : d->right,
                        s == 0 ? TAG_LEFT : TAG_RIGHT, MPI_COMM_WORLD, &req[2 + s]));
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
static void pack_ghost(const void *arg, size_t a, double *r) {
  wire_pack(arg, a, r);
}

/* Exchange the particles per edge cell with both neighbours: what the left neighbour sends
   right (its right edge) is my left halo. */
static void exchange_counts(struct dd *d, size_t n) {
  MPI_Request req[4];
  CHECK_MPI(
      MPI_Irecv(d->cnt[2], (int)n, MPI_UINT32_T, d->left, TAG_RIGHT, MPI_COMM_WORLD, &req[0]));
  CHECK_MPI(
      MPI_Irecv(d->cnt[3], (int)n, MPI_UINT32_T, d->right, TAG_LEFT, MPI_COMM_WORLD, &req[1]));
  CHECK_MPI(MPI_Isend(d->cnt[0], (int)n, MPI_UINT32_T, d->left, TAG_LEFT, MPI_COMM_WORLD, &req[2]));
  CHECK_MPI(
      MPI_Isend(d->cnt[1], (int)n, MPI_UINT32_T, d->right, TAG_RIGHT, MPI_COMM_WORLD, &req[3]));
  timer_push("halo:wait");
  CHECK_MPI(MPI_Waitall(4, req, MPI_STATUSES_IGNORE));
  timer_pop();
  d->messages += 2;
  d->bytes += 2.0 * (double)n * sizeof(uint32_t);
}

void dd_halo(struct dd *d, struct particles *P, struct nbr *nb) {
  P->n_ghost = 0;
  if (d->size == 1) return;
  timer_push("halo");
  const double t0 = MPI_Wtime();
  const int R = d->halo;
  const size_t rows = (size_t)nb->ny * nb->nz, nc = rows * (size_t)R;
  edge_slots(d, nb, 0, 0);
  edge_slots(d, nb, 1, nb->nxo - R);
  exchange_counts(d, nc);
  /* the ghosts go in halo cell order: the halo cells' ranges from the counts, then each
     received ghost's slot (the messages hold their cells in the order of nbr_halo_cells) */
  const uint32_t *const rc[2] = {d->cnt[2], d->cnt[3]};
  d->nrecv[0] = d->nrecv[1] = 0;
  for (size_t i = 0; i < nc; i++) d->nrecv[0] += rc[0][i], d->nrecv[1] += rc[1][i];
  const size_t ng = d->nrecv[0] + d->nrecv[1];
  d->reserve(d->ctx, P->n + ng);
  nbr_halo_cells(nb, P->n, rc);
  if (ng > d->cap_ghost) {
    d->cap_ghost = ng + ng / 2;
    d->ghost = mem_realloc(d->ghost, d->cap_ghost, sizeof(size_t), "domain decomposition");
  }
  for (int s = 0; s < 2; s++) {
    size_t *row_off = d->row + (size_t)s * (rows + 1); /* first ghost of each row */
    row_off[0] = s == 0 ? 0 : d->nrecv[0];
    for (size_t row = 0; row < rows; row++) {
      size_t k = 0;
      for (int h = 0; h < R; h++) k += rc[s][row * R + h];
      row_off[row + 1] = row_off[row] + k;
    }
  }
#pragma omp parallel for schedule(static)
  for (size_t row = 0; row < rows; row++)
    for (int s = 0; s < 2; s++) {
      size_t g = d->row[(size_t)s * (rows + 1) + row];
      for (int h = 0; h < R; h++) {
        const size_t c = nb->ncell_own + row * 2 * R + (size_t)(s * R + h);
        for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++) d->ghost[g++] = a;
      }
    }
  const int hl = record_len(PF_GHOST);
  struct wire w;
  wire_fields(P, PF_GHOST, &w);
  exchange(d, hl, pack_ghost, &w);
#pragma omp parallel for schedule(static)
  for (size_t g = 0; g < ng; g++) wire_unpack(&w, d->ghost[g], d->rbuf + g * (size_t)hl);
  P->n_ghost = ng;
  d->seconds += MPI_Wtime() - t0;
  timer_pop();
}

/* The arrays of one refresh: np per-particle arrays, then nw wall arrays (by vertex slot). */
struct fields {
  const struct particles *P;
  int np, nw;
  double *f[32];
};

static void pack_fields(const void *arg, size_t a, double *r) {
  const struct fields *F = arg;
  for (int k = 0; k < F->np; k++) r[k] = F->f[k][a];
  const int vertex = F->P->kind[a] == KIND_VERTEX;
  const size_t slot = vertex ? part_vertex_slot(F->P, F->P->id[a]) : 0;
  for (int k = F->np; k < F->np + F->nw; k++) r[k] = vertex ? F->f[k][slot] : 0.0;
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
  exchange(d, nf, pack_fields, &F);
  const size_t ng = d->nrecv[0] + d->nrecv[1];
#pragma omp parallel for schedule(static)
  for (size_t g = 0; g < ng; g++) {
    const size_t a = d->ghost[g];
    const double *r = d->rbuf + g * (size_t)nf;
    for (int k = 0; k < F.np; k++) F.f[k][a] = r[k];
    if (F.nw == 0 || P->kind[a] != KIND_VERTEX) continue;
    const size_t slot = part_vertex_slot(P, P->id[a]);
    for (int k = F.np; k < nf; k++) F.f[k][slot] = r[k];
  }
  d->seconds += MPI_Wtime() - t0;
  timer_pop();
}

void dd_sum(const struct dd *d, const struct nbr *nb, int nv, const double *const *x, double *out) {
  if (nv > 8) die("dd_sum: at most 8 arrays (got %d)", nv);
  const int nxo = nb->nxo, ncol = d->ncol;
  double *all = mem_alloc((size_t)ncol * nv, sizeof(double), "domain decomposition");
  double *mine = all + (size_t)nb->ix0 * nv; /* this rank's columns, [column][v] */
#pragma omp parallel for schedule(static)
  for (int lc = 0; lc < nxo; lc++) {
    double s[8] = {0};
    for (int iz = 0; iz < nb->nz; iz++)
      for (int iy = 0; iy < nb->ny; iy++) {
        const size_t c = nbr_owned_cell(nb, lc, iy, iz);
        for (size_t a = nb->start[c]; a < nb->start[c + 1]; a++)
          for (int v = 0; v < nv; v++) s[v] += x[v][a];
      }
    for (int v = 0; v < nv; v++) mine[(size_t)lc * nv + v] = s[v];
  }
  if (d->size > 1) {
    int *cnt = mem_alloc((size_t)d->size, sizeof(int), "domain decomposition");
    int *dsp = mem_alloc((size_t)d->size, sizeof(int), "domain decomposition");
    for (int r = 0; r < d->size; r++)
      cnt[r] = (d->first[r + 1] - d->first[r]) * nv, dsp[r] = d->first[r] * nv;
    CHECK_MPI(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, all, cnt, dsp, MPI_DOUBLE,
                             MPI_COMM_WORLD));
    free(cnt), free(dsp);
  }
  double *col = mem_alloc((size_t)ncol, sizeof(double), "domain decomposition");
  for (int v = 0; v < nv; v++) {
    for (int c = 0; c < ncol; c++) col[c] = all[(size_t)c * nv + v];
    out[v] = reduce_pairwise(col, (size_t)ncol);
  }
  free(col), free(all);
}

int dd_balance(struct dd *d, struct nbr *nb, double threshold) {
  if (d->size == 1) return 0;
  /* particles per column, gathered in column order */
  const int ncol = d->ncol;
  double *cnt = mem_alloc((size_t)ncol, sizeof(double), "domain decomposition");
  memset(cnt, 0, (size_t)ncol * sizeof(double));
  for (int lc = 0; lc < nb->nxo; lc++)
    for (int iz = 0; iz < nb->nz; iz++)
      for (int iy = 0; iy < nb->ny; iy++) {
        const size_t c = nbr_owned_cell(nb, lc, iy, iz);
        cnt[nb->ix0 + lc] += (double)(nb->start[c + 1] - nb->start[c]);
      }
  CHECK_MPI(
      MPI_Allreduce(MPI_IN_PLACE, cnt, ncol, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD)); /* integers */
  double total = 0.0, most = 0.0;
  for (int c = 0; c < ncol; c++) total += cnt[c];
  for (int r = 0; r < d->size; r++) {
    double n = 0.0;
    for (int c = d->first[r]; c < d->first[r + 1]; c++) n += cnt[c];
    most = fmax(most, n);
  }
  const double mean = total / d->size;
  d->imbalance = mean > 0.0 ? most / mean : 1.0;
  if (d->imbalance <= 1.0 + threshold) {
    free(cnt);
    return 0;
  }
  /* cut where the running count passes r * mean, keeping 2 halo columns per rank */
  const int minw = 2 * d->halo;
  int *nf = mem_alloc((size_t)(d->size + 1), sizeof(int), "domain decomposition");
  nf[0] = 0, nf[d->size] = ncol;
  double run = 0.0;
  int c = 0;
  for (int r = 1; r < d->size; r++) {
    const double target = r * mean;
    int cut = nf[r - 1] + minw;
    while (c < cut) run += cnt[c++];
    while (c < ncol - (d->size - r) * minw && run + 0.5 * cnt[c] < target) run += cnt[c++];
    nf[r] = c;
  }
  double new_most = 0.0; /* keep the cuts unless the new ones lower the largest load */
  for (int r = 0; r < d->size; r++) {
    double n = 0.0;
    for (int k = nf[r]; k < nf[r + 1]; k++) n += cnt[k];
    new_most = fmax(new_most, n);
  }
  /* ... by at least half the excess over the mean: no flipping between equivalent cuts */
  const int changed = new_most < mean + 0.5 * (most - mean) &&
                      memcmp(nf, d->first, (size_t)(d->size + 1) * sizeof(int)) != 0;
  if (changed) memcpy(d->first, nf, (size_t)(d->size + 1) * sizeof(int));
  free(nf), free(cnt);
  if (!changed) return 0;
  nbr_set_range(nb, d->first[d->rank], d->first[d->rank + 1] - d->first[d->rank], d->halo);
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

void dd_gather_fluid(const struct dd *d, const struct particles *P, int nf, const double *const *f,
                     double *out) {
  const size_t n = P->n_fluid, rec = (size_t)nf + 1;
  size_t mine = 0;
  for (size_t a = 0; a < P->n; a++) mine += P->kind[a] == KIND_FLUID;
  double *buf = mem_alloc((mine ? mine : 1) * rec, sizeof(double), "domain decomposition");
  for (size_t a = 0, k = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    buf[k * rec] = (double)P->id[a]; /* ids below 2^53 are exact */
    for (int c = 0; c < nf; c++) buf[k * rec + 1 + c] = f[c][a];
    k++;
  }
  int cnt = (int)(mine * rec), *cnts = NULL, *disp = NULL;
  double *all = NULL;
  if (d->rank == 0) {
    cnts = mem_alloc((size_t)d->size, sizeof(int), "domain decomposition");
    disp = mem_alloc((size_t)d->size, sizeof(int), "domain decomposition");
    all = mem_alloc((n ? n : 1) * rec, sizeof(double), "domain decomposition");
  }
  CHECK_MPI(MPI_Gather(&cnt, 1, MPI_INT, cnts, 1, MPI_INT, 0, MPI_COMM_WORLD));
  if (d->rank == 0)
    for (int r = 0, off = 0; r < d->size; off += cnts[r], r++) disp[r] = off;
  CHECK_MPI(MPI_Gatherv(buf, cnt, MPI_DOUBLE, all, cnts, disp, MPI_DOUBLE, 0, MPI_COMM_WORLD));
  if (d->rank == 0)
    for (size_t k = 0; k < n; k++) {
      const size_t id = (size_t)all[k * rec]; /* fluid ids are 0 .. n_fluid-1 */
      for (int c = 0; c < nf; c++) out[(size_t)c * n + id] = all[k * rec + 1 + c];
    }
  free(buf), free(cnts), free(disp), free(all);
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
