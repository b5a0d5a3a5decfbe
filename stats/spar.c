/** @file spar.c @brief Implementation of spar.h. */
#include "spar.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"

static void fail(const char *msg) {
  die("statistics snapshot: %s", msg);
}

/* A zero-initialised MPI_Comm (designated initialisers that leave .comm out) is serial too. */
static int comm_serial(MPI_Comm c) {
  MPI_Comm zero;
  memset(&zero, 0, sizeof zero);
  return c == MPI_COMM_NULL || !memcmp(&c, &zero, sizeof c);
}

/* Size and rank of c (1 and 0 if serial or MPI is not running). */
static int comm_info(MPI_Comm c, int *rank) {
  int init = 0, fin = 0, size = 1;
  *rank = 0;
  if (!comm_serial(c)) MPI_Initialized(&init), MPI_Finalized(&fin);
  if (init && !fin) { /* a communicator before MPI_Init can only be a serial one */
    MPI_Comm_size(c, &size);
    MPI_Comm_rank(c, rank);
  }
  return size;
}

void spar_open(struct spar *p, const struct stats_snapshot *s) {
  memset(p, 0, sizeof *p);
  p->comm = s->comm, p->size = comm_info(s->comm, &p->rank);
  p->zcomm = s->comm_z, p->zsize = comm_info(s->comm_z, &p->zrank);
  if (comm_serial(s->comm_x))
    p->xcomm = p->zsize > 1 ? MPI_COMM_NULL : s->comm, p->xsize = p->zsize > 1 ? 1 : p->size,
    p->xrank = p->zsize > 1 ? 0 : p->rank;
  else
    p->xcomm = s->comm_x, p->xsize = comm_info(s->comm_x, &p->xrank);
  p->ncol = s->ncol, p->col0 = s->col0, p->col1 = s->col1;
  p->nplane = s->nplane > 1 ? s->nplane : 1;
  if (!s->col && s->ncol == 0) { /* layout left unset: serial, everything in column 0 */
    if (p->size > 1) fail("several ranks need the column layout (ncol, col0, col1)");
    p->ncol = 1, p->col0 = 0, p->col1 = 1;
  }
  if (p->ncol < 1 || p->col0 < 0 || p->col1 < p->col0 || p->col1 > p->ncol)
    fail("column range outside 0 .. ncol");
  if (p->nplane > 1 && (s->plane0 < 0 || s->plane1 <= s->plane0 || s->plane1 > p->nplane))
    fail("plane range outside 0 .. nplane");
  if (p->zsize > 1 && p->nplane == 1) fail("a block column without planes");
  if (!s->col && s->n > 0 && p->col1 == p->col0)
    fail("particles without a column on a rank without columns");
  p->range = mem_alloc(2 * (size_t)p->size, sizeof(int), "statistics engine");
  p->cnt = mem_alloc(3 * (size_t)p->size, sizeof(int), "statistics engine");
  p->dsp = p->cnt + p->size;
  if (p->xsize == 1) {
    if (p->col0 != 0 || p->col1 != p->ncol) fail("one rank of a block row must own all columns");
    p->range[0] = p->col0, p->range[1] = p->col1;
    return;
  }
  const int mine[3] = {p->col0, p->col1, p->ncol};
  int *all = p->cnt; /* [xrank][3], scratch until the first gather */
  CHECK_MPI(MPI_Allgather(mine, 3, MPI_INT, all, 3, MPI_INT, p->xcomm));
  for (int r = 0; r < p->xsize; r++) {
    p->range[2 * r] = all[3 * r], p->range[2 * r + 1] = all[3 * r + 1];
    if (all[3 * r + 2] != p->ncol) fail("the ranks disagree on the number of columns");
  }
  for (int r = 0; r < p->xsize; r++)
    if (p->range[2 * r] != (r ? p->range[2 * r - 1] : 0) ||
        (r == p->xsize - 1 && p->range[2 * r + 1] != p->ncol))
      fail("the column ranges of the ranks are not contiguous in rank order over 0 .. ncol");
}

void spar_close(struct spar *p) {
  free(p->range), free(p->cnt);
  memset(p, 0, sizeof *p);
}

int spar_lcol(const struct spar *p, const struct stats_snapshot *s, size_t a) {
  if (!s->col) return 0; /* every particle in column col0 */
  const int c = s->col[a] / p->nplane;
  if (c < p->col0 || c >= p->col1) fail("particle outside the rank's column range");
  return c - p->col0;
}

int spar_plane(const struct spar *p, const struct stats_snapshot *s, size_t a) {
  return s->col ? s->col[a] % p->nplane : 0;
}

/* Messages of at most 2^30 doubles. */
static int chunk(size_t n, size_t off) {
  const size_t m = n - off, cap = (size_t)1 << 30;
  return (int)(m < cap ? m : cap);
}

void spar_chain_begin(const struct spar *p, double *rec, size_t n) {
  if (p->zsize <= 1 || p->zrank == 0) return;
  for (size_t off = 0; off < n; off += (size_t)chunk(n, off))
    CHECK_MPI(MPI_Recv(rec + off, chunk(n, off), MPI_DOUBLE, p->zrank - 1, 21, p->zcomm,
                       MPI_STATUS_IGNORE));
}

void spar_chain_end(const struct spar *p, double *rec, size_t n) {
  if (p->zsize <= 1) return;
  for (size_t off = 0; off < n; off += (size_t)chunk(n, off)) {
    if (p->zrank < p->zsize - 1)
      CHECK_MPI(MPI_Send(rec + off, chunk(n, off), MPI_DOUBLE, p->zrank + 1, 21, p->zcomm));
    CHECK_MPI(MPI_Bcast(rec + off, chunk(n, off), MPI_DOUBLE, p->zsize - 1, p->zcomm));
  }
}

/* Gather over comm (size ranks, this one `rank`). */
static size_t gather(struct spar *p, MPI_Comm comm, int size, int rank, const double *local,
                     size_t n, size_t len, double **buf, size_t *cap) {
  size_t total = n;
  if (size > 1) {
    int mine = (int)(n * len);
    if (n * len > (size_t)2147483647) fail("gather larger than 2^31 doubles");
    CHECK_MPI(MPI_Allgather(&mine, 1, MPI_INT, p->cnt, 1, MPI_INT, comm));
    size_t off = 0;
    for (int r = 0; r < size; r++) {
      if (off > (size_t)2147483647) fail("gather larger than 2^31 doubles");
      p->dsp[r] = (int)off, off += (size_t)p->cnt[r];
    }
    total = off / len;
  }
  if (total > *cap) {
    *buf = mem_realloc(*buf, total * len, sizeof(double), "statistics engine");
    *cap = total;
  }
  if (size == 1) {
    if (n) memcpy(*buf, local, n * len * sizeof(double));
  } else {
    CHECK_MPI(
        MPI_Allgatherv(local, p->cnt[rank], MPI_DOUBLE, *buf, p->cnt, p->dsp, MPI_DOUBLE, comm));
  }
  return total;
}

size_t spar_gather_var(struct spar *p, const double *local, size_t n, size_t len, double **buf,
                       size_t *cap) {
  return gather(p, p->comm, p->size, p->rank, local, n, len, buf, cap);
}

size_t spar_gather_row(struct spar *p, const double *local, size_t n, size_t len, double **buf,
                       size_t *cap) {
  return gather(p, p->xcomm, p->xsize, p->xrank, local, n, len, buf, cap);
}
