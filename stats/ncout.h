/**
 * @file ncout.h
 * @brief netCDF-4 output: stats.nc (profiles + time series + run attributes) and column files
 *        (particle snapshots). Files are written to NAME.tmp, synced and renamed, so a reader
 *        or a crash never sees a half-written file and the previous version survives a failure.
 */
#ifndef CHANSPH_NCOUT_H
#define CHANSPH_NCOUT_H

#include <stddef.h>

#include "series.h"

struct stats;

/** A global attribute: text if text != NULL, else a double, or a 64-bit integer if integer. */
struct nc_attr {
  const char *name;
  const char *text;
  double value;
  int integer; /*!< 1: a count or flag, written as an int64 */
};

/**
 * @brief Write stats.nc atomically.
 * @param[in] path final file name
 * @param[in] st statistics engine (its variables and groups, stats_nc_write)
 * @param[in] ts time series (unlimited dimension time; column 0 must be the time)
 * @param[in] attrs,nattrs global attributes
 * @param[out] err message buffer (filled on failure)
 * @param[in] errlen its size
 * @return 0 on success, nonzero on failure (the previous file is left untouched)
 */
int ncout_stats(const char *path, const struct stats *st, const struct series *ts,
                const struct nc_attr *attrs, int nattrs, char *err, size_t errlen);

/**
 * @brief Write named double columns along one dimension atomically (e.g. particles.nc).
 * @param[in] path file name
 * @param[in] title global attribute title (the file also gets Conventions = CF-1.8, source)
 * @param[in] dim dimension name
 * @param[in] n rows
 * @param[in] ncol columns
 * @param[in] names,units column names and units (udunits strings)
 * @param[in] long_names column descriptions (attribute long_name; NULL: none)
 * @param[in] cols column data
 * @param[in] ids optional int64 ids written as variable "id" (may be NULL)
 * @param[in] attrs,nattrs global attributes
 * @param[out] err,errlen message on failure
 * @return 0 on success
 */
int ncout_columns(const char *path, const char *title, const char *dim, size_t n, int ncol,
                  const char *const *names, const char *const *long_names, const char *const *units,
                  const double *const *cols, const long long *ids, const struct nc_attr *attrs,
                  int nattrs, char *err, size_t errlen);

/**
 * @brief Define a variable with units and long_name attributes (CF).
 * @return a netCDF status
 */
int ncout_def(int ncid, const char *name, int type, int ndim, const int *dims, const char *units,
              const char *long_name, int *varid);

/** The value written for a missing value (NC_FILL_DOUBLE), declared as _FillValue. */
#define NCOUT_FILL 9.9692099683868690e+36

/**
 * @brief Declare the _FillValue (NCOUT_FILL) of a double variable: the one missing-value
 *        convention of chansph's netCDF files (no NaN is ever written).
 */
int ncout_fill(int ncid, int varid);

/**
 * @brief Write n doubles with non-finite values replaced by NCOUT_FILL.
 * @param[in] start,count the hyperslab (NULL, NULL: the whole variable of n values)
 */
int ncout_put_filled(int ncid, int varid, const size_t *start, const size_t *count, const double *v,
                     size_t n);

/**
 * @brief A categorical axis: the string coordinate variable named like dimension dim (one
 *        label per index), so that xarray shows labelled axes.
 */
int ncout_labels(int ncid, const char *dim, int dimid, const char *long_name,
                 const char *const *labels);

/**
 * @brief The CF cell bounds of a coordinate variable: NAME_bounds (dimensions: the coordinate's,
 *        then "bnds" of length 2, defined in ncid if not visible there) with lo[i], hi[i], and the
 *        attribute bounds = "NAME_bounds" on the coordinate.
 */
int ncout_bounds(int ncid, const char *name, int varid, int dimid, const char *units,
                 const char *long_name, const double *lo, const double *hi, size_t n);

#endif
