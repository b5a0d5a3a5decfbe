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
  const char *const *names;      /*!< column names (static strings) */
  const char *const *units;      /*!< column units (static strings) */
  const char *const *long_names; /*!< column descriptions (static strings; NULL: none) */
  size_t n, cap;                 /*!< rows stored, capacity */
  double *data;                  /*!< row-major values */
};

/** @brief Initialise an empty series with static column names, units and long names (may be
    NULL). */
void series_init(struct series *s, int ncol, const char *const *names, const char *const *units,
                 const char *const *long_names);

/** @brief Append one row of ncol values. */
void series_add(struct series *s, const double *row);

/** @brief Free the rows. */
void series_free(struct series *s);

#endif
