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

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "kernel.h"
#include "pair.h"
#include "part.h"

/** Cells per kernel support radius 2h: cells of size >= h, a stencil of 5 cells per direction
    (fewer distance checks than 3 cells of size 2h: 125 h^3 instead of 216 h^3 in 3-D). */
enum { NBR_REACH = 2 };

/** Every particle's list starts at a multiple of NBR_ALIGN entries (64 bytes), so vectorised
    sums over it split the same way into lanes on any decomposition (bitwise rank-independent). */
enum { NBR_ALIGN = 16 };

/** A block of the candidate scan (AVX-512, nbr.c): up to 8 consecutive particle slots of one
    range of a cell's stencil and the periodic shifts of their cells. */
struct nbr_block {
  int32_t id[8];   /*!< the slots b .. b + 7 */
  uint32_t live;   /*!< mask of those inside the range */
  uint16_t sx, sz; /*!< shifts in x and z: 0, 1, 2 for -L, 0, L */
  uint32_t pad[6]; /*!< to 64 bytes: the slots load aligned */
};

/**
 * The part of the global cell grid a rank owns: the columns ix0 .. ix0+nxo-1 along x and the
 * planes iz0 .. iz0+nzo-1 along z (every row along y), with hx halo columns on each side along
 * x and hz halo planes on each side along z (0: the rank owns the whole direction, and the
 * periodic wrap is inside its grid).
 */
struct nbr_range {
  int ix0, nxo, hx;
  int iz0, nzo, hz;
};

/**
 * Cell grid and neighbour list. The grid is global (cells of the whole channel, column ix
 * along x, row iy, plane iz); a rank owns a block of it (struct nbr_range). Local cell numbers:
 *  - the owned cells first, (izl * ny + iy) * nxo + lc, lc = ix - ix0, izl = iz - iz0;
 *  - then the x halo: ncell_own + (izl * ny + iy) * 2 hx + h, h < hx for the columns below the
 *    block (column ix0 - hx + h), h >= hx for those above it (ix0 + nxo + h - hx);
 *  - then the z halo, the planes below the block (s = 0, plane iz0 - hz + k) and above it (s =
 *    1, plane iz0 + nzo + k), each over the block's columns and its x halo:
 *    ncell_own + nzo ny 2 hx + ((s hz + k) ny + iy) nxe + ixe, ixe = ix - ix0 + hx < nxe =
 *    nxo + 2 hx.
 * The halo cells are filled in this order (dd_halo: the x halo, then the z halo with its
 * corners taken from the neighbours' x halo). The stencil of a particle visits the same global
 * cells in the same order on any decomposition, and the particles of a cell are ordered by id,
 * so neighbour sums are bitwise independent of the number of ranks.
 */
struct nbr {
  int dim;
  int nx, ny, nz;      /*!< cells per direction (global) */
  int ix0, nxo;        /*!< owned columns: ix0 .. ix0 + nxo - 1 */
  int hx;              /*!< halo columns on each side (0: x not cut, periodic wrap in the grid) */
  int iz0, nzo;        /*!< owned planes: iz0 .. iz0 + nzo - 1 */
  int hz;              /*!< halo planes on each side (0: z not cut) */
  size_t ncell_own;    /*!< owned cells */
  size_t ncell_x;      /*!< owned + x halo cells (the first z halo cell) */
  double lx, ly, lz;   /*!< domain lengths [m] (ly = 2 delta) */
  double cx, cy, cz;   /*!< inverse cell sizes [1/m] */
  double support2;     /*!< (2h)^2 [m^2] */
  size_t ncell;        /*!< owned + halo cells */
  size_t *start;       /*!< particles of cell c are start[c] .. start[c+1]-1 */
  uint32_t *tcount;    /*!< per thread: particles of each owned cell, then the thread's first
                            slot in it (sort scratch, tcount_threads x tcount_cells) */
  int tcount_threads;  /*!< threads tcount was made for */
  size_t tcount_cells; /*!< owned cells it was made for */
  size_t *perm;        /*!< sort scratch */
  int *cell;           /*!< cell of each particle (sort scratch) */
  size_t cap;          /*!< particles the arrays hold */
  /* neighbour list */
  int stride;       /*!< list slots per particle, a multiple of NBR_ALIGN */
  int *count;       /*!< neighbours of each particle (excluding itself) */
  int *nfluid;      /*!< of which fluid particles: they come first in the list, then the vertices */
  int avx512;       /*!< the candidate scan uses AVX-512 */
  double **pairbuf; /*!< per thread: the gathered records of one list (records.h),
                         16 fields of pairbuf_ld values, then PAIRBUF_GEOM fields of pair
                         geometry the force loop keeps for the strain sums (forces.c) */
  int pairbuf_ld;   /*!< values per field of a pair buffer: stride + NBR_ALIGN, room for the
                         fluid and vertex parts of a list each padded to a multiple of 8 */
  int32_t **scratch;         /*!< per thread: a list being built and its squared distances */
  struct nbr_block **blocks; /*!< per thread: the candidate blocks of one cell's stencil
                                  (AVX-512 scan) */
  size_t block_cap;          /*!< blocks each of them holds */
  int scratch_threads;       /*!< threads the scratch lists were made for */
  int scratch_stride;        /*!< stride they were made for */
  int32_t *list; /*!< neighbours of a: list[a*stride .. a*stride+count[a]-1], each part in
                      stencil order (cells, then id) */
};

