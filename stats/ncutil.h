/**
 * @file ncutil.h
 * @brief The error check shared by the netCDF writers of the engines.
 */
#ifndef CHANSPH_NCUTIL_H
#define CHANSPH_NCUTIL_H

#include <netcdf.h>
#include <stdio.h>

/** Run a netCDF call; on failure store "message (in call)" in err (errlen bytes) and jump to
    label. Needs `int rc`, `char *err`, `size_t errlen` in scope. */
#define NC_TRY(call, label)                                        \
  do {                                                             \
    rc = (call);                                                   \
    if (rc != NC_NOERR) {                                          \
      snprintf(err, errlen, "%s (in %s)", nc_strerror(rc), #call); \
      goto label;                                                  \
    }                                                              \
  } while (0)

#endif
