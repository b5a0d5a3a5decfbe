/**
 * @file engine.h
 * @brief How the statistics layer (stats.c, stats_nc.c) reaches an engine: one table of
 *        operations per engine, defined by the engine's own module next to its accumulators
 *        and its netCDF writer, and the one list of the engines (engines.c).
 *
 * Adding an engine: its module (state struct and configuration, its scene keys, the table
 * below: built from the scene, free, sample, checkpoint state, memory, writer; merging across ranks
 * happens inside its sample, through spar.h), its table declared in its header, and one line in
 * `stats_engines` in engines.c (docs/stats-format.md, "How to add a statistic").
 */
#ifndef CHANSPH_ENGINE_H
#define CHANSPH_ENGINE_H

#include <stddef.h>

struct scene_key_def;
struct stats_scene;
struct stats_snapshot;
struct state_list;

/** The operations of one engine; self is its state (size bytes, zeroed, owned by stats.c). */
struct stats_engine {
  const char *name; /*!< for messages */
  size_t size;      /*!< bytes of the engine's state (its struct) */
  /** The engine's own scene keys, declared beside its code (contract.h): the scene
      (solver/scene.c) collects them in the order of stats_engines, parses, checks, documents
      and writes them, and the engine reads their values from struct stats_scene by these
      definitions (stats_scene_int() and its kin). */
  const struct scene_key_def *const *keys;
  int n_keys; /*!< how many */
  /** Build the engine's configuration from the scene and set it up if the scene asks for it;
      returns 1 if it does, 0 if not (then self is left as it was and never used). */
  int (*init_scene)(void *self, const struct stats_scene *sc);
  /** A lower bound of the bytes the engine would allocate per rank for this scene (0 if the
      scene does not ask for it), before anything is allocated: the memory check of a scene
      (sim.c); NULL for an engine whose memory does not grow with the scene's keys. */
  double (*estimate)(const struct stats_scene *sc);
  /** Set up from the engine's own configuration struct (struct euler_config, ...). */
  void (*init)(void *self, const void *cfg);
  /** Free what init allocated. */
  void (*free)(void *self);
  /** Accumulate one snapshot (collective across the ranks: merged in a fixed order). */
  void (*sample)(void *self, const struct stats_snapshot *s);
  /** Close the open averaging window if t, the time the run has reached, lies at or past its
      end: no later snapshot can fall in it, so it is complete without waiting for the next
      one (stats.nc written at a window boundary, e.g. at t_end); what a later snapshot would
      do, so the records are the same. NULL for an engine without windows. */
  void (*close)(void *self, double t);
  /** Add the accumulators to a checkpoint's state list (state.h). */
  void (*state)(void *self, struct state_list *L);
  /** Bytes the accumulators hold. */
  size_t (*bytes)(const void *self);
  /** Write the engine's variables and groups into stats.nc (t_reached: the time the run
      reached, NaN if not known); netCDF status, with "message (in call)" in err. */
  int (*write)(const void *self, double t_reached, int ncid, char *err, size_t errlen);
  /** Warnings about what it could not give ("warning: ..." lines), or NULL; returns how many. */
  int (*warnings)(const void *self, char *buf, size_t len);
  /** Its lines for the log when stats.nc is written (each ending in a newline; nothing if it
      has nothing to say yet), or NULL. */
  void (*log)(const void *self, char *buf, size_t len);
};

enum { STATS_MAX_ENGINES = 16 }; /*!< room in struct stats (engines.c checks the list) */

/** The adapters from the table's void pointers to an engine's typed functions PREFIX_init,
    _free, _sample and _state (calling a function through a pointer of another type would be
    undefined): defines engine_init, engine_free, engine_sample and engine_state. */
#define STATS_ENGINE_ADAPTERS(PREFIX)                                     \
  static void engine_init(void *self, const void *cfg) {                  \
    PREFIX##_init(self, cfg);                                             \
  }                                                                       \
  static void engine_free(void *self) {                                   \
    PREFIX##_free(self);                                                  \
  }                                                                       \
  static void engine_sample(void *self, const struct stats_snapshot *s) { \
    PREFIX##_sample(self, s);                                             \
  }                                                                       \
  static void engine_state(void *self, struct state_list *L) {            \
    PREFIX##_state(self, L);                                              \
  }

/** The engines, in the order they are initialised, sampled, checkpointed and written. */
extern const struct stats_engine *const stats_engines[];
/** How many there are. */
extern const int stats_n_engines;

#endif
