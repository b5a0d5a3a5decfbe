/**
 * @file reduce.h
 * @brief Every global sum, min and max goes through here, so results do not depend on the
 *        number of threads (fixed blocks summed in a fixed order) and, later, of ranks.
 */
#ifndef CHANSPH_REDUCE_H
#define CHANSPH_REDUCE_H

#include <stddef.h>

/** Particles per block of the deterministic sums; independent of the thread count. */
enum { REDUCE_BLOCK = 2048 };

/**
 * @brief Deterministic sum of x[0..n-1]: blocks of REDUCE_BLOCK summed serially (in parallel
 *        across blocks), then the block sums added pairwise; then summed across MPI ranks.
 * @param[in] x values
 * @param[in] n count
 * @return the global sum, bitwise independent of OMP_NUM_THREADS
 */
double reduce_sum(const double *x, size_t n);

/**
 * @brief Deterministic sums of several arrays at once (same scheme as reduce_sum()).
 * @param[in] nv number of arrays (at most 8)
 * @param[in] x the arrays
 * @param[in] n length of each
 * @param[out] out the nv global sums
 */
void reduce_sums(int nv, const double *const *x, size_t n, double *out);

/** @brief Pairwise sum of x[0..n-1] (a fixed recursion, so a fixed order). */
double reduce_pairwise(const double *x, size_t n);

/** @brief Global sum across ranks of already-local values (in place, fixed rank order). */
void reduce_global_sum(double *v, int nv);

/** @brief Global maximum across ranks (in place). */
void reduce_global_max(double *v, int nv);

/** @brief Global minimum across ranks (in place). */
void reduce_global_min(double *v, int nv);

#endif
