/**
 * @file engine.h
 * @brief How the statistics layer (stats.c) reaches an engine: one table of operations per
 *        engine, defined by the engine's own module next to its accumulators and its netCDF
 *        writer.
 *
 * Adding an engine: its module (state struct, init, free, sample, checkpoint state, memory,
 * writer; merging across ranks happens inside its sample, through spar.h), a member for its
 * state in struct stats, its switch in struct stats_config, and one line in `engines` in
 * stats.c (docs/stats-format.md, "How to add a statistic").
 */
#ifndef CHANSPH_ENGINE_H
#define CHANSPH_ENGINE_H

#include <stddef.h>

struct stats_config;
struct stats_snapshot;
struct state_list;

struct stats_engine {
  const char *name; /*!< for messages */
  size_t offset;    /*!< of the engine's state in struct stats */
  /** 1 if the scene asks for this engine (else it is never allocated or called). */
  int (*wanted)(const struct stats_config *cfg);
  void (*init)(void *self, const struct stats_config *cfg);
  void (*free)(void *self);
  /** Accumulate one snapshot (collective across the ranks: merged in a fixed order). */
  void (*sample)(void *self, const struct stats_snapshot *s);
  /** Add the accumulators to a checkpoint's state list (state.h). */
  void (*state)(void *self, struct state_list *L);
  /** Bytes the accumulators hold. */
  size_t (*bytes)(const void *self);
  /** Write the engine's variables and groups into stats.nc (t_reached: the time the run
      reached, NaN if not known); netCDF status, with "message (in call)" in err. */
  int (*write)(const void *self, double t_reached, int ncid, char *err, size_t errlen);
  /** Warnings about what it could not give ("warning: ..." lines), or NULL. */
  int (*warnings)(const void *self, char *buf, size_t len);
};

extern const struct stats_engine euler_engine; /* euler_nc.c */
extern const struct stats_engine corr_engine;  /* corr.c */
extern const struct stats_engine lagr_engine;  /* lagr.c */
extern const struct stats_engine quad_engine;  /* quad.c */

#endif
