/**
 * @file stats_nc.h
 * @brief The stats.nc writer: the run's attributes, every running engine's variables and
 *        groups (through their write operation, engine.h) and the time series, written
 *        atomically with the helpers of ncout.h.
 */
#ifndef CHANSPH_STATS_NC_H
#define CHANSPH_STATS_NC_H

#include <stddef.h>

#include "ncout.h"
#include "series.h"
#include "stats.h"

/**
 * @brief Define and write the engines' variables and groups into an open netCDF-4 file.
 * @param[in] st engine
 * @param[in] ncid file
 * @param[out] err,errlen message on failure
 * @return 0 or a netCDF status
 */
int stats_nc_write(const struct stats *st, int ncid, char *err, size_t errlen);

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
int stats_nc_file(const char *path, const struct stats *st, const struct series *ts,
                  const struct nc_attr *attrs, int nattrs, char *err, size_t errlen);

#endif
