/** @file stats_nc.c @brief Implementation of stats_nc.h. */
#include "stats_nc.h"

#include <netcdf.h>
#include <netcdf_mem.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "engine.h"
#include "ncout.h"

int stats_nc_write(const struct stats *st, int ncid, char *err, size_t errlen) {
  for (int k = 0; k < stats_n_engines; k++) {
    if (!st->self[k]) continue;
    const int rc = stats_engines[k]->write(st->self[k], st->t_reached, ncid, err, errlen);
    if (rc) return rc;
  }
  return NC_NOERR;
}

int stats_nc_file(const char *path, const struct stats *st, const struct series *ts,
                  const struct nc_attr *attrs, int nattrs, char *err, size_t errlen) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  int ncid = -1, dt;
  NCOUT_OR_DISCARD(nc_create_mem(tmp, NC_NETCDF4, 1 << 20, &ncid));
  NCOUT_OR_DISCARD(nc_put_att_text(ncid, NC_GLOBAL, "Conventions", 6, "CF-1.8"));
  NCOUT_OR_DISCARD(
      nc_put_att_text(ncid, NC_GLOBAL, "title", 36, "chansph channel-flow statistics file"));
  NCOUT_OR_DISCARD(nc_put_att_text(ncid, NC_GLOBAL, "source", 7, "chansph"));
  NCOUT_OR_DISCARD(ncout_put_attrs(ncid, attrs, nattrs));
  /* the engines: profiles (dimension y), groups of raw accumulators */
  char eerr[1024] = "";
  const int erc = stats_nc_write(st, ncid, eerr, sizeof eerr);
  if (erc != NC_NOERR) {
    snprintf(err, errlen, "cannot write %s: %s", tmp, eerr);
    nc_close(ncid), remove(tmp);
    return 1;
  }
  /* time series, column by column, on the unlimited dimension time */
  NCOUT_OR_DISCARD(nc_def_dim(ncid, "time", NC_UNLIMITED, &dt));
  int *vts = mem_alloc(1, (size_t)ts->ncol * sizeof *vts, "netCDF output");
  double *col = mem_alloc(1, (ts->n ? ts->n : 1) * sizeof *col, "netCDF output");
  int rc = NC_NOERR;
  for (int c = 0; c < ts->ncol && rc == NC_NOERR; c++) {
    rc = ncout_def(ncid, ts->names[c], NC_DOUBLE, 1, &dt, ts->units[c],
                   ts->long_names ? ts->long_names[c] : NULL, &vts[c]);
    /* simulated time from the initial condition: no calendar date to refer to, so plain
       seconds (udunits "s", what xarray keeps as float seconds) and the origin in words
       (docs/stats-format.md) */
    static const char ref[] =
        "t = 0 is the initial condition of the run (simulated time, not a "
        "calendar date)";
    if (rc == NC_NOERR && c == 0) rc = nc_put_att_text(ncid, vts[c], "standard_name", 4, "time");
    if (rc == NC_NOERR && c == 0) rc = nc_put_att_text(ncid, vts[c], "axis", 1, "T");
    if (rc == NC_NOERR && c == 0) rc = nc_put_att_text(ncid, vts[c], "reference", strlen(ref), ref);
    if (rc == NC_NOERR && c > 0) rc = ncout_fill(ncid, vts[c]);
  }
  for (int c = 0; c < ts->ncol && rc == NC_NOERR && ts->n; c++) {
    for (size_t r = 0; r < ts->n; r++) col[r] = ts->data[r * (size_t)ts->ncol + c];
    const size_t start = 0, count = ts->n;
    rc = ncout_put_filled(ncid, vts[c], &start, &count, col, ts->n);
  }
  free(col), free(vts);
  NCOUT_OR_DISCARD(rc);
  NCOUT_OR_DISCARD(ncout_link_stderr(ncid)); /* CF: each statistic names its error */
  return ncout_commit(ncid, tmp, path, err, errlen);
}
