/**
 * @file ncout.h
 * @brief The low-level netCDF-4 helpers of chansph's files (CF variables, fill values, labels,
 *        cell bounds, global attributes, the atomic commit) and the column files (particles.nc).
 *        Files are built in memory, written to NAME.tmp, synced and renamed, so a reader or a
 *        crash never sees a half-written file and the previous version survives a failure; a
 *        column file of several ranks is written by them together (ncout_columns_par) with the
 *        same rules. The stats.nc writer is stats_nc.h; this file knows no engine.
 */
#ifndef CHANSPH_NCOUT_H
#define CHANSPH_NCOUT_H

#include <netcdf.h>
#include <stddef.h>
#include <stdio.h>

/** A global attribute: text if text != NULL, else a double, or a 64-bit integer if integer. */
struct nc_attr {
  const char *name;
  const char *text;
  double value;
  int integer; /*!< 1: a count or flag, written as an int64 */
};

/** Run a netCDF call of a file being written to tmp (ncid, or -1); on failure store "cannot
    write TMP: message (in call)" in err (errlen bytes), close the file, remove tmp and return 1
    from the calling function. */
#define NCOUT_OR_DISCARD(call)                                                               \
  do {                                                                                       \
    const int nc_rc_ = (call);                                                               \
    if (nc_rc_ != NC_NOERR) {                                                                \
      snprintf(err, errlen, "cannot write %s: %s (in %s)", tmp, nc_strerror(nc_rc_), #call); \
      if (ncid >= 0) nc_close(ncid);                                                         \
      remove(tmp);                                                                           \
      return 1;                                                                              \
    }                                                                                        \
  } while (0)

/**
 * @brief Put global attributes; a number that is not finite (not known) is left out.
 * @return a netCDF status
 */
int ncout_put_attrs(int ncid, const struct nc_attr *attrs, int nattrs);

/**
 * @brief CF links from each statistic to its uncertainty, in group ncid and every group below:
 *        a variable NAME with a variable NAME_stderr beside it gets the attribute
 *        ancillary_variables = "NAME_stderr", followed by those of n_eff_windows,
 *        short_windows, n_batches, release_batches and pdf_release_batches that the group
 *        holds on a subset of NAME's dimensions (the batches and the flags of that error).
 * @return a netCDF status
 */
int ncout_link_stderr(int ncid);

/**
 * @brief Close a file built in memory (nc_create_mem), write its image to tmp, make it durable
 *        and rename it to path; on failure tmp is removed and an earlier path is kept.
 * @param[out] err,errlen message on failure
 * @return 0 on success, 1 on failure
 */
int ncout_commit(int ncid, const char *tmp, const char *path, char *err, size_t errlen);

/** What a column file holds besides its data (ncout_columns, ncout_columns_par). */
struct ncout_table {
  const char *title;             /*!< global attribute title (the file also gets Conventions =
                                      CF-1.8, source) */
  const char *dim;               /*!< the rows' dimension */
  size_t n;                      /*!< rows in the file */
  int ncol;                      /*!< columns (doubles) */
  const char *const *names;      /*!< column names */
  const char *const *long_names; /*!< column descriptions (attribute long_name; NULL: none) */
  const char *const *units;      /*!< column units (udunits strings) */
  const struct nc_attr *attrs;   /*!< global attributes */
  int nattrs;                    /*!< their number */
};

/**
 * @brief Write named double columns along one dimension atomically (e.g. particles.nc): the
 *        file is built in memory and committed (ncout_commit).
 * @param[in] path file name
 * @param[in] t the dimension, columns and attributes
 * @param[in] cols column data (t->n rows each)
 * @param[in] ids optional int64 ids written as variable "id" and as the coordinate variable of
 *                dim, with CF point markup (featureType point, coordinates "x y z") (may be NULL)
 * @param[out] err,errlen message on failure
 * @return 0 on success
 */
int ncout_columns(const char *path, const struct ncout_table *t, const double *const *cols,
                  const long long *ids, char *err, size_t errlen);

/**
 * @brief ncout_columns() written by all ranks of MPI_COMM_WORLD together, each with its rows
 *        lo .. lo+rows-1 of every column (and ids): the same dimension, variables and attributes
 *        (rank 0's global attributes), no fill values. Parallel netCDF-4 (MPI-IO, collective
 *        writes) into PATH.tmp, after rank 0 made sure the file fits (durable_probe); rank 0
 *        then fsyncs it, renames it to path and fsyncs the directory. The ranks agree on every
 *        step: each returns the same result and message (naming the file; an earlier path is
 *        kept and no PATH.tmp is left on failure). Collective.
 * @return 0 on success
 */
int ncout_columns_par(const char *path, const struct ncout_table *t, size_t lo, size_t rows,
                      const double *const *cols, const long long *ids, char *err, size_t errlen);

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
 * @brief Read variable name of group g, n doubles in all (any shape), into out, _FillValue
 *        (NCOUT_FILL) back to NaN: the raw records chansph extract re-combines.
 * @return 0, or nonzero if the variable is absent, holds another number of values or cannot be
 *         read.
 */
int ncout_get_raw(int g, const char *name, size_t n, double *out);

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
