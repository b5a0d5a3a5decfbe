/**
 * @file dd.h
 * @brief Domain decomposition across MPI ranks: Px x Pz blocks of whole cell pencils (a
 *        column along x and a plane along z, every row along y: the walls and the statistics'
 *        y bins are never cut).
 *
 * Rank r = bz Px + bx owns the columns fx[bx] .. fx[bx+1]-1 and the planes fz[bz] .. fz[bz+1]-1
 * of the global grid (nbr.h) and the particles in them; Pz = 1 are the slabs along x. Each step:
 *  1. dd_migrate() sends the particles that left a rank's block to their new owner, one of the
 *     (up to 8) neighbouring blocks (the holes they leave are filled from the end of the
 *     slots, the arrivals appended: nbr_sort orders them whatever order they come in);
 *  2. nbr_sort() orders the owned particles by cell and id;
 *  3. dd_halo() copies the particles of the NBR_REACH columns at each x edge of every block to
 *     the neighbouring block along x (ghosts, with their unshifted coordinates: the periodic
 *     shift is applied by the stencil, as on one rank), then the NBR_REACH planes at each z
 *     edge, with the x ghosts next to them (the corners), to the neighbours along z; cell by
 *     cell in the sender's order, with the particles of each edge cell: each ghost goes
 *     straight to its slot in the halo cells (nbr_halo_cells), with no sort;
 *  4. after each pass that computes a per-particle value the next pass reads at neighbours,
 *     dd_refresh() refreshes the ghosts' copies of the fields the field table (part.h) marks
 *     for that stage, in one exchange per cut direction.
 * Packing and unpacking are threaded; the time in MPI waits is the timer phase "halo:wait",
 * the rest "halo" (building the ghosts), "halo:refresh" and "halo:migrate" (docs/parallel.md).
 * Sums over all particles (dd_sum) are formed per global pencil in the cell order, then added
 * over the pencils in a fixed order, so every result is bitwise the same on any number of
 * ranks, any Px x Pz and any number of threads (docs/parallel.md).
 */
#ifndef CHANSPH_DD_H
#define CHANSPH_DD_H

#include <mpi.h>
#include <stddef.h>
#include <stdint.h>

#include "nbr.h"
#include "part.h"
#include "scene.h"

/** Grows every per-particle array of the simulation to hold n slots. */
typedef void (*dd_reserve_fn)(void *ctx, size_t n);

/** The halo exchange along one cut direction (x or z) in the current step. */
struct dd_dir {
  int width;          /*!< halo columns (planes) per side; 0: the direction is not cut */
  int lo, hi;         /*!< the neighbouring ranks below and above (periodic) */
  size_t nsend[2];    /*!< slots sent below (0) and above (1) */
  size_t cap_send[2]; /*!< their capacity */
  size_t *send[2];    /*!< the slots (owned, or x ghosts in the z direction), in cell order */
  size_t nrecv[2];    /*!< ghosts received from below (0) and above (1) */
  size_t first;       /*!< the slot of this direction's first ghost */
  uint32_t *cnt[4];   /*!< particles per edge cell: sent below, above; received from below,
                           above (nbr_halo_cells' order) */
  size_t ncnt;        /*!< edge cells per side */
  size_t cap_cnt;     /*!< their capacity */
};

/** The decomposition and the halo bookkeeping of the current step. */
struct dd {
  int rank, size;           /*!< this rank, ranks */
  int px, pz;               /*!< blocks along x and z (size = px pz) */
  int bx, bz;               /*!< this rank's block: rank = bz px + bx */
  int ncol, nplane;         /*!< global cell columns along x, planes along z */
  int *fx, *fz;             /*!< first column of each block column (fx[px] = ncol), first plane of
                                 each block row (fz[pz] = nplane) */
  struct dd_dir dir[2];     /*!< the x and z halo exchanges */
  int nnb, nb_rank[8];      /*!< the distinct neighbouring ranks (3 x 3 blocks around, not self) */
  MPI_Comm comm_x;          /*!< the block row (the ranks of this bz, by bx); MPI_COMM_NULL if
                                 px = 1 or pz = 1 (the statistics' contract.h) */
  MPI_Comm comm_z;          /*!< the block column (the ranks of this bx, by bz); MPI_COMM_NULL
                                 if pz = 1 */
  dd_reserve_fn reserve;    /*!< grows the simulation's per-particle arrays */
  void *ctx;                /*!< its argument */
  size_t cap_ghost, *ghost; /*!< the ghost slot of each received record (x, then z) */
  size_t *row, cap_row;     /*!< per-row offsets (scratch) */
  double *sbuf, *rbuf;
  size_t cap_sbuf, cap_rbuf;
  /* cost of the exchanges, for the log */
  double seconds;   /*!< wall time in migration and halo exchanges [s] */
  double bytes;     /*!< bytes sent by this rank */
  long messages;    /*!< messages sent by this rank */
  long migrated;    /*!< particles this rank sent to another owner */
  double ghosts;    /*!< ghosts this rank received, summed over the halo builds */
  long halos;       /*!< halo builds (steps) counted */
  long rebalances;  /*!< re-partitions done */
  double imbalance; /*!< last max / mean particles per rank */
};

