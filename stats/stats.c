/** @file stats.c @brief Implementation of stats.h: the engines through their table of
    operations (engine.h), none of them by name. */
#include "stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "state.h"

void stats_init(struct stats *st, const struct stats_scene *sc) {
  memset(st, 0, sizeof *st);
  st->t_reached = NAN;
  for (int k = 0; k < stats_n_engines && sc; k++) {
    const struct stats_engine *e = stats_engines[k];
    void *self = mem_calloc(1, e->size, e->name);
    if (e->init_scene(self, sc))
      st->self[k] = self;
    else
      free(self);
  }
}

/* The place of e in stats_engines. */
static int index_of(const struct stats_engine *e) {
  for (int k = 0; k < stats_n_engines; k++)
    if (stats_engines[k] == e) return k;
  die("statistics engine %s is not in stats_engines (engines.c)", e->name);
  return -1;
}

void stats_add(struct stats *st, const struct stats_engine *e, const void *cfg) {
  const int k = index_of(e);
  if (st->self[k]) e->free(st->self[k]), free(st->self[k]);
  st->self[k] = mem_calloc(1, e->size, e->name);
  e->init(st->self[k], cfg);
}

void *stats_find(const struct stats *st, const struct stats_engine *e) {
  return st->self[index_of(e)];
}

void stats_free(struct stats *st) {
  for (int k = 0; k < stats_n_engines; k++)
    if (st->self[k]) stats_engines[k]->free(st->self[k]), free(st->self[k]);
  memset(st, 0, sizeof *st);
}

int stats_wanted(const struct stats *st) {
  for (int k = 0; k < stats_n_engines; k++)
    if (st->self[k]) return 1;
  return 0;
}

void stats_sample(struct stats *st, const struct stats_snapshot *s) {
  for (int k = 0; k < stats_n_engines; k++)
    if (st->self[k]) stats_engines[k]->sample(st->self[k], s);
  st->samples++;
}

void stats_close(struct stats *st, double t) {
  for (int k = 0; k < stats_n_engines; k++)
    if (st->self[k] && stats_engines[k]->close) stats_engines[k]->close(st->self[k], t);
}

void stats_state(struct stats *st, struct state_list *L) {
  state_add(L, "stats/samples", STATE_I64, 0, NULL, &st->samples, NULL);
  for (int k = 0; k < stats_n_engines; k++)
    if (st->self[k]) stats_engines[k]->state(st->self[k], L);
}

size_t stats_memory(const struct stats *st) {
  size_t b = 0;
  for (int k = 0; k < stats_n_engines; k++)
    if (st->self[k]) b += stats_engines[k]->bytes(st->self[k]);
  return b;
}

int stats_warnings(const struct stats *st, char *buf, size_t len) {
  buf[0] = '\0';
  int n = 0;
  for (int k = 0; k < stats_n_engines; k++) {
    const struct stats_engine *e = stats_engines[k];
    if (!e->warnings || !st->self[k]) continue;
    const size_t used = strlen(buf);
    n += e->warnings(st->self[k], buf + used, len - used);
  }
  return n;
}

void stats_convergence_line(const struct stats *st, char *buf, size_t len) {
  buf[0] = '\0';
  for (int k = 0; k < stats_n_engines; k++) {
    const struct stats_engine *e = stats_engines[k];
    if (!e->log || !st->self[k]) continue;
    const size_t used = strlen(buf);
    e->log(st->self[k], buf + used, len - used);
  }
}
