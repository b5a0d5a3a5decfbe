/**
 * @file sim.h
 * @brief The simulation state and one time step (thesis Eq. 2.159 with the continuity
 *        equation 3.64), plus diagnostics. The step loop itself is in chansph.c.
 */
#ifndef CHANSPH_SIM_H
#define CHANSPH_SIM_H

#include "dd.h"
#include "forcing.h"
#include "nbr.h"
#include "part.h"
#include "scene.h"
#include "sph.h"
#include "state.h"

enum { SIM_GATHER = 16 }; /*!< arrays of this rank's checkpoint id block (sim_state) */

enum { SIM_DT_LIMITS = 5 }; /*!< time-step limits: acoustic, viscous, force, wall, diffusion */

/** Everything a running simulation holds. */
struct sim {
  const struct scene *sc;          /*!< the validated scene */
  struct model M;                  /*!< discretisation constants */
  struct particles P;              /*!< particles */
  struct walls W;                  /*!< wall values on the vertex lattice */
  struct nbr nb;                   /*!< cells and neighbour list */
  struct dd dd;                    /*!< decomposition across MPI ranks and the ghosts */
  size_t cap;                      /*!< slots of the per-particle scratch arrays below */
  struct drive drive;              /*!< driving force state */
  long step;                       /*!< steps taken */
  double t;                        /*!< simulated time [s] */
  double dt;                       /*!< last time step [s] */
  double fx;                       /*!< last streamwise body acceleration [m/s^2] */
  double dt_limits[SIM_DT_LIMITS]; /*!< last limits: acoustic, viscous, force, wall, volume
                                        diffusion [s] */
  double nu_max;                   /*!< largest nu + nu_r of the current state [m^2/s] */
  double *scratch[5];              /*!< per-particle scratch for deterministic sums */
  double *ksum_new;                /*!< kernel sums at the new positions, from the neighbour pass */
  double *wall_ax;          /*!< per particle x-acceleration from the walls (statistics only) */
  double wall_fx[2];        /*!< x-force of the walls y = 0, 2 delta on the fluid, last sampled
                                 force pass (NaN if not sampled) [N, N/m in 2-D] */
  char violation[384];      /*!< a fixed dt broke a stability limit, or the step is zero: what,
                                 where (else empty) */
  int grid;                 /*!< 1 once the blocks and the grid are set up (sim_create) */
  double rss_before;        /*!< peak resident memory before sim_create [bytes] (the log) */
  int distributed;          /*!< 1 after the particles were sized for this rank's part */
  long qcrit_step;          /*!< step whose Q criterion P.qcrit holds (-1: none yet) */
  long reflections;         /*!< wall reflections on this rank since the process began
                                 (sph.wall_collision = reflect) */
  void *gather[SIM_GATHER]; /*!< this rank's id block of the state, for a checkpoint */
  char *init_run_id;        /*!< the state the run started from (init_origin): run_id of the
                                 init.from file, "none" (the scene's initial condition) or
                                 "unknown" (a file without run_id, or a resume from a
                                 checkpoint that did not record it) */
  double init_time;         /*!< that file's time [s], or NaN */
};

/** Global diagnostics of the current state (all fluid particles). */
struct diag {
  double u_bulk;           /*!< volume-weighted mean streamwise velocity [m/s] */
  double kinetic_energy;   /*!< sum of m |v|^2 / 2 [J, or J/m in 2-D] */
  double mass;             /*!< sum of m [kg] */
  double volume;           /*!< sum of m / rho [m^dim] */
  double rho_min, rho_max; /*!< density range [kg/m^3] */
  double max_speed;        /*!< [m/s] */
  double min_gamma;        /*!< [-] */
  long reflections;        /*!< wall reflections since the process began, all ranks */
};

/** @brief Kinematic viscosity of the schedule at time t (fluid.nu_start ramped to fluid.nu;
           the Jimenez-Moin start-up of thesis Sec. 6.1.1) [m^2/s]. */
double sim_viscosity(const struct scene *sc, double t);

/**
 * @brief Create particles from the scene, sort them, compute kernel sums, gamma, wall values
 *        and the model terms.
 * @param[out] S simulation
 * @param[in] sc validated scene (kept by pointer)
 * @return CHANSPH_OK, or CHANSPH_ERR after a message (init.from unreadable or mismatched)
 */
int sim_init(struct sim *S, const struct scene *sc);

/**
 * @brief The blocks of the decomposition and this rank's part of the initial state: the
 *        particles of its block (resume = 0; init.from read in slices and sent to the owners)
 *        or the slots of its checkpoint id block (resume = 1), fields and drive; without
 *        neighbours. sim_init() continues from it, a resume reads a checkpoint into it
 *        (sim_state) and continues with sim_restored().
 * @return CHANSPH_OK, or CHANSPH_ERR after a message (too many ranks, memory, init.from)
 */
int sim_create(struct sim *S, const struct scene *sc, int resume);

/** @brief The memory check's estimate of a scene's large allocations on one rank (lower bounds:
           particles, statistics engines, synthetic eddies, the init.from state) [bytes]. */
double sim_memory_estimate(const struct scene *sc);

/** @brief Free the simulation. */
void sim_free(struct sim *S);

/**
 * @brief Advance one step: forces at t^n, dt (Eq. 2.160-2.164), driving force, symplectic
 *        update of velocity then position (Eq. 2.159), re-sort, density (Eq. 3.64), walls.
 */
void sim_step(struct sim *S);

/**
 * @brief Whether the state after `step` steps is a budget sample of the statistics: one in each
 *        block of stats.budget_every statistics samples (every output.stats_every steps), at a
 *        position within the block drawn from the block's number (Philox: the same on every
 *        rank and thread count, and after a restart); every statistics sample if
 *        budget_every = 1. The budgets and the wall shear stress are gathered on these only.
 */
int sim_budget_sample(const struct scene *sc, long step);

/** Checkpoint id blocks: rank r of size holds the ids [r N / size, (r+1) N / size) of the
    particle datasets (restart/layout.c). */
static inline void sim_id_block(int r, int size, size_t N, size_t *lo, size_t *hi) {
  dd_id_block(r, size, N, lo, hi); /* the blocks of the particle files too */
}

/**
 * @brief After the fields of sim_state() were filled from a checkpoint (into the slots of
 *        this rank's id block, sim_create(S, sc, 1)): split the particles over the ranks (each
 *        rank's id block migrates to the owners of its columns), re-sort them (order by cell,
 *        then id), rebuild the neighbour list and the quantities derived from the stored state
 *        (pressure, sound speed, volumes, wall values), bitwise as the step that produced them.
 * @return 0, or the number of wall values that differ from the stored ones (not bitwise)
 */
size_t sim_restored(struct sim *S);

/** @brief The derived per-particle fields that outputs write (output.q_criterion), computed at
           most once per step: particles.nc and a snapshot of the same step share them. */
void sim_output_fields(struct sim *S);

/** @brief Diagnostics of the current state (deterministic sums). */
void sim_diag(struct sim *S, struct diag *d);

/** @brief True when t_end or max_steps is reached. */
int sim_done(const struct sim *S);

#endif