/**
 * @brief Choose Px x Pz (the scene's run.ranks, or the factorisation of the ranks of
 *        MPI_COMM_WORLD with the fewest ghosts) and partition the columns and planes evenly
 *        (or as run.partition says, for slabs).
 * @return CHANSPH_OK, or CHANSPH_ERR after a message naming the key when the blocks would be
 *         too thin (every cut direction needs 2 NBR_REACH columns or planes per block: the
 *         halo must come from the neighbouring block only) or run.ranks does not fit
 */
int dd_init(struct dd *d, const struct scene *sc, dd_reserve_fn reserve, void *ctx);

/** @brief This rank's share of the particles with its halo and the room its arrays keep to grow
           (a half), for the memory check before anything is built: 1 on one rank. */
double dd_share(const struct dd *d);

/** @brief This rank's block as a cell range of the grid (nbr_set_range). */
struct nbr_range dd_range(const struct dd *d);

/** @brief Free the bookkeeping. */
void dd_free(struct dd *d);

/** @brief Owner rank of a global column and plane. */
int dd_owner(const struct dd *d, int col, int plane);

/**
 * @brief Keep only the particles of this rank's block (after every rank built the same full
 *        initial state); their order is kept.
 */
void dd_keep_owned(struct dd *d, struct particles *P, const struct nbr *nb);

/**
 * @brief Keep the slots lo .. lo+n-1 (a checkpoint's id block read on this rank) as this rank's
 *        particles and send each to the owner of its pencil (dd_migrate). Collective.
 */
void dd_take_block(struct dd *d, struct particles *P, const struct nbr *nb, size_t lo, size_t n);

/**
 * @brief Drop the ghosts and send every owned particle that is not in this rank's block to
 *        its owner (positions are wrapped first). Collective.
 */
void dd_migrate(struct dd *d, struct particles *P, const struct nbr *nb);

/**
 * @brief Build the ghosts: after nbr_sort(), send the particles of the edge cells and their
 *        count per edge cell to the neighbours, x then z, and put what arrives in halo cell
 *        order after the owned particles (nbr_halo_cells). Collective.
 */
void dd_halo(struct dd *d, struct particles *P, struct nbr *nb);

/**
 * @brief Refresh the ghosts' copies of every allocated per-particle and wall array whose
 *        table entry (part_fields, wall_fields) names this stage (enum part_refresh): one
 *        exchange per cut direction for them all (wall arrays at the ghost vertices, by
 *        vertex slot). Collective.
 */
void dd_refresh(struct dd *d, const struct particles *P, const struct walls *W, int stage);

/**
 * @brief Deterministic global sums of nv per-particle arrays over the owned particles: per
 *        global pencil in the cell order, then added pairwise over the pencils in global
 *        order (x-major); bitwise the same on any number of ranks and threads. Collective.
 * @param[in] nv arrays (at most 8)
 */
void dd_sum(const struct dd *d, const struct nbr *nb, int nv, const double *const *x, double *out);

/**
 * @brief The id block of rank r of size ranks over the ids 0 .. N-1: lo .. hi-1, in rank order
 *        and as even as integer division makes them. The checkpoints (sim_id_block), particles.nc
 *        and the snapshots hold the ids in order, each rank writing its block.
 */
static inline void dd_id_block(int r, int size, size_t N, size_t *lo, size_t *hi) {
  *lo = (size_t)((unsigned long long)r * N / (unsigned)size);
  *hi = (size_t)((unsigned long long)(r + 1) * N / (unsigned)size);
}

/** @brief The rank whose id block (dd_id_block over N ids, size ranks) holds id. */
int dd_id_owner(int64_t id, int size, size_t N);

/**
 * @brief Send nf per-particle arrays of this rank's fluid particles to the ranks whose id blocks
 *        (dd_id_block over n_fluid; fluid ids are 0 .. n_fluid-1) hold them, and place what
 *        arrives by id: out[c (hi - lo) + id - lo] = f[c] of the fluid particle id, for this
 *        rank's block lo .. hi-1. Collective (dd_exchange). Each rank holds its block only: the
 *        particle files are written in parallel, nothing is gathered on one rank.
 * @param[out] out nf (hi - lo) values
 */
void dd_block_fluid(const struct dd *d, const struct particles *P, int nf, const double *const *f,
                    size_t lo, size_t hi, double *out);

/**
 * @brief Debug check: every id 0 .. n_total-1 is owned by exactly one rank (gathered on rank 0).
 *        Collective. Dies with the step and the first missing or duplicated id otherwise.
 * @return the number of owned particles over all ranks (n_total when the check passes)
 */
size_t dd_check_ids(const struct dd *d, const struct particles *P, size_t n_total, long step);

/**
 * @brief Re-partition the columns (and planes) by particle count when the largest rank holds
 *        more than (1 + threshold) times the mean; the caller migrates. Collective.
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
