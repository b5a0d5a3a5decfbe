/** @file ncout.c @brief Implementation of ncout.h. */
#include "ncout.h"
#include "alloc.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netcdf.h>
#include <netcdf_mem.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The calls of a column file being written: on failure, discard it (ncout.h). */
#define NC(call) NCOUT_OR_DISCARD(call)

int ncout_put_attrs(int ncid, const struct nc_attr *attrs, int nattrs) {
  for (int i = 0; i < nattrs; i++) {
    if (!attrs[i].text && !isfinite(attrs[i].value)) continue; /* not known: left out */
    const long long v = (long long)attrs[i].value;
    const int rc =
        attrs[i].text
            ? nc_put_att_text(ncid, NC_GLOBAL, attrs[i].name, strlen(attrs[i].text), attrs[i].text)
        : attrs[i].integer
            ? nc_put_att_longlong(ncid, NC_GLOBAL, attrs[i].name, NC_INT64, 1, &v)
            : nc_put_att_double(ncid, NC_GLOBAL, attrs[i].name, NC_DOUBLE, 1, &attrs[i].value);
    if (rc != NC_NOERR) return rc;
  }
  return NC_NOERR;
}

static int def_var(int ncid, const char *name, nc_type type, int ndim, const int *dims,
                   const char *units, const char *long_name, int *varid) {
  int rc = nc_def_var(ncid, name, type, ndim, dims, varid);
  if (rc == NC_NOERR && units) rc = nc_put_att_text(ncid, *varid, "units", strlen(units), units);
  if (rc == NC_NOERR && long_name)
    rc = nc_put_att_text(ncid, *varid, "long_name", strlen(long_name), long_name);
  return rc;
}

/* The file is built in memory (nc_create_mem) and written here with plain POSIX calls, so that a
   full disk or a file-size limit is an error message, not a failure inside HDF5's close (which
   HDF5 1.10 does not survive). Write the image to tmp, make it durable, move it into place. */
/* 1 if every dimension of variable a of group g is one of variable b's. */
static int dims_within(int g, int a, int b) {
  int na, nb, da[NC_MAX_VAR_DIMS], db[NC_MAX_VAR_DIMS];
  if (nc_inq_var(g, a, NULL, NULL, &na, da, NULL) || nc_inq_var(g, b, NULL, NULL, &nb, db, NULL))
    return 0;
  for (int i = 0; i < na; i++) {
    int found = 0;
    for (int j = 0; j < nb && !found; j++) found = da[i] == db[j];
    if (!found) return 0;
  }
  return 1;
}

int ncout_link_stderr(int ncid) {
  static const char *const extra[] = {"n_eff_windows", "short_windows", "n_batches",
                                      "release_batches", "pdf_release_batches"};
  int nv, rc = nc_inq_nvars(ncid, &nv);
  for (int v = 0; v < nv && rc == NC_NOERR; v++) {
    char name[NC_MAX_NAME + 1], se[NC_MAX_NAME + 16], list[4 * NC_MAX_NAME];
    int vs;
    if ((rc = nc_inq_varname(ncid, v, name)) != NC_NOERR) break;
    snprintf(se, sizeof se, "%s_stderr", name);
    if (nc_inq_varid(ncid, se, &vs) != NC_NOERR) continue;
    snprintf(list, sizeof list, "%s", se);
    for (size_t k = 0; k < sizeof extra / sizeof extra[0]; k++) {
      int ve;
      if (nc_inq_varid(ncid, extra[k], &ve) == NC_NOERR && dims_within(ncid, ve, v))
        snprintf(list + strlen(list), sizeof list - strlen(list), " %s", extra[k]);
    }
    rc = nc_put_att_text(ncid, v, "ancillary_variables", strlen(list), list);
  }
  int ng, *grps = NULL;
  if (rc == NC_NOERR) rc = nc_inq_grps(ncid, &ng, NULL);
  if (rc == NC_NOERR && ng > 0) {
    grps = mem_alloc((size_t)ng, sizeof *grps, "netCDF output");
    rc = nc_inq_grps(ncid, NULL, grps);
    for (int i = 0; i < ng && rc == NC_NOERR; i++) rc = ncout_link_stderr(grps[i]);
    free(grps);
  }
  return rc;
}

int ncout_commit(int ncid, const char *tmp, const char *path, char *err, size_t errlen) {
  NC_memio mem = {0, NULL, 0};
  const int rc = nc_close_memio(ncid, &mem);
  if (rc != NC_NOERR) {
    snprintf(err, errlen, "cannot write %s: %s (in nc_close_memio)", tmp, nc_strerror(rc));
    free(mem.memory);
    return 1;
  }
  const int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const char *p = mem.memory;
  size_t left = mem.size;
  int bad = fd < 0;
  while (!bad && left > 0) {
    const ssize_t w = write(fd, p, left);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      bad = 1;
      break;
    }
    p += w, left -= (size_t)w;
  }
  if (!bad && fsync(fd) != 0) bad = 1;
  const int why = errno;
  if (fd >= 0 && close(fd) != 0 && !bad) bad = 1;
  free(mem.memory);
  if (bad) {
    snprintf(err, errlen, "cannot write %s (%s); an earlier %s is kept", tmp, strerror(why), path);
    remove(tmp);
    return 1;
  }
  if (rename(tmp, path) != 0) {
    snprintf(err, errlen, "cannot rename %s to %s (%s)", tmp, path, strerror(errno));
    remove(tmp);
    return 1;
  }
  return 0;
}

int ncout_def(int ncid, const char *name, int type, int ndim, const int *dims, const char *units,
              const char *long_name, int *varid) {
  return def_var(ncid, name, (nc_type)type, ndim, dims, units, long_name, varid);
}

