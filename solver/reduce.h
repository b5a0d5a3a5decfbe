/**
 * @file reduce.h
 * @brief The building blocks of deterministic reductions: a pairwise sum in a fixed order, and
 *        the global maximum and minimum across ranks (exact in any order). Sums over particles
 *        are dd_sum() (dd.h): per global cell column, then pairwise over the columns, so they do
 *        not depend on the number of threads or ranks.
 */
#ifndef CHANSPH_REDUCE_H
#define CHANSPH_REDUCE_H

#include <stddef.h>

/** @brief Pairwise sum of x[0..n-1] (a fixed recursion, so a fixed order). */
double reduce_pairwise(const double *x, size_t n);

/** @brief Global maximum across ranks (in place). */
void reduce_global_max(double *v, int nv);

/** @brief Global minimum across ranks (in place). */
void reduce_global_min(double *v, int nv);

#endif
