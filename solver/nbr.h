/**
 * @file nbr.h
 * @brief Neighbour search: cell lists of size >= h (NBR_REACH cells per support radius), particles
 * reordered by cell and by id within a cell, and a per-particle neighbour list built in the density
 * pass.
 *
 * x (and z in 3-D) are periodic; y is bounded by the walls. Every loop over neighbours is a
 * gather: particle a reads its neighbours and writes only to itself, so results are bitwise
 * independent of the number of threads.
 */
#ifndef CHANSPH_NBR_H
#define CHANSPH_NBR_H

#include <stddef.h>
#include <stdint.h>

#include "kernel.h"
#include "part.h"

/** Cells per kernel support radius 2h: cells of size >= h, a stencil of 5 cells per direction
    (fewer distance checks than 3 cells of size 2h: 125 h^3 instead of 216 h^3 in 3-D). */
enum { NBR_REACH = 2 };

/** Cell grid and neighbour list. */
struct nbr {
  int dim;
  int nx, ny, nz;    /*!< cells per direction */
  double lx, ly, lz; /*!< domain lengths [m] (ly = 2 delta) */
  double cx, cy, cz; /*!< inverse cell sizes [1/m] */
  double support2;   /*!< (2h)^2 [m^2] */
  size_t ncell;
  size_t *start; /*!< particles of cell c are start[c] .. start[c+1]-1 */
  size_t *pos;   /*!< fill position of each cell (sort scratch) */
  size_t *perm;  /*!< sort scratch */
  int *cell;     /*!< cell of each particle (sort scratch) */
  size_t cap;    /*!< particles the arrays hold */
  /* neighbour list */
  int stride;    /*!< list slots per particle */
  int *count;    /*!< neighbours of each particle (excluding itself) */
  int32_t *list; /*!< neighbours of a: list[a*stride .. a*stride+count[a]-1] */
};

/**
 * @brief Set up the cell grid for a domain.
 * @param[out] nb neighbour structure
 * @param[in] s scene
 * @param[in] n particles
 */
void nbr_init(struct nbr *nb, const struct scene *s, size_t n);

/** @brief Free the grid and the list. */
void nbr_free(struct nbr *nb);

/**
 * @brief Wrap periodic coordinates, then reorder the particles by cell and by id in a cell.
 * @param[in,out] nb grid
 * @param[in,out] P particles
 */
void nbr_sort(struct nbr *nb, struct particles *P);

/**
 * @brief Build the neighbour list of every particle (pairs closer than 2h, self excluded) and,
 *        in the same pass, the kernel sums S_a = sum_b m_b w_ab (self included).
 * @param[in,out] nb grid and list; the stride grows if a particle has more neighbours
 * @param[in] P particles, sorted by nbr_sort()
 * @param[in] K kernel
 * @param[out] ksum kernel sum of every particle [kg/m^dim]
 */
void nbr_build(struct nbr *nb, const struct particles *P, const struct kernel *K, double *ksum);

/** @brief Minimum-image separation in a periodic direction of length l (|d| < l/2 after). */
static inline double nbr_wrap(double d, const double l) {
  if (d > 0.5 * l)
    d -= l;
  else if (d < -0.5 * l)
    d += l;
  return d;
}

#endif