int ncout_fill(int ncid, int varid) {
  const double fill = NCOUT_FILL;
  return nc_put_att_double(ncid, varid, "_FillValue", NC_DOUBLE, 1, &fill);
}

int ncout_put_filled(int ncid, int varid, const size_t *start, const size_t *count, const double *v,
                     size_t n) {
  double *tmp = mem_alloc(1, (n ? n : 1) * sizeof *tmp, "netCDF output");
  for (size_t i = 0; i < n; i++) tmp[i] = isfinite(v[i]) ? v[i] : NCOUT_FILL;
  const int rc = start ? nc_put_vara_double(ncid, varid, start, count, tmp)
                       : nc_put_var_double(ncid, varid, tmp);
  free(tmp);
  return rc;
}

int ncout_labels(int ncid, const char *dim, int dimid, const char *long_name,
                 const char *const *labels) {
  size_t n;
  int v, rc = nc_inq_dimlen(ncid, dimid, &n);
  if (rc == NC_NOERR) rc = def_var(ncid, dim, NC_STRING, 1, &dimid, NULL, long_name, &v);
  if (rc == NC_NOERR && n) rc = nc_put_var_string(ncid, v, (const char **)labels);
  return rc;
}

int ncout_bounds(int ncid, const char *name, int varid, int dimid, const char *units,
                 const char *long_name, const double *lo, const double *hi, size_t n) {
  char bname[NC_MAX_NAME + 1];
  snprintf(bname, sizeof bname, "%s_bounds", name);
  int db, v;
  int rc = nc_inq_dimid(ncid, "bnds", &db);
  if (rc == NC_EBADDIM) rc = nc_def_dim(ncid, "bnds", 2, &db);
  const int dims[2] = {dimid, db};
  if (rc == NC_NOERR) rc = nc_put_att_text(ncid, varid, "bounds", strlen(bname), bname);
  if (rc == NC_NOERR) rc = def_var(ncid, bname, NC_DOUBLE, 2, dims, units, long_name, &v);
  double *b = mem_alloc(1, (n ? 2 * n : 1) * sizeof *b, "netCDF output");
  for (size_t i = 0; i < n; i++) b[2 * i] = lo[i], b[2 * i + 1] = hi[i];
  if (rc == NC_NOERR && n) rc = nc_put_var_double(ncid, v, b);
  free(b);
  return rc;
}

/* CF point data (CF-1.8 Sec. 9, featureType point) of a column file with ids: the dimension's
   coordinate variable (the ids) and, on every other column, the attribute coordinates naming
   the position columns x, y, z present. Returns a netCDF status. */
static int def_points(int ncid, const char *dim, int d, int ncol, const char *const *names,
                      const int *v, int *cvid) {
  char coords[16] = "";
  for (int c = 0; c < ncol; c++)
    if (!strcmp(names[c], "x") || !strcmp(names[c], "y") || !strcmp(names[c], "z"))
      snprintf(coords + strlen(coords), sizeof coords - strlen(coords), "%s%s",
               coords[0] ? " " : "", names[c]);
  int rc = nc_put_att_text(ncid, NC_GLOBAL, "featureType", 5, "point");
  if (rc == NC_NOERR) rc = def_var(ncid, dim, NC_INT64, 1, &d, NULL, "particle id", cvid);
  for (int c = 0; c < ncol && rc == NC_NOERR && coords[0]; c++)
    if (strlen(names[c]) > 1 || !strchr("xyz", names[c][0]))
      rc = nc_put_att_text(ncid, v[c], "coordinates", strlen(coords), coords);
  return rc;
}

int ncout_columns(const char *path, const char *title, const char *dim, size_t n, int ncol,
                  const char *const *names, const char *const *long_names, const char *const *units,
                  const double *const *cols, const long long *ids, const struct nc_attr *attrs,
                  int nattrs, char *err, size_t errlen) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  int ncid = -1, d, vid = -1;
  NC(nc_create_mem(tmp, NC_NETCDF4, 1 << 20, &ncid));
  NC(nc_put_att_text(ncid, NC_GLOBAL, "Conventions", 6, "CF-1.8"));
  NC(nc_put_att_text(ncid, NC_GLOBAL, "title", strlen(title), title));
  NC(nc_put_att_text(ncid, NC_GLOBAL, "source", 7, "chansph"));
  NC(nc_def_dim(ncid, dim, n, &d));
  if (ids) NC(def_var(ncid, "id", NC_INT64, 1, &d, "1", "particle id", &vid));
  int *v = mem_alloc(1, (size_t)ncol * sizeof *v, "netCDF output");
  if (!v) {
    snprintf(err, errlen, "out of memory writing %s", path);
    nc_close(ncid), remove(tmp);
    return 1;
  }
  for (int c = 0; c < ncol; c++) {
    const int rc = def_var(ncid, names[c], NC_DOUBLE, 1, &d, units[c],
                           long_names ? long_names[c] : NULL, &v[c]);
    if (rc != NC_NOERR) free(v);
    NC(rc);
  }
  int cvid = -1, rc = ids ? def_points(ncid, dim, d, ncol, names, v, &cvid) : NC_NOERR;
  if (rc == NC_NOERR) rc = ncout_put_attrs(ncid, attrs, nattrs);
  if (rc == NC_NOERR) rc = nc_enddef(ncid);
  if (rc == NC_NOERR && ids) rc = nc_put_var_longlong(ncid, vid, ids);
  if (rc == NC_NOERR && ids) rc = nc_put_var_longlong(ncid, cvid, ids);
  for (int c = 0; c < ncol && rc == NC_NOERR; c++) rc = nc_put_var_double(ncid, v[c], cols[c]);
  free(v);
  NC(rc);
  return ncout_commit(ncid, tmp, path, err, errlen);
}
