/**
 * @file quad.h
 * @brief Quadrant analysis of the Reynolds shear stress in wall-parallel planes (Wallace, Eckelman
 *        & Brodkey 1972; Willmarth & Lu 1972; Kim, Moin & Moser 1987, Fig. 14).
 *
 * At each level (and its mirror 2 delta - y, with v -> -v), the fluid particles within a slab
 * of one dr are split by the signs of their fluctuations u' = u - <u>, v' = v - <v> about the
 * plane average of that instant: Q1 (u' > 0, v' > 0, outward interactions), Q2 (u' < 0,
 * v' > 0, ejections), Q3 (u' < 0, v' < 0, inward interactions), Q4 (u' > 0, v' < 0, sweeps).
 * The engine sums u'v' and the particle count of each quadrant. In wall turbulence the
 * ejections and sweeps carry more than the whole -u'v' (each 60-80% of it near the wall, the
 * interactions negative); for uncorrelated particle noise all four quadrants carry about the
 * same, so the split tells resolved turbulence from noise at a glance.
 *
 * Determinism: per (plane, cell column) partial sums in memory order, gathered in column order
 * (spar.h): the state is bitwise independent of the number of ranks and threads.
 */
#ifndef CHANSPH_QUAD_H
#define CHANSPH_QUAD_H

#include <stddef.h>

struct stats_snapshot;
struct state_list;
struct stats_engine;

enum { QUAD_MAX_LEVELS = 8 };
/** Accumulator slots per level: u'v' sums of Q1..Q4, then the counts of Q1..Q4. */
enum { QS_UV = 0, QS_N = 4, QS_LEN = 8 };

/** Configuration of the quadrant engine. */
struct quad_config {
  int n_levels;                   /*!< levels (0: engine off) */
  double y[QUAD_MAX_LEVELS];      /*!< level heights from the lower wall [m] */
  double y_plus[QUAD_MAX_LEVELS]; /*!< the y+ they were given as */
  double half;                    /*!< half thickness of the slabs [m] */
  double delta;                   /*!< channel half-width [m] (mirror levels) */
  double t_start;                 /*!< start of the averaging [s] */
  double window;                  /*!< averaging window [s] (the Eulerian engine's; 0: none) */
};

/** Per-window batch values per level (checkpoint format 1.12): uv of Q1..Q4, their shares of
    u'v', their shares of the samples. */
enum { QB_UV = 0, QB_SHARE = 4, QB_TIME = 8, QB_LEN = 12 };

/** The engine. */
struct quad {
  struct quad_config cfg;
  double *acc;     /*!< [level][QS_LEN] sums over the planes */
  double *samples; /*!< [level] planes accumulated */
  double *win;     /*!< [level][QS_LEN + 1] sums and planes of the open window */
  double win_end;  /*!< end of the open window [s] */
  double *batch;   /*!< [level][QB_LEN][3] Welford of the closed windows' values */
  double *ent;     /*!< scratch: this rank's per-(plane, column) partial sums */
  double *all;     /*!< scratch: the same gathered from all ranks */
  size_t ent_cap;  /*!< capacity of ent [doubles] */
  size_t all_cap;  /*!< capacity of all [records of rec doubles] */
  size_t rec;      /*!< doubles per column record (planes x QS_LEN) */
};

/** @brief Set up (allocates only if n_levels > 0). */
void quad_init(struct quad *q, const struct quad_config *cfg);

/** @brief Free. */
void quad_free(struct quad *q);

/** @brief Add one snapshot (deterministic; a collective call on s->comm). */
void quad_sample(struct quad *q, const struct stats_snapshot *s);

/** @brief Close the open window if t lies at or past its end (engine.h, close). */
void quad_close(struct quad *q, double t);

/** @brief Expose the sums to a state list (checkpoints). */
void quad_state(struct quad *q, struct state_list *L);

/** @brief Define and write the group `quadrants` of stats.nc (netCDF status, message in err). */
int quad_nc_write(const struct quad *q, int ncid, char *err, size_t errlen);

/**
 * @brief Read the raw state of group `quadrants` of a stats.nc (ncid: the file): configuration
 *        (levels, window length, delta), sums, samples and the window batches (batch_welford).
 *        The open window is not in the file: the engine read holds none.
 * @return 0 (q set up; quad_free it), 1 no group (engine off), 2 no raw batches (a file of an
 *         earlier version), -1 not this layout; err says why
 */
int quad_nc_read(struct quad *q, int ncid, char *err, size_t errlen);

/**
 * @brief Pool the engine b (a later segment of the run) into q: sums and samples added, the
 *        window batches merged pairwise (scal_merge). Nonzero if b was configured otherwise
 *        (why says how); q is then unchanged.
 */
int quad_join(struct quad *q, const struct quad *b, char *why, size_t len);

/** The quadrant engine's table of operations (engine.h; quad.c). */
extern const struct stats_engine quad_engine;

#endif
