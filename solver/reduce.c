/** @file reduce.c @brief Implementation of reduce.h. */
#include "reduce.h"

#include <mpi.h>
#include <stdlib.h>

#include "error.h"

double reduce_pairwise(const double *x, size_t n) {
  if (n <= 8) {
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += x[i];
    return s;
  }
  const size_t m = n / 2;
  return reduce_pairwise(x, m) + reduce_pairwise(x + m, n - m);
}

void reduce_sums(int nv, const double *const *x, size_t n, double *out) {
  if (nv > 8) die("reduce_sums: at most 8 arrays (got %d)", nv);
  const size_t nb = (n + REDUCE_BLOCK - 1) / REDUCE_BLOCK;
  double *blk = malloc((nb ? nb : 1) * (size_t)nv * sizeof *blk);
  if (!blk) die("out of memory in reduce_sums");
#pragma omp parallel for schedule(static)
  for (size_t b = 0; b < nb; b++) {
    const size_t i0 = b * REDUCE_BLOCK, i1 = i0 + REDUCE_BLOCK < n ? i0 + REDUCE_BLOCK : n;
    for (int v = 0; v < nv; v++) {
      double s = 0.0;
      for (size_t i = i0; i < i1; i++) s += x[v][i];
      blk[(size_t)v * nb + b] = s;
    }
  }
  for (int v = 0; v < nv; v++) out[v] = nb ? reduce_pairwise(blk + (size_t)v * nb, nb) : 0.0;
  free(blk);
  reduce_global_sum(out, nv);
}

double reduce_sum(const double *x, size_t n) {
  double s;
  reduce_sums(1, &x, n, &s);
  return s;
}

/* Across ranks: gather to every rank and add in rank order, so the result does not depend on
   the reduction tree MPI chooses. */
void reduce_global_sum(double *v, int nv) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size == 1) return;
  double *all = malloc((size_t)size * nv * sizeof *all);
  if (!all) die("out of memory in reduce_global_sum");
  MPI_Allgather(v, nv, MPI_DOUBLE, all, nv, MPI_DOUBLE, MPI_COMM_WORLD);
  for (int k = 0; k < nv; k++) {
    double s = 0.0;
    for (int r = 0; r < size; r++) s += all[(size_t)r * nv + k];
    v[k] = s;
  }
  free(all);
}

void reduce_global_max(double *v, int nv) {
  MPI_Allreduce(MPI_IN_PLACE, v, nv, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

void reduce_global_min(double *v, int nv) {
  MPI_Allreduce(MPI_IN_PLACE, v, nv, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
}