/** @brief Columns of the global cell grid along x for a scene (what nbr_init uses). */
int nbr_columns(const struct scene *s);

/** @brief Neighbour-list slots per particle a scene starts with (1.5 times the expected
    neighbours within 2h, plus 8, rounded up to the alignment). */
int nbr_stride(const struct scene *s);

/** @brief The whole grid of a scene on one rank (no halo). */
struct nbr_range nbr_whole(const struct scene *s);

/**
 * @brief Set up the cell grid for a domain.
 * @param[out] nb neighbour structure
 * @param[in] s scene
 * @param[in] n particle slots (grown later by nbr_reserve)
 * @param[in] r this rank's block (nbr_whole(s) on one rank)
 */
void nbr_init(struct nbr *nb, const struct scene *s, size_t n, const struct nbr_range *r);

/** @brief Change the owned block (after a re-partition); the particles must be sorted again. */
void nbr_set_range(struct nbr *nb, const struct nbr_range *r);

/** @brief Make the per-particle arrays hold at least n slots. */
void nbr_reserve(struct nbr *nb, size_t n);

/** @brief The cell index of the scaled coordinate v = position / cell size among n cells,
    clamped to 0 .. n-1 before the integer conversion, so that a NaN (to 0) or a huge value of
    a failing run (reported by the health check after the step) cannot overflow it. Plain
    comparisons: fmin and fmax are calls into libm without -ffinite-math-only. */
static inline int nbr_cell_index(double v, int n) {
  return !(v > 0.0) ? 0 : v >= (double)n ? n - 1 : (int)v;
}

/** @brief Global column of the position x (already wrapped into [0, lx)). */
static inline int nbr_column(const struct nbr *nb, double x) {
  return nbr_cell_index(x * nb->cx, nb->nx);
}

/** @brief Global plane of the position z (already wrapped into [0, lz); 0 in 2-D). */
static inline int nbr_plane(const struct nbr *nb, double z) {
  return nb->dim == 3 ? nbr_cell_index(z * nb->cz, nb->nz) : 0;
}

/** @brief Global pencil (column and plane: every cell along y) of a position, x-major:
    ix nz + iz. */
static inline int nbr_pencil(const struct nbr *nb, double x, double z) {
  return nbr_column(nb, x) * nb->nz + nbr_plane(nb, z);
}

/** @brief Wrap x (and z in 3-D) of particle a into the periodic box. */
static inline void nbr_wrap_position(const struct nbr *nb, double *x, double *z) {
  if (*x < 0.0 || *x >= nb->lx) {
    *x -= nb->lx * floor(*x / nb->lx);
    if (*x >= nb->lx) *x -= nb->lx; /* a tiny negative x rounds to lx above */
  }
  if (nb->dim == 3 && (*z < 0.0 || *z >= nb->lz)) {
    *z -= nb->lz * floor(*z / nb->lz);
    if (*z >= nb->lz) *z -= nb->lz;
  }
}

/** @brief Free the grid and the list. */
void nbr_free(struct nbr *nb);

