/**
 * @file output.h
 * @brief The run directory: log.txt, scene.used.ini, stats.nc (profiles and time series,
 *        rewritten atomically) and particles.nc (final particle state, sorted by id).
 */
#ifndef CHANSPH_OUTPUT_H
#define CHANSPH_OUTPUT_H

#include <stdio.h>

#include "health.h"
#include "series.h"
#include "sim.h"
#include "state.h"
#include "stats.h"

/** Output state of a run. */
struct output {
  char dir[2048];    /*!< run directory */
  FILE *log;         /*!< DIR/log.txt */
  char *scene_text;  /*!< resolved scene */
  struct stats st;   /*!< the statistics engine */
  struct series ts;  /*!< time series */
  double next_write; /*!< simulated time of the next stats.nc rewrite [s] */
  double window_len; /*!< length of the Eulerian averaging windows in use [s] (checkpointed:
                          fixed once averaging has begun; NaN while a checkpoint is read) */
  double wall0;      /*!< wall clock at the start of the loop [s] */
  double t0;         /*!< simulated time at the start of the loop [s] */
  double last_wall;  /*!< wall clock of the last log line [s] */
  long last_step;    /*!< step of the last log line */
  long reflections;  /*!< wall reflections the log has reported (sph.wall_collision) */
  long step0;        /*!< step at the start of the loop (0, or where a resume started) */
  long max_steps;    /*!< the command line's --max-steps: steps of this process (0: none) */
  int *col;          /*!< global cell column of each owned particle (statistics snapshots) */
  size_t col_cap;    /*!< entries col holds */
  long rebalances;   /*!< re-partitions already reported in the log */
  char run_id[64];   /*!< identity of the run (DIR/run_id), attribute of stats.nc, particles.nc */
  char *history;     /*!< DIR/history: every run and resume command, newest first (rank 0) */
  char *resumed_without; /*!< malloc'd: the statistics datasets a checkpoint the run resumed
                              from lacked (an earlier format) and the time of that resume
                              ("" if none): what they accumulate starts there; checkpointed */
  size_t target_nwin;    /*!< complete windows when the convergence target was last checked */
  int converged;         /*!< the convergence target (stats.target_stderr) is met: end the run
                              (checkpointed: a resumed run that met it stays finished) */
};

/**
 * @brief Create (or check) the run directory before anything is computed. Refuses a directory
 *        holding results of an earlier run unless overwrite is set, so nothing is lost.
 * @return CHANSPH_OK or CHANSPH_ERR with a message
 */
int output_open(struct output *o, const char *dir, const struct scene *sc, int overwrite);

/** @brief The scene as the statistics engines see it (stats/contract.h): the channel's values,
 *         derived ones resolved, and the engines' own keys with their definitions. */
void output_stats_scene(const struct scene *sc, struct stats_scene *view);

/**
 * @brief Reopen the directory of a run being resumed: log.txt is appended to, scene.used.ini
 *        rewritten with the (possibly changed) scene, accumulators sized from the scene; their
 *        contents come from the checkpoint through output_state().
 * @return CHANSPH_OK or CHANSPH_ERR with a message
 */
int output_reopen(struct output *o, const char *dir, const struct scene *sc);

/**
 * @brief Append the output state to a list: every statistics engine's accumulators
 *        (stats_state), the time series (sized on reading) and the time of the next stats.nc
 *        rewrite. Rebuild the list before each checkpoint: growing arrays move.
 */
void output_state(struct output *o, struct state_list *L);

/**
 * @brief The length of the Eulerian averaging windows: of the running engine (sc NULL; NaN
 *        without Eulerian statistics), or the one the scene sc would give.
 */
double output_stats_window(const struct output *o, const struct scene *sc);

/**
 * @brief Use this length for the Eulerian averaging windows from now on (a resume keeps the
 *        length the windows already averaged have, whatever time.t_end says now).
 * @param[in] len window length [s]
 */
void output_set_window(struct output *o, double len);

/**
 * @brief Memory the statistics engines of a scene need on a rank, before they exist (lower
 *        bounds, for the scene's memory check).
 * @param[out] eulerian bytes of the Eulerian per-column partials (output.n_bins, domain.lx)
 *             and of its per-window records (with the Reynolds-stress budgets) for the run
 * @param[out] corr bytes of the correlation grids and spectra (correlations.*)
 * @param[out] lagr bytes of the Lagrangian records (lagrangian.*)
 */
void output_stats_bytes(const struct scene *sc, double *eulerian, double *corr, double *lagr);

/** @brief Log a line to stdout and log.txt (printf-style). */
void output_log(struct output *o, const char *fmt, ...);

/** @brief Start the clocks of a resumed run (no record: the series holds the state's row). */
void output_resume(struct output *o, struct sim *S);

/**
 * @brief The run stops before its end (checkpointed): rewrite stats.nc with what was gathered,
 *        log why and the timing report.
 * @return CHANSPH_OK or CHANSPH_ERR
 */
int output_stop(struct output *o, struct sim *S, const char *why);

/** @brief Record the initial state and start the clocks. */
void output_begin(struct output *o, struct sim *S);

/**
 * @brief Does output_step() take anything from the state of this step (a statistics sample, a
 *        time-series row, a stats.nc rewrite)? The caller checks such a state first.
 */
int output_takes_state(const struct output *o, const struct sim *S);

/**
 * @brief Statistics sample of the current state when one is due (output.stats_every), and the
 *        convergence check when an averaging window has closed (sets o->converged when
 *        stats.target_stderr is met). Call after the health check of the state, before
 *        output_step.
 */
void output_sample(struct output *o, struct sim *S);

/**
 * @brief After each step and output_sample: record the series, log, rewrite stats.nc when
 *        due (the statistics sample is output_sample's).
 * @return CHANSPH_OK, or CHANSPH_ERR after a message when stats.nc cannot be written (the
 *         previous stats.nc and the checkpoints are kept)
 */
int output_step(struct output *o, struct sim *S);

/**
 * @brief Final log line, stats.nc and particles.nc, phase timing report.
 * @return CHANSPH_OK or CHANSPH_ERR (a file could not be written; message printed)
 */
int output_finish(struct output *o, struct sim *S);

/** @brief Report a failed health check to stdout, stderr and log.txt; keeps earlier files. */
void output_fail(struct output *o, struct sim *S, const struct health_report *rep);

/** @brief Release the output state. */
void output_close(struct output *o);

#endif
