/**
 * @file profile.h
 * @brief Wall-normal binned profiles (bin sampling, thesis Eq. 5.54-5.55) and time series.
 *
 * The statistics engine sees plain arrays only, never solver structs. Accumulation is serial
 * over the particles in the order given, so the sums do not depend on the number of threads.
 */
#ifndef CHANSPH_PROFILE_H
#define CHANSPH_PROFILE_H

#include <stddef.h>
#include <stdint.h>

/** Time- and plane-averaged profiles over wall-normal bins. */
struct profile {
  int nb;                        /*!< number of bins */
  double y0, y1;                 /*!< range of the uniform bins [m] */
  double *sum_u, *sum_v, *sum_w; /*!< sums of velocity samples per bin [m/s] */
  double *sum_y;                 /*!< sum of sample positions per bin [m] */
  int64_t *count;                /*!< samples per bin */
  long n_snapshots;              /*!< snapshots accumulated */
};

/**
 * @brief Allocate an empty profile.
 * @param[out] pr profile
 * @param[in] nb bins
 * @param[in] y0,y1 range of y [m]
 */
void profile_init(struct profile *pr, int nb, double y0, double y1);

/** @brief Free a profile. */
void profile_free(struct profile *pr);

/**
 * @brief Add one snapshot: every particle with skip[i] == 0 adds its velocity to its bin;
 *        particles below y0 or above y1 count in the first or last bin.
 * @param[in,out] pr profile
 * @param[in] n particles
 * @param[in] y,u,v,w position and velocity arrays
 * @param[in] skip per-particle flag, nonzero = not sampled (may be NULL)
 */
void profile_add(struct profile *pr, size_t n, const double *y, const double *u, const double *v,
                 const double *w, const uint8_t *skip);

/** @brief Centre of bin i [m]. */
double profile_centre(const struct profile *pr, int i);

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
