/**
 * @file series.h
 * @brief The time series of a run: a table of named columns growing by rows.
 */
#ifndef CHANSPH_SERIES_H
#define CHANSPH_SERIES_H

#include <stddef.h>
#include <stdint.h>

/** A table of named columns growing by rows (the time series of a run). */
struct series {
  int ncol;
  const char *const *names; /*!< column names (static strings) */
  const char *const *units; /*!< column units (static strings) */
  size_t n, cap;            /*!< rows stored, capacity */
  double *data;             /*!< row-major values */
};

/** @brief Initialise an empty series with static column names and units. */
void series_init(struct series *s, int ncol, const char *const *names, const char *const *units);

/** @brief Append one row of ncol values. */
void series_add(struct series *s, const double *row);

/** @brief Free the rows. */
void series_free(struct series *s);

#endif
