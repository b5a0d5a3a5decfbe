/** @file ncout.c @brief Implementation of ncout.h. */
#include "ncout.h"
#include "alloc.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <mpi.h>
#include <netcdf.h>
#include <netcdf_mem.h>
#include <netcdf_par.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "durable.h"
#include "error.h"

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

/* CF point data (CF-1.8 Sec. 9, featureType point) of a column file with ids: on every column
   but the positions, the attribute coordinates naming the position columns x, y, z present.
   (The dimension's coordinate variable, the ids, is defined with the others: def_table.)
   Returns a netCDF status. */
static int point_coords(int ncid, int ncol, const char *const *names, const int *v) {
  char coords[16] = "";
  for (int c = 0; c < ncol; c++)
    if (!strcmp(names[c], "x") || !strcmp(names[c], "y") || !strcmp(names[c], "z"))
      snprintf(coords + strlen(coords), sizeof coords - strlen(coords), "%s%s",
               coords[0] ? " " : "", names[c]);
  int rc = NC_NOERR;
  for (int c = 0; c < ncol && rc == NC_NOERR && coords[0]; c++)
    if (strlen(names[c]) > 1 || !strchr("xyz", names[c][0]))
      rc = nc_put_att_text(ncid, v[c], "coordinates", strlen(coords), coords);
  return rc;
}

/* The variables of a column file: the columns 0 .. ncol-1, and with ids the variable id
   (DEF_ID) and the dimension's coordinate variable (DEF_COORD). */
enum { DEF_ID = -1, DEF_COORD = -2 };

static const char *def_name(const struct ncout_table *t, int k) {
  return k == DEF_ID ? "id" : k == DEF_COORD ? t->dim : t->names[k];
}

/* The order in which they are defined: the ids, the columns, the coordinate variable; by name
   if sorted. A file built in memory tracks no creation order, and netCDF lists its variables
   by name; a file written in parallel lists them in creation order: defined by name, both list
   them alike. Returns their number. */
static int def_order(const struct ncout_table *t, int ids, int sorted, int *order) {
  int nk = 0;
  if (ids) order[nk++] = DEF_ID;
  for (int c = 0; c < t->ncol; c++) order[nk++] = c;
  if (ids) order[nk++] = DEF_COORD;
  for (int i = 1; i < nk && sorted; i++) /* insertion sort: a few names */
    for (int j = i; j > 0 && strcmp(def_name(t, order[j - 1]), def_name(t, order[j])) > 0; j--) {
      const int k = order[j];
      order[j] = order[j - 1], order[j - 1] = k;
    }
  return nk;
}

/* The global attributes, dimension and variables of a column file (in define mode): v[c] the
   columns; with ids, *vid the variable id and *cvid the dimension's coordinate variable. The
   same calls on one rank and on several, the variables by name if sorted (def_order). Returns a
   netCDF status. */
static int def_table(int ncid, const struct ncout_table *t, int ids, int sorted, int *v, int *vid,
                     int *cvid) {
  int d, rc = nc_put_att_text(ncid, NC_GLOBAL, "Conventions", 6, "CF-1.8");
  if (rc == NC_NOERR) rc = nc_put_att_text(ncid, NC_GLOBAL, "title", strlen(t->title), t->title);
  if (rc == NC_NOERR) rc = nc_put_att_text(ncid, NC_GLOBAL, "source", 7, "chansph");
  if (rc == NC_NOERR) rc = nc_def_dim(ncid, t->dim, t->n, &d);
  int *order = mem_alloc((size_t)t->ncol + 2, sizeof *order, "netCDF output");
  const int nk = def_order(t, ids, sorted, order);
  for (int i = 0; i < nk && rc == NC_NOERR; i++) {
    const int k = order[i];
    if (k == DEF_ID) {
      rc = def_var(ncid, "id", NC_INT64, 1, &d, "1", "particle id", vid);
    } else if (k == DEF_COORD) { /* CF point data (CF-1.8 Sec. 9) */
      rc = nc_put_att_text(ncid, NC_GLOBAL, "featureType", 5, "point");
      if (rc == NC_NOERR) rc = def_var(ncid, t->dim, NC_INT64, 1, &d, NULL, "particle id", cvid);
    } else {
      rc = def_var(ncid, t->names[k], NC_DOUBLE, 1, &d, t->units[k],
                   t->long_names ? t->long_names[k] : NULL, &v[k]);
    }
  }
  free(order);
  if (rc == NC_NOERR && ids) rc = point_coords(ncid, t->ncol, t->names, v);
  if (rc == NC_NOERR) rc = ncout_put_attrs(ncid, t->attrs, t->nattrs);
  return rc;
}

