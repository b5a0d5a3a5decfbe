/**
 * @file stats_setup.h
 * @brief The statistics tests' way to set up the engines with explicit configurations (the
 *        solver configures them from the scene instead, stats_init) and to reach their states.
 */
#ifndef CHANSPH_TEST_STATS_SETUP_H
#define CHANSPH_TEST_STATS_SETUP_H

#include "corr.h"
#include "euler.h"
#include "lagr.h"
#include "pdf.h"
#include "quad.h"
#include "stats.h"

/** The engines a test runs: each with its configuration, off if eulerian == 0 / n_levels == 0. */
struct test_stats_config {
  int eulerian;            /*!< 1: Eulerian profiles */
  struct euler_config eul; /*!< their bins and windows */
  struct corr_config corr; /*!< two-point correlations (off if corr.n_levels == 0) */
  struct lagr_config lagr; /*!< Lagrangian statistics (off if lagr.n_levels == 0) */
  struct quad_config quad; /*!< quadrant analysis (off if quad.n_levels == 0) */
  struct pdf_config pdf;   /*!< one-point PDFs (off if pdf.n_levels == 0) */
};

/** @brief Set up the engines c asks for. */
static inline void test_stats_init(struct stats *st, const struct test_stats_config *c) {
  stats_init(st, NULL);
  if (c->eulerian) stats_add(st, &euler_engine, &c->eul);
  if (c->corr.n_levels > 0) stats_add(st, &corr_engine, &c->corr);
  if (c->lagr.n_levels > 0) stats_add(st, &lagr_engine, &c->lagr);
  if (c->quad.n_levels > 0) stats_add(st, &quad_engine, &c->quad);
  if (c->pdf.n_levels > 0) stats_add(st, &pdf_engine, &c->pdf);
}

/** @brief The Eulerian engine's state (NULL if off). */
static inline struct euler *test_eu(const struct stats *st) {
  return stats_find(st, &euler_engine);
}

/** @brief The correlation engine's state (NULL if off). */
static inline struct corr *test_co(const struct stats *st) {
  return stats_find(st, &corr_engine);
}

/** @brief The Lagrangian engine's state (NULL if off). */
static inline struct lagr *test_la(const struct stats *st) {
  return stats_find(st, &lagr_engine);
}

/** @brief The PDF engine's state (NULL if off). */
static inline struct pdf *test_pdf(const struct stats *st) {
  return stats_find(st, &pdf_engine);
}

#endif
