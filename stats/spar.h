/**
 * @file spar.h
 * @brief The statistics engine across MPI ranks: the column layout of a snapshot and the
 *        gathers that make every rank hold the same per-column partial sums (internal to
 *        stats/).
 *
 * A snapshot holds this rank's particles, a block of pencils; each carries its global pencil.
 * The engines reduce the particles of each column in memory order (the same order on any
 * decomposition): where the planes are cut, a column's partial goes up the block column
 * (spar_chain_begin / spar_chain_end: each rank continues the partial of the rank below, plane
 * by plane as one rank would) and the top one's comes back to all of them. Then the block
 * row gathers the per-column partials to every rank in column order, and they are combined in
 * that fixed order: the engine state is replicated and bitwise independent of the number of
 * ranks and of Px x Pz (docs/stats-format.md).
 */
#ifndef CHANSPH_SPAR_H
#define CHANSPH_SPAR_H

#include <mpi.h>
#include <stddef.h>

#include "contract.h"

/** The layout of one snapshot across the ranks. */
struct spar {
  MPI_Comm comm;  /*!< the snapshot's communicator (valid only if size > 1) */
  int size, rank; /*!< ranks (1: serial, no MPI call is made) */
  MPI_Comm xcomm; /*!< the block row: the ranks owning the other columns (valid if xsize > 1) */
  int xsize, xrank;
  MPI_Comm zcomm; /*!< the block column: the ranks owning the other planes of these columns
                       (valid if zsize > 1) */
  int zsize, zrank;
  int ncol;       /*!< global columns */
  int col0, col1; /*!< this rank's columns [col0, col1) */
  int nplane;     /*!< global planes (1: not cut) */
  int *range;     /*!< [xrank][2] column ranges of the block row's ranks */
  int *cnt, *dsp; /*!< scratch counts and displacements of the gathers */
};

/** @brief Read and check the layout of a snapshot (one MPI_Allgather of three ints if several
 *         ranks); aborts with a message if the ranks disagree on ncol or their column ranges
 *         are not contiguous in rank order over 0 .. ncol - 1. */
void spar_open(struct spar *p, const struct stats_snapshot *s);

/** @brief Free the scratch of spar_open. */
void spar_close(struct spar *p);

/** @brief Local column (0 .. col1 - col0 - 1) of particle a; aborts if outside the range. */
int spar_lcol(const struct spar *p, const struct stats_snapshot *s, size_t a);

/** @brief Global cell plane of particle a (0 when the planes are not given). */
int spar_plane(const struct spar *p, const struct stats_snapshot *s, size_t a);

/**
 * @brief Start the per-column partials rec (n doubles, zeroed by the caller) of this rank:
 *        where the planes are cut, the partials of the ranks below in the block column
 *        replace them (received from the rank below). Collective over the block column.
 */
void spar_chain_begin(const struct spar *p, double *rec, size_t n);

/**
 * @brief End the per-column partials rec: passed up the block column, and the top rank's
 *        (the whole columns') given back to every rank of it. Collective over the block column.
 */
void spar_chain_end(const struct spar *p, double *rec, size_t n);

/**
 * @brief Gather variable numbers of records of len doubles to every rank of the snapshot's
 *        communicator, in rank order.
 * @param[in] local,n this rank's records
 * @param[in,out] buf,cap growable receive buffer (realloc'd; in records)
 * @return the number of records gathered into *buf
 */
size_t spar_gather_var(struct spar *p, const double *local, size_t n, size_t len, double **buf,
                       size_t *cap);

/**
 * @brief The same over the block row only (whose rank order is the column order): per-column
 *        partials after spar_chain_end.
 */
size_t spar_gather_row(struct spar *p, const double *local, size_t n, size_t len, double **buf,
                       size_t *cap);

#endif