int ncout_columns(const char *path, const struct ncout_table *t, const double *const *cols,
                  const long long *ids, char *err, size_t errlen) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  int ncid = -1, vid = -1, cvid = -1;
  NC(nc_create_mem(tmp, NC_NETCDF4, 1 << 20, &ncid));
  int *v = mem_alloc(t->ncol > 0 ? (size_t)t->ncol : 1, sizeof *v, "netCDF output");
  int rc = def_table(ncid, t, ids != NULL, 0, v, &vid, &cvid);
  if (rc == NC_NOERR) rc = nc_enddef(ncid);
  if (rc == NC_NOERR && ids) rc = nc_put_var_longlong(ncid, vid, ids);
  if (rc == NC_NOERR && ids) rc = nc_put_var_longlong(ncid, cvid, ids);
  for (int c = 0; c < t->ncol && rc == NC_NOERR; c++) rc = nc_put_var_double(ncid, v[c], cols[c]);
  free(v);
  NC(rc);
  return ncout_commit(ncid, tmp, path, err, errlen);
}

/* A step of a collective write: on failure "cannot write TMP: message (in what)"; the ranks
   agree (durable_agree): 1 on every rank if it failed on any, with that rank's message. */
static int par_step(int rc, const char *what, const char *tmp, char *err, size_t errlen) {
  if (rc != NC_NOERR)
    snprintf(err, errlen, "cannot write %s: %s (in %s)", tmp, nc_strerror(rc), what);
  return durable_agree(rc != NC_NOERR, err, errlen);
}

/* The global attributes as rank 0 has them (the date it read, the run's history that only it
   reads): the ranks that write a netCDF-4 file together must give it the same metadata. The
   texts of the copy are in *store (free both). Collective. */
static struct nc_attr *root_attrs(const struct nc_attr *a, int n, char **store) {
  int me = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  unsigned long long len = 0;
  for (int i = 0; i < n && me == 0; i++) len += a[i].text ? strlen(a[i].text) + 1 : 0;
  CHECK_MPI(MPI_Bcast(&len, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD));
  if (len > INT_MAX) die("netCDF output: %llu bytes of global attributes", len);
  char *text = mem_alloc(len ? len : 1, 1, "netCDF output");
  double *num = mem_alloc(n > 0 ? 2 * (size_t)n : 1, sizeof *num, "netCDF output");
  for (size_t i = 0, k = 0; (int)i < n && me == 0; i++) {
    num[2 * i] = a[i].value, num[2 * i + 1] = a[i].text != NULL;
    if (a[i].text) memcpy(text + k, a[i].text, strlen(a[i].text) + 1), k += strlen(a[i].text) + 1;
  }
  CHECK_MPI(MPI_Bcast(text, (int)len, MPI_CHAR, 0, MPI_COMM_WORLD));
  CHECK_MPI(MPI_Bcast(num, 2 * n, MPI_DOUBLE, 0, MPI_COMM_WORLD));
  struct nc_attr *out = mem_alloc(n > 0 ? (size_t)n : 1, sizeof *out, "netCDF output");
  for (size_t i = 0, k = 0; (int)i < n; i++) { /* names and kinds are the same on every rank */
    out[i] = a[i], out[i].value = num[2 * i], out[i].text = num[2 * i + 1] ? text + k : NULL;
    if (out[i].text) k += strlen(out[i].text) + 1;
  }
  free(num);
  *store = text;
  return out;
}

/* Define the file and write this rank's rows lo .. lo+rows-1 of every variable collectively;
   1 on every rank if any failed. */
