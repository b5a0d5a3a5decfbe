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

void spar_open(struct spar *p, const struct stats_snapshot *s) {
  memset(p, 0, sizeof *p);
  p->size = 1;
  int init = 0, fin = 0;
  if (!comm_serial(s->comm)) MPI_Initialized(&init), MPI_Finalized(&fin);
  if (init && !fin) { /* a communicator before MPI_Init can only be a serial one */
    p->comm = s->comm;
    MPI_Comm_size(p->comm, &p->size);
    MPI_Comm_rank(p->comm, &p->rank);
  }
  p->range = mem_alloc(2 * (size_t)p->size, sizeof(int), "statistics engine");
  p->ncol = s->ncol, p->col0 = s->col0, p->col1 = s->col1;
  if (!s->col && s->ncol == 0) { /* layout left unset: serial, everything in column 0 */
    if (p->size > 1) fail("several ranks need the column layout (ncol, col0, col1)");
    p->ncol = 1, p->col0 = 0, p->col1 = 1;
  }
  if (p->ncol < 1 || p->col0 < 0 || p->col1 < p->col0 || p->col1 > p->ncol)
    fail("column range outside 0 .. ncol");
  if (!s->col && s->n > 0 && p->col1 == p->col0)
    fail("particles without a column on a rank without columns");
  if (p->size == 1) {
    if (p->col0 != 0 || p->col1 != p->ncol) fail("one rank must own all columns");
    p->range[0] = p->col0, p->range[1] = p->col1;
    return;
  }
  p->cnt = mem_alloc(3 * (size_t)p->size, sizeof(int), "statistics engine");
  p->dsp = p->cnt + p->size;
  const int mine[3] = {p->col0, p->col1, p->ncol};
  int *all = p->cnt; /* [rank][3], scratch until the first gather */
  CHECK_MPI(MPI_Allgather(mine, 3, MPI_INT, all, 3, MPI_INT, p->comm));
  for (int r = 0; r < p->size; r++) {
    p->range[2 * r] = all[3 * r], p->range[2 * r + 1] = all[3 * r + 1];
    if (all[3 * r + 2] != p->ncol) fail("the ranks disagree on the number of columns");
  }
  for (int r = 0; r < p->size; r++)
    if (p->range[2 * r] != (r ? p->range[2 * r - 1] : 0) ||
        (r == p->size - 1 && p->range[2 * r + 1] != p->ncol))
      fail("the column ranges of the ranks are not contiguous in rank order over 0 .. ncol");
}

void spar_close(struct spar *p) {
  free(p->range), free(p->cnt);
  memset(p, 0, sizeof *p);
}

int spar_lcol(const struct spar *p, const struct stats_snapshot *s, size_t a) {
  if (!s->col) return 0; /* every particle in column col0 */
  const int c = s->col[a];
  if (c < p->col0 || c >= p->col1) fail("particle outside the rank's column range");
  return c - p->col0;
}

size_t spar_gather_var(struct spar *p, const double *local, size_t n, size_t len, double **buf,
                       size_t *cap) {
  size_t total = n;
  if (p->size > 1) {
    int mine = (int)(n * len);
    if (n * len > (size_t)2147483647) fail("gather larger than 2^31 doubles");
    CHECK_MPI(MPI_Allgather(&mine, 1, MPI_INT, p->cnt, 1, MPI_INT, p->comm));
    size_t off = 0;
    for (int r = 0; r < p->size; r++) {
      if (off > (size_t)2147483647) fail("gather larger than 2^31 doubles");
      p->dsp[r] = (int)off, off += (size_t)p->cnt[r];
    }
    total = off / len;
  }
  if (total > *cap) {
    *buf = mem_realloc(*buf, total * len, sizeof(double), "statistics engine");
    *cap = total;
  }
  if (p->size == 1) {
    if (n) memcpy(*buf, local, n * len * sizeof(double));
  } else {
    CHECK_MPI(MPI_Allgatherv(local, p->cnt[p->rank], MPI_DOUBLE, *buf, p->cnt, p->dsp, MPI_DOUBLE,
                             p->comm));
  }
  return total;
}
