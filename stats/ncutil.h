/**
 * @file ncutil.h
 * @brief The error check shared by the netCDF writers of the engines.
 */
#ifndef CHANSPH_NCUTIL_H
#define CHANSPH_NCUTIL_H

#include <netcdf.h>
#include <stdio.h>

#include "error.h"

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

/** Run a netCDF call whose failure has no graceful path (closing a file that was read): a
    failure dies naming the call, file and line, with nc_strerror. Writers use NC_TRY. */
#define CHECK_NC(call)                                                                         \
  do {                                                                                         \
    const int check_nc_rc_ = (call);                                                           \
    if (check_nc_rc_ != NC_NOERR) die("netCDF: %s (in %s)", nc_strerror(check_nc_rc_), #call); \
  } while (0)

#endif
