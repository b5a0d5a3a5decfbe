/**
 * @file stats.h
 * @brief The in-process statistics engine: the engines a scene asks for (Eulerian profiles,
 *        two-point correlations and spectra, Lagrangian tracks), fed with the particle state
 *        every stats interval, serialised through the run state and written to stats.nc.
 *
 * Engines that are not requested are never allocated or called, so they cost nothing.
 * The engine sees plain arrays only (struct stats_snapshot), never solver structs.
 */
#ifndef CHANSPH_STATS_H
#define CHANSPH_STATS_H

#include <stddef.h>
#include <stdint.h>

#include "corr.h"
#include "euler.h"
#include "lagr.h"
#include "quad.h"

struct state_list;

/** What the scene asks of the engine. */
struct stats_config {
  int eulerian;            /*!< 1: Eulerian profiles */
  struct euler_config eul; /*!< their bins and windows */
  struct corr_config corr; /*!< two-point correlations (off if corr.n_levels == 0) */
  struct lagr_config lagr; /*!< Lagrangian statistics (off if lagr.n_levels == 0) */
  struct quad_config quad; /*!< quadrant analysis (off if quad.n_levels == 0) */
};

/** The engine. */
struct stats {
  struct stats_config cfg;
  struct euler eu;  /*!< Eulerian profiles (if cfg.eulerian) */
  struct corr co;   /*!< correlations and spectra (if cfg.corr.n_levels) */
  struct lagr la;   /*!< Lagrangian statistics (if cfg.lagr.n_levels) */
  struct quad qu;   /*!< quadrant analysis (if cfg.quad.n_levels) */
  int64_t samples;  /*!< snapshots handed to the engine */
  double t_reached; /*!< simulated time reached, set before a write (NaN: not known); the
                         average_end written is at most this */
};

/** @brief Set up the requested engines. */
void stats_init(struct stats *st, const struct stats_config *cfg);

/**
 * @brief Warnings about what the statistics could not give (Lagrangian lags without samples,
 *        T_L = NaN, no completed release): lines starting "warning: ".
 * @return the number of warnings (buf "" if none)
 */
int stats_warnings(const struct stats *st, char *buf, size_t len);

/** @brief Free them. */
void stats_free(struct stats *st);

/** @brief True if the scene requested any engine (else the solver need not build snapshots). */
int stats_wanted(const struct stats *st);

/** @brief Hand one snapshot to every requested engine. With several ranks (s->comm) a
 *         collective call: every rank calls it with its part of the snapshot, and every rank
 *         ends with the same state (docs/stats-format.md, "Statistics across ranks"). */
void stats_sample(struct stats *st, const struct stats_snapshot *s);

/**
 * @brief Append the complete state of every requested engine to a state list (for the
 *        checkpoints). The arrays grow as windows close: build the list afresh right before
 *        each checkpoint write. Reading fills the same memory through the reserve callbacks.
 */
void stats_state(struct stats *st, struct state_list *L);

/**
 * @brief Define and write the engines' variables and groups into an open netCDF-4 file.
 * @param[in] st engine
 * @param[in] ncid file
 * @param[out] err,errlen message on failure
 * @return 0 or a netCDF status
 */
int stats_nc_write(const struct stats *st, int ncid, char *err, size_t errlen);

/** @brief Bytes held by the requested engines (accumulators, work arrays, tracks). */
size_t stats_memory(const struct stats *st);

/**
 * @brief One line for the log: windows, correlation time, largest standard error of u_mean,
 *        friction velocities and the shear-stress balance.
 * @param[out] buf,len the text (ends with a newline; empty if nothing is gathered yet)
 */
void stats_convergence_line(const struct stats *st, char *buf, size_t len);

/** Is it turbulent? Indicators of a finished Eulerian result (wall units of its u_tau). */
struct stats_turb {
  double uv_peak;        /*!< peak of -u'v'+ (upper half mirrored) */
  double y_peak;         /*!< its y+ */
  double r_uv;           /*!< -u'v' / (u_rms v_rms) averaged over 30 <= y+ <= 100 (about 0.4-0.5
                              in wall turbulence, near 0 for particle noise) */
  double resolved_share; /*!< reynolds_stress / total_stress in the bin nearest y+ = 30 */
  double pair_share;     /*!< pair_stress / total_stress there (the scheme's numerical stress) */
};

/** @brief The indicators of a result (NaN where not available: no budget, no samples). */
void stats_turbulence(const struct euler_config *c, const struct euler_result *r,
                      struct stats_turb *t);

/** A convergence target (scene keys stats.target_*). */
struct stats_target {
  double rel_stderr; /*!< target relative standard error (> 0) */
  int profiles;      /*!< 0: u_mean and the -u'v' peak, 1: u_mean, 2: the -u'v' peak */
  double corr_ratio; /*!< smallest window length / correlation time (0: none) */
  int windows;       /*!< fewest complete windows */
};

/** Where the statistics stand against a target. */
struct stats_progress {
  double rel_u;          /*!< max stderr(u_mean) / max |u_mean| (NaN: not yet) */
  double rel_uv;         /*!< stderr / value of -u'v' at its peak (NaN: not yet) */
  double worst;          /*!< the largest of the chosen ones (NaN: not yet) */
  int windows;           /*!< complete windows */
  double ratio;          /*!< window length / correlation time (NaN: not measured) */
  double windows_needed; /*!< projected complete windows at the target (stderr ~ n^-1/2) */
  double t_reach;        /*!< projected simulated time at which they are complete [s] */
  int met;               /*!< the target is met */
};

/**
 * @brief The standard errors against a target, and the projection to reach it (the batch-means
 *        standard error falls as one over the square root of the number of windows).
 */
void stats_progress(const struct stats *st, const struct stats_target *tg,
                    struct stats_progress *p);

#endif
