/**
 * @file init.h
 * @brief Initial velocity field of a run: mean profile (rest, laminar, Reichardt),
 *        divergence-free streaks and sinusoidal modes, counter-based random noise, or the
 *        state of an earlier run (thesis Sec. 6.1.1; docs/theory.md, "Start-up").
 */
#ifndef CHANSPH_INIT_H
#define CHANSPH_INIT_H

#include "part.h"
#include "scene.h"

/** The ranks of a run and which of them owns a position (the blocks of the decomposition):
    init.from is read in slices, one per rank, and its particles sent to the ranks that need
    them. */
struct init_owner {
  int (*owner)(const void *ctx, double x, double z); /*!< NULL: rank 0 (one rank) */
  const void *ctx;
  int rank, size;
};

/**
 * @brief Set the velocities (and, from an earlier run of the same resolution, positions and
 *        densities) of the fluid particles of a freshly created lattice (or of this rank's
 *        block of it). Collective over own's ranks with init.from.
 * @param[in] sc scene
 * @param[in,out] P particles as created by part_create or part_create_part (fluid first)
 * @param[in] own the ranks and the owner of a position; NULL: one rank
 * @return CHANSPH_OK, or CHANSPH_ERR after a message naming the file (init.from)
 */
int init_fields(const struct scene *sc, struct particles *P, const struct init_owner *own);

/**
 * @brief The state a run starts from, for the provenance of its statistics (chansph extract
 *        joins a segment only after the state its previous segment ended in): the global
 *        attributes run_id and time of the init.from file path.
 * @param[in] path particles.nc of an earlier run, "" (the scene's initial condition) or NULL
 *            (not known: a resume from a checkpoint that did not record it)
 * @param[out] run_id malloc'd: the file's run_id, "unknown" where it has none or for NULL,
 *             "none" for ""

 * @param[out] time its attribute time [s], or NaN
 */
void init_origin(const char *path, char **run_id, double *time);

/**
 * @brief Memory reading the init.from file needs on one of `ranks` ranks (its slice of the
 *        columns and ids, the records sent and received, the id check), from the length of its
 *        dimension 'particle', before anything is read (a lower bound; 0 without init.from or
 *        if the file cannot be opened: reading it reports that).
 * @param[out] count its particles
 */
double init_source_bytes(const struct scene *sc, int ranks, double *count);

/**
 * @brief The friction velocity of the Reichardt initial profile: (force delta)^(1/2) in force
 *        mode, or the u_tau whose Reichardt profile has the target bulk velocity (flux mode).
 */
double init_reichardt_utau(const struct scene *sc);

/**
 * @brief Uniform random number in [-1, 1) from the Philox-4x64 generator (Random123) with
 *        key (seed) and counter (id, stream): the same for a particle whatever the thread or rank.
 * @param seed key
 * @param id particle id
 * @param stream which number of this particle (0, 1, 2 for u, v, w)
 */
double init_noise(long seed, long long id, int stream);

/** @brief A set of synthetic eddies (Jarrin et al. 2006) in the periodic box extended by sigma
    beyond both walls, binned in cells of width >= sigma. */
struct init_sem {
  size_t n;              /*!< eddies */
  double sigma;          /*!< half-width [m] */
  double lx, ly, lz, y0; /*!< box: [0, lx) x [y0, y0 + ly) x [0, lz) */
  double scale;          /*!< (V_B / (N sigma^3))^(1/2) */
  double *pos, *eps;     /*!< 3 n positions, 3 n signs (+-1) */
  int nx, ny, nz;        /*!< cells */
  size_t *start, *order; /*!< cell start offsets (ncell + 1), eddies by cell */
};

/** @brief The eddy set of a scene: count init.eddies (0: box volume / sigma^3), size
    init.eddy_size delta, positions and signs from init_noise keyed by init.seed and eddy
    index (streams 16-21). Returns CHANSPH_OK (dies when out of memory). */
int init_sem_make(struct init_sem *E, const struct scene *sc);

/** @brief Number of synthetic eddies of a scene: init.eddies, or (0) box volume / sigma^3. */
double init_sem_count(const struct scene *sc);

/** @brief Lower bound of the bytes the initial state needs beyond the particles (the
    synthetic eddies of init.profile = synthetic; 0 otherwise): the scene's memory check. */
double init_bytes(const struct scene *sc);
void init_sem_free(struct init_sem *E);

/** @brief Normalised fluctuation xi (zero mean, unit variance, uncorrelated components in
    expectation) at a point: (V_B / N)^(1/2) sum_k eps_k f_sigma(x - x_k), tent shape
    functions; summed in a fixed order, so independent of threads and ranks. */
void init_sem_xi(const struct init_sem *E, double x, double y, double z, double xi[3]);

/** @brief Velocity of profile = synthetic at a point: u_tau (U+(y+) e_x + a xi) with a the
    Cholesky factor (Lund et al. 1998) of the Lee & Moser Re_tau = 180 Reynolds stresses at
    y+ = min(y, 2 delta - y) u_tau / nu; exactly zero at the walls. */
void init_sem_velocity(const struct init_sem *E, const struct scene *sc, double ut, double x,
                       double y, double z, double vel[3]);

/** @brief Lee & Moser Re_tau = 180 profiles at y+ (linear in y+, the centre-line values
    beyond the table): U+, u'u'+, v'v'+, w'w'+, u'v'+ (solver/dns_lm180.h). */
void init_dns180(double yplus, double out[5]);

#endif
