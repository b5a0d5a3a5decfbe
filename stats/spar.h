/**
 * @file spar.h
 * @brief The statistics engine across MPI ranks: the column layout of a snapshot and the
 *        gathers that make every rank hold the same per-column partial sums (internal to
 *        stats/).
 *
 * A snapshot holds this rank's particles; each carries its global cell column, and the ranks
 * own contiguous column ranges in rank order. The engines reduce the particles of each column
 * in memory order (the same order on any decomposition), gather the per-column partials to
 * every rank in column order, and combine them in that fixed order: the engine state is
 * replicated and bitwise independent of the number of ranks (docs/stats-format.md).
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
  int ncol;       /*!< global columns */
  int col0, col1; /*!< this rank's columns [col0, col1) */
  int *range;     /*!< [rank][2] column ranges of all ranks */
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

/**
 * @brief Gather variable numbers of records of len doubles to every rank, in rank order.
 * @param[in] local,n this rank's records
 * @param[in,out] buf,cap growable receive buffer (realloc'd; in records)
 * @return the number of records gathered into *buf
 */
size_t spar_gather_var(struct spar *p, const double *local, size_t n, size_t len, double **buf,
                       size_t *cap);

#endif