static int par_write(int ncid, const struct ncout_table *t, size_t lo, size_t rows,
                     const double *const *cols, const long long *ids, const char *tmp, char *err,
                     size_t errlen) {
  int *v = mem_alloc(t->ncol > 0 ? (size_t)t->ncol : 1, sizeof *v, "netCDF output");
  int vid = -1, cvid = -1, old;
  /* no fill values: every row is written, and parallel HDF5 would write them all first */
  int rc = nc_set_fill(ncid, NC_NOFILL, &old);
  if (rc == NC_NOERR) rc = def_table(ncid, t, ids != NULL, 1, v, &vid, &cvid);
  if (rc == NC_NOERR) rc = nc_enddef(ncid);
  int bad = par_step(rc, "defining the variables", tmp, err, errlen);
  const size_t start = rows ? lo : 0; /* an empty block writes nothing, but takes part */
  for (int c = ids ? -2 : 0; c < t->ncol && !bad; c++) { /* ids, coordinate, then the columns */
    const int var = c == -2 ? vid : c == -1 ? cvid : v[c];
    rc = nc_var_par_access(ncid, var, NC_COLLECTIVE);
    if (rc == NC_NOERR)
      rc = c < 0 ? nc_put_vara_longlong(ncid, var, &start, &rows, ids)
                 : nc_put_vara_double(ncid, var, &start, &rows, cols[c]);
    bad = par_step(rc, c < 0 ? "writing the ids" : t->names[c], tmp, err, errlen);
  }
  free(v);
  return bad;
}

/* A failure before the rename: say that the earlier file is kept. */
static void kept(char *err, size_t errlen, const char *path) {
  const size_t k = strlen(err);
  if (k + 1 < errlen) snprintf(err + k, errlen - k, "; an earlier %s is kept", path);
}

int ncout_columns_par(const char *path, const struct ncout_table *t, size_t lo, size_t rows,
                      const double *const *cols, const long long *ids, char *err, size_t errlen) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  int me = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  char *text;
  struct ncout_table tt = *t;
  struct nc_attr *attrs = root_attrs(t->attrs, t->nattrs, &text);
  tt.attrs = attrs;
  /* rank 0 makes sure it fits first (durable_probe): the data, the attributes and room for the
     metadata (4 kB a variable, 64 kB) */
  size_t need = t->n * ((size_t)t->ncol + (ids ? 2 : 0)) * sizeof(double) +
                4096 * ((size_t)t->ncol + 3) + ((size_t)1 << 16);
  for (int i = 0; i < t->nattrs; i++) need += attrs[i].text ? strlen(attrs[i].text) : 8;
  int rc = durable_agree(me == 0 ? durable_probe(tmp, need, "", err, errlen) : 0, err, errlen);
  int ncid = -1;
  if (!rc)
    rc = par_step(nc_create_par(tmp, NC_NETCDF4 | NC_CLOBBER, MPI_COMM_WORLD, MPI_INFO_NULL, &ncid),
                  "nc_create_par", tmp, err, errlen);
  if (!rc) rc = par_write(ncid, &tt, lo, rows, cols, ids, tmp, err, errlen);
  const int closed = ncid >= 0 ? nc_close(ncid) : NC_NOERR; /* collective: after every step */
  if (!rc) rc = par_step(closed, "nc_close", tmp, err, errlen);
  free(attrs), free(text);
  /* rank 0: make it durable, move it into place, sync the directory */
  int renamed = 0;
  if (me == 0 && !rc && durable_sync(tmp, 0))
    snprintf(err, errlen, "cannot fsync %s: %s", tmp, strerror(errno)), rc = 1;
  if (me == 0 && !rc && rename(tmp, path))
    snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno)), rc = 1;
  else if (me == 0 && !rc)
    renamed = 1, rc = durable_sync_dir(path, err, errlen);
  if (me == 0 && rc && !renamed) kept(err, errlen, path), remove(tmp);
  return durable_agree(rc, err, errlen);
}

int ncout_get_raw(int g, const char *name, size_t n, double *out) {
  int v, nd, dims[NC_MAX_VAR_DIMS];
  size_t len, total = 1;
  if (nc_inq_varid(g, name, &v) || nc_inq_var(g, v, NULL, NULL, &nd, dims, NULL)) return 1;
  for (int i = 0; i < nd; i++) {
    if (nc_inq_dimlen(g, dims[i], &len)) return 1;
    total *= len;
  }
  if (total != n || (n && nc_get_var_double(g, v, out) != NC_NOERR)) return 1;
  for (size_t i = 0; i < n; i++)
    if (out[i] == NCOUT_FILL) out[i] = NAN;
  return 0;
}
