/** @file reduce.c @brief Implementation of reduce.h. */
#include "reduce.h"

#include <mpi.h>

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

void reduce_global_max(double *v, int nv) {
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, v, nv, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD));
}

void reduce_global_min(double *v, int nv) {
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, v, nv, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD));
}