/**
 * @brief Wrap periodic coordinates, then reorder the owned particles (slots 0 .. P->n - 1) by
 *        cell and by id in a cell. Every owned particle must lie in an owned column.
 * @param[in,out] nb grid
 * @param[in,out] P particles
 */
void nbr_sort(struct nbr *nb, struct particles *P);

/**
 * @brief Set the ranges of the halo cells of one direction (dir 0: x, 1: z; the x halo first)
 *        for ghosts that take the slots from `first` on in halo cell order: cnt[0] holds the
 *        particles of each cell of the halo below the block, cnt[1] of the one above it, in
 *        the order of the local cell numbers (nbr above: x, (izl * ny + iy) * hx + h; z,
 *        (k * ny + iy) * nxe + ixe). The neighbours send their edge cells in this order with
 *        their particles in id order (dd_halo), so the ghosts need no sort.
 * @return the slot after the last ghost of this direction
 */
size_t nbr_halo_cells(struct nbr *nb, int dir, size_t first, const uint32_t *const cnt[2]);

/**
 * @brief Local cell of the cell (lc, iy, izl) of the block's extended grid: lc in
 *        [-hx, nxo + hx), izl in [-hz, nzo + hz) (with hx or hz = 0 the direction wraps
 *        inside the grid: any lc, izl); owned, x halo or z halo.
 */
static inline size_t nbr_local_cell(const struct nbr *nb, int lc, int iy, int izl) {
  if (!nb->hx) /* wrap: lc lies within a stencil's reach of the grid (no division) */
    while (lc < 0 || lc >= nb->nx) lc += lc < 0 ? nb->nx : -nb->nx;
  if (!nb->hz)
    while (izl < 0 || izl >= nb->nz) izl += izl < 0 ? nb->nz : -nb->nz;
  if (izl >= 0 && izl < nb->nzo) {
    if (lc >= 0 && lc < nb->nxo) return ((size_t)izl * nb->ny + iy) * nb->nxo + lc;
    const int h = lc < 0 ? lc + nb->hx : nb->hx + lc - nb->nxo;
    return nb->ncell_own + ((size_t)izl * nb->ny + iy) * 2 * nb->hx + h;
  }
  const int sk = izl < 0 ? izl + nb->hz : nb->hz + izl - nb->nzo; /* s hz + k */
  return nb->ncell_x + ((size_t)sk * nb->ny + iy) * (nb->nxo + 2 * nb->hx) + (lc + nb->hx);
}

/** @brief The step of nbr_local_cell(nb, lc, iy, izl) from row iy to iy + 1 (lc and izl as
    there, already wrapped): a column of cells is an arithmetic sequence in every part of the
    block. */
static inline size_t nbr_row_stride(const struct nbr *nb, int lc, int izl) {
  if (izl >= 0 && izl < nb->nzo) return lc >= 0 && lc < nb->nxo ? (size_t)nb->nxo : 2u * nb->hx;
  return (size_t)nb->nxo + 2u * nb->hx;
}

/** @brief Owned cell of local column lc (0 .. nxo-1) and local plane izl (0 .. nzo-1):
    (izl * ny + iy) * nxo + lc. */
static inline size_t nbr_owned_cell(const struct nbr *nb, int lc, int iy, int izl) {
  return ((size_t)izl * nb->ny + iy) * nb->nxo + lc;
}

/**
 * @brief Build the neighbour list of every particle (pairs closer than 2h, self excluded; fluid
 *        neighbours first, then wall vertices) and, in the same pass, the kernel sums
 *        S_a = sum_b m_b w_ab (self included).
 * @param[in,out] nb grid and list; the stride grows if a particle has more neighbours
 * @param[in] P particles, sorted by nbr_sort()
 * @param[in] K kernel
 * @param[out] ksum kernel sum of every particle [kg/m^dim]
 */
void nbr_build(struct nbr *nb, const struct particles *P, const struct kernel *K, double *ksum);

/** @brief Minimum-image separation in a periodic direction of length l (|d| < l/2 after). */
static inline double nbr_wrap(double d, const double l) {
  return pair_wrap(d, l, 0.5 * l);
}

/** Fields of a pair buffer: 16 of gathered records, 4 of pair geometry. */
enum { PAIRBUF_RECORDS = 16, PAIRBUF_GEOM = 4, PAIRBUF_FIELDS = PAIRBUF_RECORDS + PAIRBUF_GEOM };

#endif
