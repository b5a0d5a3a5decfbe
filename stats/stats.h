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

struct state_list;

/** What the scene asks of the engine. */
struct stats_config {
  int eulerian;            /*!< 1: Eulerian profiles */
  struct euler_config eul; /*!< their bins and windows */
  struct corr_config corr; /*!< two-point correlations (off if corr.n_levels == 0) */
  struct lagr_config lagr; /*!< Lagrangian statistics (off if lagr.n_levels == 0) */
};

/** The engine. */
struct stats {
  struct stats_config cfg;
  struct euler eu;  /*!< Eulerian profiles (if cfg.eulerian) */
  struct corr co;   /*!< correlations and spectra (if cfg.corr.n_levels) */
  struct lagr la;   /*!< Lagrangian statistics (if cfg.lagr.n_levels) */
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

#endif
