/**
 * @file dd.h
 * @brief Domain decomposition across MPI ranks: slabs of whole cell columns along x.
 *
 * Rank r owns the cell columns first[r] .. first[r+1]-1 of the global grid (nbr.h) and the
 * particles in them. Each step:
 *  1. dd_migrate() sends the particles that left a rank's columns to their new owner (the holes
 *     they leave are filled from the end of the slots, the arrivals appended: nbr_sort orders
 *     them whatever order they come in);
 *  2. nbr_sort() orders the owned particles by cell and id;
 *  3. dd_halo() copies the particles of the NBR_REACH columns at each edge of every slab to the
 *     neighbouring rank (ghosts, with their unshifted coordinates: the periodic shift is applied
 *     by the stencil, as on one rank), cell by cell in the sender's order, with the particles
 *     of each edge cell: each ghost goes straight to its slot in the halo cells
 *     (nbr_halo_cells), with no sort;
 *  4. after each pass that computes a per-particle value the next pass reads at neighbours,
 *     dd_refresh() refreshes the ghosts' copies of the fields the field table (part.h) marks
 *     for that stage, in one exchange.
 * Packing and unpacking are threaded; the time in MPI waits is the timer phase "halo:wait",
 * the rest "halo" (building the ghosts), "halo:refresh" and "halo:migrate" (docs/parallel.md).
 * Sums over all particles (dd_sum) are formed per global column in the cell order, then
 * added over the columns in a fixed order, so every result is bitwise the same on any number
 * of ranks and threads (docs/parallel.md).
 */
#ifndef CHANSPH_DD_H
#define CHANSPH_DD_H

#include <stddef.h>
#include <stdint.h>

#include "nbr.h"
#include "part.h"
#include "scene.h"

/** Grows every per-particle array of the simulation to hold n slots. */
typedef void (*dd_reserve_fn)(void *ctx, size_t n);

/** The decomposition and the halo bookkeeping of the current step. */
struct dd {
  int rank, size;        /*!< this rank, ranks */
  int ncol;              /*!< global cell columns along x */
  int halo;              /*!< halo columns per side (0 on one rank) */
  int *first;            /*!< first column of each rank; first[size] = ncol */
  int left, right;       /*!< neighbouring ranks (periodic) */
  dd_reserve_fn reserve; /*!< grows the simulation's per-particle arrays */
  void *ctx;             /*!< its argument */
  /* halo of the current step: owned slots sent to the left (0) and right (1) neighbour, and
     the ghost slot of each received particle (left halo first) */
  size_t nsend[2], cap_send[2], *send[2];
  size_t nrecv[2], cap_ghost, *ghost;
  /* particles per edge cell (row * halo + h): sent left (0), right (1), received from the left
     (2), from the right (3); and per-row offsets into the lists (scratch) */
  uint32_t *cnt[4];
  size_t cap_cnt, *row;
  double *sbuf, *rbuf;
  size_t cap_sbuf, cap_rbuf;
  /* cost of the exchanges, for the log */
  double seconds;   /*!< wall time in migration and halo exchanges [s] */
  double bytes;     /*!< bytes sent by this rank */
  long messages;    /*!< messages sent by this rank */
  long migrated;    /*!< particles this rank sent to another owner */
  long rebalances;  /*!< re-partitions done */
  double imbalance; /*!< last max / mean particles per rank */
};

/**
 * @brief Partition the columns of the scene's grid evenly over the ranks of MPI_COMM_WORLD.
 * @return CHANSPH_OK, or CHANSPH_ERR after a message when the slabs would be too thin (every
 *         rank needs 2 NBR_REACH columns: the halo must come from the neighbouring rank only)
 */
int dd_init(struct dd *d, const struct scene *sc, dd_reserve_fn reserve, void *ctx);

/** @brief Free the bookkeeping. */
void dd_free(struct dd *d);

/** @brief Owner rank of a global column. */
int dd_owner(const struct dd *d, int col);

/**
 * @brief Keep only the particles of this rank's columns (after every rank built the same full
 *        initial state); their order is kept.
 */
void dd_keep_owned(struct dd *d, struct particles *P, const struct nbr *nb);

/**
 * @brief Keep the slots lo .. lo+n-1 (a checkpoint's id block read on this rank) as this rank's
 *        particles and send each to the owner of its column (dd_migrate). Collective.
 */
void dd_take_block(struct dd *d, struct particles *P, const struct nbr *nb, size_t lo, size_t n);

/**
 * @brief Drop the ghosts and send every owned particle that is not in this rank's columns to
 *        its owner (positions are wrapped first). Collective.
 */
void dd_migrate(struct dd *d, struct particles *P, const struct nbr *nb);

/**
 * @brief Build the ghosts: after nbr_sort(), send the particles of the edge columns and their
 *        count per edge cell to the neighbours, and put what arrives in halo cell order after
 *        the owned particles (nbr_halo_cells). Collective.
 */
void dd_halo(struct dd *d, struct particles *P, struct nbr *nb);

/**
 * @brief Refresh the ghosts' copies of every allocated per-particle and wall array whose
 *        table entry (part_fields, wall_fields) names this stage (enum part_refresh): one
 *        exchange for them all (wall arrays at the ghost vertices, by vertex slot). Collective.
 */
void dd_refresh(struct dd *d, const struct particles *P, const struct walls *W, int stage);

/**
 * @brief Deterministic global sums of nv per-particle arrays over the owned particles: per
 *        global column in the cell order, then added pairwise over the columns; bitwise the
 *        same on any number of ranks and threads. Collective.
 * @param[in] nv arrays (at most 8)
 */
void dd_sum(const struct dd *d, const struct nbr *nb, int nv, const double *const *x, double *out);

/**
 * @brief Gather nf per-particle arrays of the fluid particles of all ranks on rank 0, by id:
 *        out[k * n_fluid + id] = f[k] of the fluid particle id. Collective.
 * @param[out] out rank 0: nf * n_fluid values (other ranks: unused, may be NULL)
 */
void dd_gather_fluid(const struct dd *d, const struct particles *P, int nf, const double *const *f,
                     double *out);

/**
 * @brief Debug check: every id 0 .. n_total-1 is owned by exactly one rank (gathered on rank 0).
 *        Collective. Dies with the step and the first missing or duplicated id otherwise.
 * @return the number of owned particles over all ranks (n_total when the check passes)
 */
size_t dd_check_ids(const struct dd *d, const struct particles *P, size_t n_total, long step);

/**
 * @brief Re-partition the columns by particle count when the largest rank holds more than
 *        (1 + threshold) times the mean, then migrate. Collective.
 * @return 1 if the partition changed
 */
int dd_balance(struct dd *d, struct nbr *nb, double threshold);

/**
 * @brief Send record a (R doubles at rec + a R) of this rank's n records to rank dest[a] and
 *        receive what every rank sends here: by source rank, each rank's records in the order
 *        it gave them. Collective over MPI_COMM_WORLD (the checkpoint's id blocks use it).
 * @param[out] got the number of records received
 * @return the received records (free with part_free)
 */
double *dd_exchange(int size, const int *dest, size_t n, const double *rec, size_t R, size_t *got);

#endif
