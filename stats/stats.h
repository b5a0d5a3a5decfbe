/**
 * @file stats.h
 * @brief The in-process statistics engine: the engines a scene asks for (the list is
 *        stats_engines, engines.c), fed with the particle state every stats interval,
 *        serialised through the run state and written to stats.nc (stats_nc.h).
 *
 * Engines that are not requested are never allocated or called, so they cost nothing.
 * The engine sees plain arrays only (struct stats_snapshot, contract.h), never solver structs;
 * this layer names no engine: it loops over the table of operations (engine.h).
 */
#ifndef CHANSPH_STATS_H
#define CHANSPH_STATS_H

#include <stddef.h>
#include <stdint.h>

#include "contract.h"
#include "engine.h"

struct state_list;

/** The engine: the states of the engines the scene asked for. */
struct stats {
  void *self[STATS_MAX_ENGINES]; /*!< state of engine k of stats_engines (engine.h), or NULL:
                                      not asked for (never allocated or called) */
  int64_t samples;               /*!< snapshots handed to the engine */
  double t_reached;              /*!< simulated time reached, set before a write (NaN: not
                                      known); the average_end written is at most this */
};

/**
 * @brief Set up the engines the scene asks for, each configured from the scene by its own
 *        init_scene (engine.h).
 * @param[out] st the engine
 * @param[in] sc the scene as the engines see it; NULL: no engine (add them with stats_add)
 */
void stats_init(struct stats *st, const struct stats_scene *sc);

/**
 * @brief Set up one engine from its own configuration (tests, tools), replacing it if it runs.
 * @param[in,out] st the engine (after stats_init)
 * @param[in] e one of stats_engines
 * @param[in] cfg its configuration (struct euler_config for euler_engine, ...)
 */
void stats_add(struct stats *st, const struct stats_engine *e, const void *cfg);

/** @brief The state of engine e (struct euler * for euler_engine, ...), or NULL if it does not
 *         run. */
void *stats_find(const struct stats *st, const struct stats_engine *e);

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

/** @brief Close every engine's open averaging window if t, the time the run has reached, lies
 *         at or past its end (no later snapshot can fall in it): before stats.nc is written,
 *         so that a run ending at a window boundary (t_end) has that window complete. The
 *         records are those the next snapshot would have closed; the same on every rank. */
void stats_close(struct stats *st, double t);

/**
 * @brief Append the complete state of every requested engine to a state list (for the
 *        checkpoints). The arrays grow as windows close: build the list afresh right before
 *        each checkpoint write. Reading fills the same memory through the reserve callbacks.
 */
void stats_state(struct stats *st, struct state_list *L);

/** @brief Bytes held by the requested engines (accumulators, work arrays, tracks). */
size_t stats_memory(const struct stats *st);

/**
 * @brief The engines' lines for the log (windows, correlation time, standard errors, friction
 *        velocities, the shear-stress balance ...: each engine's log operation).
 * @param[out] buf,len the text (each line ends with a newline; empty if nothing is gathered)
 */
void stats_convergence_line(const struct stats *st, char *buf, size_t len);

#endif
