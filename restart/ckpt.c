/** @file ckpt.c @brief Implementation of ckpt.h (serial and parallel HDF5). */
#include "ckpt.h"
#include "alloc.h"

#include <errno.h>
#include <hdf5.h>
#include <mpi.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "durable.h"
#include "error.h"

/** Identity of the run (ckpt_set_run_id), written into every file; "" = none. */
static char run_id[CKPT_RUN_ID_MAX];

void ckpt_set_run_id(const char *id) {
  snprintf(run_id, sizeof run_id, "%s", id ? id : "");
}

/** Largest chunk [bytes]: Fletcher32 covers each chunk; HDF5 needs chunks below 4 GB. */
enum { CHUNK_BYTES = 1 << 22 };

/* Innermost HDF5 error message (the most specific one) of the current error stack. */
static herr_t walk_cb(unsigned n, const H5E_error2_t *e, void *data) {
  char *buf = data;
  if (n == 0 && e->desc) snprintf(buf, 512, "%s", e->desc);
  return 0;
}

static const char *h5_error(char *buf) {
  buf[0] = '\0';
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk_cb, buf);
  if (!buf[0]) snprintf(buf, 512, "unknown HDF5 error");
  return buf;
}

static void fail(char *err, size_t errlen, const char *fmt, ...) {
  char h5[512];
  char what[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  h5_error(h5);
  if (strcmp(h5, "unknown HDF5 error"))
    snprintf(err, errlen, "%s (HDF5: %s)", what, h5);
  else
    snprintf(err, errlen, "%s", what);
}

static hid_t mem_type(enum state_type t) {
  switch (t) {
    case STATE_F64:
      return H5T_NATIVE_DOUBLE;
    case STATE_I64:
      return H5T_NATIVE_INT64;
    case STATE_I32:
      return H5T_NATIVE_INT32;
    case STATE_U8:
      return H5T_NATIVE_UINT8;
    case STATE_TEXT:
      break;
  }
  return -1;
}

static hid_t file_type(enum state_type t) {
  switch (t) {
    case STATE_F64:
      return H5T_IEEE_F64LE;
    case STATE_I64:
      return H5T_STD_I64LE;
    case STATE_I32:
      return H5T_STD_I32LE;
    case STATE_U8:
      return H5T_STD_U8LE;
    case STATE_TEXT:
      break;
  }
  return -1;
}

static const char *type_name(enum state_type t) {
  static const char *const names[] = {"64-bit float", "64-bit integer", "string", "32-bit integer",
                                      "8-bit unsigned integer"};
  return names[t];
}

static size_t type_size(enum state_type t) {
  static const size_t sizes[] = {8, 8, 1, 4, 1};
  return sizes[t];
}

/* Elements of a field in the file (all rows of a distributed field). */
static size_t file_count(const struct state_field *f) {
  size_t n = 1;
  for (int i = 0; i < f->rank; i++) n *= i == 0 && f->total ? f->total : f->dims[i];
  return n;
}

/* Rows of a chunk of a field whose rows weigh row bytes: at most CHUNK_BYTES (write_field). */
static size_t chunk_rows(const struct state_field *f, size_t row) {
  const size_t n0 = f->rank ? (f->total ? f->total : f->dims[0]) : 1;
  const size_t rows = CHUNK_BYTES / (row ? row : 1);
  return n0 > rows ? (rows ? rows : 1) : n0;
}

size_t ckpt_state_bytes(const struct state_list *L) {
  size_t b = 0;
  for (int i = 0; i < L->n; i++) {
    const struct state_field *f = &L->f[i];
    if (f->type == STATE_TEXT) {
      b += strlen(*(char **)f->data) + 1 + 4;
      continue;
    }
    const size_t n = file_count(f), n0 = f->rank ? (f->total ? f->total : f->dims[0]) : 1;
    if (n == 0) continue;
    const size_t row = n / n0 * type_size(f->type), c = chunk_rows(f, row);
    b += (n0 + c - 1) / c * (c * row + 4); /* whole chunks, each with its Fletcher32 sum */
  }
  return b;
}

static int put_attr_text(hid_t obj, const char *name, const char *text) {
  const hid_t t = H5Tcopy(H5T_C_S1);
  CHECK_H5(H5Tset_size(t, strlen(text) + 1));
  CHECK_H5(H5Tset_strpad(t, H5T_STR_NULLTERM));
  const hid_t sp = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t rc = a < 0 ? -1 : H5Awrite(a, t, text);
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp), H5Tclose(t);
  return rc < 0 ? -1 : 0;
}

static int put_attr_num(hid_t obj, const char *name, hid_t ftype, hid_t mtype, const void *v) {
  const hid_t sp = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(obj, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t rc = a < 0 ? -1 : H5Awrite(a, mtype, v);
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp);
  return rc < 0 ? -1 : 0;
}

/* Create the groups on the way to a dataset name ("a/b/c": a and a/b), without timestamps. */
static int make_parents(hid_t file, const char *name, hid_t gcpl) {
  char path[128];
  for (const char *s = strchr(name, '/'); s; s = strchr(s + 1, '/')) {
    snprintf(path, sizeof path, "%.*s", (int)(s - name), name);
    const htri_t ex = H5Lexists(file, path, H5P_DEFAULT);
    if (ex < 0) return -1;
    if (!ex) {
      const hid_t g = H5Gcreate2(file, path, H5P_DEFAULT, gcpl, H5P_DEFAULT);
      if (g < 0) return -1;
      H5Gclose(g);
    }
  }
  return 0;
}

/* Close an HDF5 object without clearing the error stack of a failed call before it (every
   successful API call clears it; fail() reports its innermost message). */
static void close_keeping_errors(hid_t id, herr_t (*close)(hid_t)) {
  const hid_t stack = H5Eget_current_stack();
  close(id);
  if (stack >= 0) H5Eset_current_stack(stack);
}

/* Write this rank's part of a dataset collectively (parallel HDF5): the rows of a distributed
   field, all of a replicated field on rank 0, nothing on the other ranks. */
static herr_t write_part(hid_t ds, hid_t mtype, hid_t fsp, int rank, const hsize_t *start,
                         const hsize_t *count, int mine, const void *buf) {
  const hsize_t one[STATE_MAX_RANK] = {1, 1, 1};
  const hid_t msp = H5Screate_simple(rank, mine ? count : one, NULL);
  herr_t rc = 0;
  if (mine)
    rc = H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, count, NULL);
  else
    rc = H5Sselect_none(fsp) < 0 || H5Sselect_none(msp) < 0 ? -1 : 0;
  const hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
  CHECK_H5(H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE)); /* filtered (Fletcher32) writes need it */
  if (rc >= 0) rc = H5Dwrite(ds, mtype, msp, fsp, dxpl, buf);
  close_keeping_errors(dxpl, H5Pclose);
  close_keeping_errors(msp, H5Sclose);
  return rc;
}

/* One dataset: chunked, Fletcher32; scalars and strings as one-element 1-D datasets. A
   distributed field is stored with its total rows. par: parallel file, every rank calls. */
static int write_field(hid_t file, const struct state_field *f, hid_t gcpl, int par, int me) {
  if (make_parents(file, f->name, gcpl)) return -1;
  hsize_t dims[STATE_MAX_RANK] = {1}, chunk[STATE_MAX_RANK] = {1};
  hsize_t start[STATE_MAX_RANK] = {0}, count[STATE_MAX_RANK] = {1};
  int rank = f->rank ? f->rank : 1;
  size_t row = type_size(f->type), n = 1;
  for (int i = 0; i < f->rank; i++) {
    dims[i] = chunk[i] = count[i] = f->dims[i];
    if (i == 0 && f->total) dims[0] = chunk[0] = f->total, start[0] = f->offset;
    n *= dims[i];
    if (i > 0) row *= f->dims[i];
  }
  if (!par && f->total && (f->offset || f->dims[0] != f->total)) return -1; /* not all rows */
  hid_t ftype = -1, mtype = -1;
  const void *buf = f->data;
  if (f->type == STATE_TEXT) {
    const char *text = *(char *const *)f->data;
    ftype = H5Tcopy(H5T_C_S1);
    CHECK_H5(H5Tset_size(ftype, strlen(text) + 1));
    CHECK_H5(H5Tset_strpad(ftype, H5T_STR_NULLTERM));
    mtype = ftype, buf = text, rank = 1, dims[0] = chunk[0] = count[0] = 1, n = 1;
  } else {
    ftype = file_type(f->type), mtype = mem_type(f->type);
  }
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  CHECK_H5(H5Pset_obj_track_times(dcpl, 0));
  if (n > 0) {
    chunk[0] = chunk_rows(f, row);
    CHECK_H5(H5Pset_chunk(dcpl, rank, chunk));
    CHECK_H5(H5Pset_fletcher32(dcpl));
    /* parallel HDF5 allocates chunks when the dataset is created: no fill-value writes */
    if (par) H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER);
  }
  const hid_t sp = H5Screate_simple(rank, dims, NULL);
  const hid_t ds = H5Dcreate2(file, f->name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  herr_t rc = ds < 0 ? -1 : 0;
  if (rc == 0 && n > 0 && !par) rc = H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
  if (rc == 0 && n > 0 && par) {
    const int mine = f->total ? count[0] > 0 : me == 0;
    rc = write_part(ds, mtype, sp, rank, start, count, mine, buf);
  }
  if (rc == 0 && f->units) rc = put_attr_text(ds, "units", f->units);
  if (rc == 0 && f->rank == 0) {
    const int32_t scalar = 1; /* stored as shape (1,), read back as a scalar */
    rc = put_attr_num(ds, "scalar", H5T_STD_I32LE, H5T_NATIVE_INT32, &scalar);
  }
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(sp), H5Pclose(dcpl);
  if (f->type == STATE_TEXT) H5Tclose(ftype);
  return rc < 0 ? -1 : 0;
}

int ckpt_agree(int rc, char *err, size_t errlen) {
  return durable_agree(rc, err, errlen);
}

/* Serial (par = 0): the file is built in memory (HDF5 core driver) and written to disk when it
   is closed: one large write, and a full disk or a file-size limit fails cleanly in H5Fclose
   (with the sec2 driver, HDF5 1.10 crashes at exit after a failed close).
   Parallel (par = 1, every rank of MPI_COMM_WORLD calls): the MPI-IO driver, the same metadata
   calls on every rank (collective metadata operations and writes), collective raw-data writes of
   each rank's rows; after every dataset the ranks agree on the outcome, so a failure on one rank
   stops them all at the same call. Rank 0 then fsyncs, renames and fsyncs the directory. */
/* Where write_file() is: the file for the messages, this rank, and the error text. */
struct wctx {
  const char *noun, *tmp; /* "checkpoint" or "snapshot"; the temporary file */
  int par, me;            /* collective write; this rank */
  char *err;
  size_t errlen;
};

/* What a checkpoint of a list weighs on disk, at least: its data in whole chunks, the scene and
   room for the metadata (4 kB a dataset, 1 MB). The in-memory image starts at this size: the
   core driver grows an image by whole increments, zero-filled, so an image that does not fit
   would double the memory a checkpoint takes. */
static size_t file_bytes(const struct state_list *L, const char *scene) {
  return ckpt_state_bytes(L) + (scene ? strlen(scene) : 0) + 4096 * (size_t)(L->n + 1) +
         ((size_t)1 << 20);
}

/* The file access properties: MPI-IO for a collective write, else one in-memory image of the
   whole file (file_bytes), written on close. */
static hid_t file_access(const struct state_list *L, const char *scene, int par) {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  CHECK_H5(H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_V18)); /* checksummed metadata */
  if (par) {
    CHECK_H5(H5Pset_fapl_mpio(fapl, MPI_COMM_WORLD, MPI_INFO_NULL));
    CHECK_H5(H5Pset_all_coll_metadata_ops(fapl, 1));
    CHECK_H5(H5Pset_coll_metadata_write(fapl, 1));
  } else {
    CHECK_H5(H5Pset_fapl_core(fapl, file_bytes(L, scene), 1));
  }
  return fapl;
}

/* The root attributes, the scene, every field and, last, the completion mark; 1 on failure
   (the ranks agree after each part). */
static int write_content(hid_t file, hid_t gcpl, const char *format, const struct state_list *L,
                         const char *scene, long step, double time, const struct wctx *w) {
  char *err = w->err;
  const size_t errlen = w->errlen;
  int rc = 0;
  const int64_t step64 = step;
  const int32_t major = CKPT_VERSION_MAJOR, minor = CKPT_VERSION_MINOR;
  if (put_attr_text(file, "format", format) ||
      put_attr_num(file, "format_version_major", H5T_STD_I32LE, H5T_NATIVE_INT32, &major) ||
      put_attr_num(file, "format_version_minor", H5T_STD_I32LE, H5T_NATIVE_INT32, &minor) ||
      put_attr_text(file, "code_version", CHANSPH_VERSION) ||
      put_attr_num(file, "step", H5T_STD_I64LE, H5T_NATIVE_INT64, &step64) ||
      put_attr_num(file, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time) ||
      (run_id[0] && put_attr_text(file, "run_id", run_id))) {
    fail(err, errlen, "cannot write the root attributes of %s %s", w->noun, w->tmp);
    rc = 1;
  }
  if (w->par) rc = ckpt_agree(rc, err, errlen);
  char *scene_copy = (char *)scene;
  struct state_field sf = {.name = "scene", .type = STATE_TEXT, .data = &scene_copy};
  if (!rc && scene && write_field(file, &sf, gcpl, w->par, w->me)) {
    fail(err, errlen, "cannot write dataset /scene of %s %s", w->noun, w->tmp);
    rc = 1;
  }
  if (w->par) rc = ckpt_agree(rc, err, errlen);
  for (int i = 0; i < L->n && !rc; i++) {
    if (write_field(file, &L->f[i], gcpl, w->par, w->me)) {
      fail(err, errlen, "cannot write dataset /%s of %s %s", L->f[i].name, w->noun, w->tmp);
      rc = 1;
    }
    if (w->par) rc = ckpt_agree(rc, err, errlen);
  }
  const int32_t one = 1; /* written last: a file without it is incomplete */
  if (!rc && put_attr_num(file, "complete", H5T_STD_I32LE, H5T_NATIVE_INT32, &one)) {
    fail(err, errlen, "cannot write the completion mark of %s %s", w->noun, w->tmp);
    rc = 1;
  }
  if (w->par) rc = ckpt_agree(rc, err, errlen);
  return rc;
}

/* After the close: fsync the temporary file, rename it to path, fsync the directory (rank 0);
   on failure the temporary file is removed. */
static int commit_file(const char *path, int rc, const struct wctx *w) {
  if (w->me == 0 && !rc && durable_sync(w->tmp, 0)) {
    snprintf(w->err, w->errlen, "cannot fsync %s %s: %s", w->noun, w->tmp, strerror(errno));
    rc = 1;
  }
  if (w->me == 0 && !rc && rename(w->tmp, path)) {
    snprintf(w->err, w->errlen, "cannot rename %s to %s: %s", w->tmp, path, strerror(errno));
    rc = 1;
  }
  if (w->me == 0 && rc) remove(w->tmp);
  if (w->me == 0 && !rc) rc = durable_sync_dir(path, w->err, w->errlen);
  if (w->par) rc = ckpt_agree(rc, w->err, w->errlen);
  return rc;
}

static int write_file(const char *path, const char *format, const struct state_list *L,
                      const char *scene, long step, double time, int par, char *err,
                      size_t errlen) {
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  int me = 0;
  if (par) CHECK_MPI(MPI_Comm_rank(MPI_COMM_WORLD, &me));
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  /* what the messages call the file: "checkpoint", "snapshot" (chansph-<noun>) */
  const struct wctx w = {
      strncmp(format, "chansph-", 8) ? "file" : format + 8, tmp, par, me, err, errlen};
  const hid_t fcpl = H5Pcreate(H5P_FILE_CREATE), fapl = file_access(L, scene, par);
  const hid_t gcpl = H5Pcreate(H5P_GROUP_CREATE);
  CHECK_H5(H5Pset_obj_track_times(fcpl, 0));
  CHECK_H5(H5Pset_obj_track_times(gcpl, 0));
  if (par) { /* rank 0 makes sure it fits first (durable_probe) */
    if (ckpt_agree(me == 0 ? durable_probe(tmp, file_bytes(L, scene), w.noun, err, errlen) : 0, err,
                   errlen)) {
      H5Pclose(fcpl), H5Pclose(fapl), H5Pclose(gcpl);
      return 1;
    }
  }
  const hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, fcpl, fapl);
  H5Pclose(fcpl), H5Pclose(fapl);
  int rc = file < 0;
  if (rc) fail(err, errlen, "cannot write %s %s (%s)", w.noun, tmp, strerror(errno));
  if (par) rc = ckpt_agree(rc, err, errlen);
  if (rc) {
    H5Pclose(gcpl);
    if (file >= 0) H5Fclose(file);
    if (me == 0) remove(tmp);
    return 1;
  }
  rc = write_content(file, gcpl, format, L, scene, step, time, &w);
  H5Pclose(gcpl);
  if (H5Fclose(file) < 0 && !rc) {
    fail(err, errlen, "cannot write %s %s", w.noun, tmp);
    rc = 1;
  }
  if (par) rc = ckpt_agree(rc, err, errlen);
  return commit_file(path, rc, &w);
}

int ckpt_write_fields(const char *path, const char *format, const struct state_list *L,
                      const char *scene, long step, double time, char *err, size_t errlen) {
  return write_file(path, format, L, scene, step, time, 0, err, errlen);
}

int ckpt_write(const char *path, const struct state_list *L, const char *scene, long step,
               double time, char *err, size_t errlen) {
  return write_file(path, CKPT_FORMAT, L, scene, step, time, 0, err, errlen);
}

int ckpt_write_fields_all(const char *path, const char *format, const struct state_list *L,
                          const char *scene, long step, double time, char *err, size_t errlen) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return write_file(path, format, L, scene, step, time, size > 1, err, errlen);
}

int ckpt_write_all(const char *path, const struct state_list *L, const char *scene, long step,
                   double time, char *err, size_t errlen) {
  return ckpt_write_fields_all(path, CKPT_FORMAT, L, scene, step, time, err, errlen);
}

static int get_attr_int(hid_t obj, const char *name, hid_t mtype, void *v) {
  if (H5Aexists(obj, name) <= 0) return -1;
  const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return -1;
  const herr_t rc = H5Aread(a, mtype, v);
  H5Aclose(a);
  return rc < 0 ? -1 : 0;
}

static int get_attr_text(hid_t obj, const char *name, char *buf, size_t n) {
  if (H5Aexists(obj, name) <= 0) return -1;
  const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return -1;
  const hid_t ft = H5Aget_type(a);
  int rc = -1;
  if (H5Tget_class(ft) == H5T_STRING && !H5Tis_variable_str(ft)) {
    const size_t sz = H5Tget_size(ft);
    char *tmp = mem_calloc(sz + 1, 1, "checkpoint");
    const hid_t mt = H5Tcopy(H5T_C_S1);
    CHECK_H5(H5Tset_size(mt, sz));
    if (tmp && H5Aread(a, mt, tmp) >= 0) {
      snprintf(buf, n, "%s", tmp);
      rc = 0;
    }
    H5Tclose(mt);
    free(tmp);
  }
  H5Tclose(ft), H5Aclose(a);
  return rc;
}

/* Open a dataset by path, naming the first missing component. */
static hid_t open_dataset(hid_t file, const char *name, const char *path, char *err,
                          size_t errlen) {
  char part[128];
  for (const char *s = strchr(name, '/');; s = strchr(s + 1, '/')) {
    const int len = s ? (int)(s - name) : (int)strlen(name);
    snprintf(part, sizeof part, "%.*s", len, name);
    const htri_t ex = H5Lexists(file, part, H5P_DEFAULT);
    if (ex <= 0) {
      if (ex < 0)
        fail(err, errlen, "%s: cannot look up /%s", path, part);
      else if (s)
        snprintf(err, errlen, "%s: group /%s is missing (needed for dataset /%s)", path, part,
                 name);
      else
        snprintf(err, errlen, "%s: dataset /%s is missing", path, name);
      return -1;
    }
    if (!s) break;
  }
  const hid_t ds = H5Dopen2(file, name, H5P_DEFAULT);
  if (ds < 0) fail(err, errlen, "%s: cannot open dataset /%s", path, name);
  return ds;
}

/* 1 if every component of a path exists (a dataset of an earlier format may not). */
static int link_exists(hid_t file, const char *name) {
  char part[128];
  for (const char *s = strchr(name, '/');; s = strchr(s + 1, '/')) {
    const int len = s ? (int)(s - name) : (int)strlen(name);
    snprintf(part, sizeof part, "%.*s", len, name);
    if (H5Lexists(file, part, H5P_DEFAULT) <= 0) return 0;
    if (!s) return 1;
  }
}

/* Read a string dataset (shape (1,), fixed length) into a malloc'd string. */
static char *read_text(hid_t file, const char *name, const char *path, char *err, size_t errlen) {
  const hid_t ds = open_dataset(file, name, path, err, errlen);
  if (ds < 0) return NULL;
  const hid_t ft = H5Dget_type(ds);
  char *text = NULL;
  if (H5Tget_class(ft) != H5T_STRING || H5Tis_variable_str(ft)) {
    snprintf(err, errlen, "%s: dataset /%s is not a fixed-length string", path, name);
  } else {
    const size_t sz = H5Tget_size(ft);
    text = mem_calloc(sz + 1, 1, "checkpoint");
    const hid_t mt = H5Tcopy(H5T_C_S1);
    CHECK_H5(H5Tset_size(mt, sz));
    if (!text || H5Dread(ds, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, text) < 0) {
      fail(err, errlen, "%s: cannot read dataset /%s (checksum or data error)", path, name);
      free(text);
      text = NULL;
    }
    H5Tclose(mt);
  }
  H5Tclose(ft), H5Dclose(ds);
  return text;
}

static hid_t open_file(const char *path, char *err, size_t errlen) {
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  struct stat st;
  if (stat(path, &st)) {
    snprintf(err, errlen, "%s: cannot open checkpoint: %s", path, strerror(errno));
    return -1;
  }
  const hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) fail(err, errlen, "%s: cannot open as HDF5 (truncated or corrupt)", path);
  return file;
}

int ckpt_info(const char *path, struct ckpt_info *info, char *err, size_t errlen) {
  memset(info, 0, sizeof *info);
  const hid_t file = open_file(path, err, errlen);
  if (file < 0) return 1;
  struct stat st;
  if (!stat(path, &st)) info->n_bytes = (size_t)st.st_size;
  char format[128];
  int rc = 1;
  int32_t major = 0, minor = 0, complete = 0;
  int64_t step = 0;
  const htri_t has_format = H5Aexists(file, "format");
  if (has_format < 0) /* the root group's header does not read: its checksum, or damage */
    fail(err, errlen,
         "%s: cannot read the root group's attributes (metadata checksum mismatch or corrupt "
         "file)",
         path);
  else if (has_format == 0)
    snprintf(err, errlen, "%s: not a chansph checkpoint (no root attribute 'format')", path);
  else if (get_attr_text(file, "format", format, sizeof format))
    fail(err, errlen, "%s: cannot read root attribute 'format' (checksum mismatch or corrupt file)",
         path);
  else if (strcmp(format, CKPT_FORMAT))
    snprintf(err, errlen,
             "%s: not a chansph checkpoint (root attribute 'format' is '%.64s', not '%s')", path,
             format, CKPT_FORMAT);
  else if (get_attr_int(file, "format_version_major", H5T_NATIVE_INT32, &major) ||
           get_attr_int(file, "format_version_minor", H5T_NATIVE_INT32, &minor))
    snprintf(err, errlen, "%s: no readable format version (root attributes format_version_*)",
             path);
  else if (major > CKPT_VERSION_MAJOR)
    snprintf(err, errlen,
             "%s: written in checkpoint format %d.%d by a newer chansph; this build (%s) reads "
             "format %d.x only: resume with a newer chansph",
             path, major, minor, CHANSPH_VERSION, CKPT_VERSION_MAJOR);
  else if (major < CKPT_VERSION_MAJOR)
    snprintf(err, errlen, "%s: checkpoint format %d.%d is older than %d.x and not supported", path,
             major, minor, CKPT_VERSION_MAJOR);
  else if (get_attr_int(file, "complete", H5T_NATIVE_INT32, &complete) || complete != 1)
    snprintf(err, errlen, "%s: incomplete checkpoint (no completion mark 'complete' = 1)", path);
  else if (get_attr_int(file, "step", H5T_NATIVE_INT64, &step) ||
           get_attr_int(file, "time", H5T_NATIVE_DOUBLE, &info->time))
    snprintf(err, errlen, "%s: root attributes 'step' or 'time' missing", path);
  else if (H5Aexists(file, "run_id") > 0 &&
           get_attr_text(file, "run_id", info->run_id, sizeof info->run_id))
    snprintf(err, errlen, "%s: root attribute 'run_id' cannot be read", path);
  else if ((info->scene = read_text(file, "scene", path, err, errlen)))
    rc = 0;
  info->step = (long)step, info->major = major, info->minor = minor;
  H5Fclose(file);
  return rc;
}

/* Check the stored type against the field's. */
static int type_matches(hid_t ft, enum state_type t) {
  const H5T_class_t c = H5Tget_class(ft);
  const size_t sz = H5Tget_size(ft);
  switch (t) {
    case STATE_F64:
      return c == H5T_FLOAT && sz == 8;
    case STATE_I64:
    case STATE_I32:
      return c == H5T_INTEGER && sz == type_size(t) && H5Tget_sign(ft) == H5T_SGN_2;
    case STATE_U8:
      return c == H5T_INTEGER && sz == 1 && H5Tget_sign(ft) == H5T_SGN_NONE;
    case STATE_TEXT:
      return c == H5T_STRING;
  }
  return 0;
}

static void shape_text(char *buf, size_t n, int rank, const size_t *dims) {
  int m = snprintf(buf, n, "(");
  for (int i = 0; i < rank && m < (int)n; i++)
    m += snprintf(buf + m, n - (size_t)m, "%s%zu", i ? ", " : "", dims[i]);
  if (m < (int)n) snprintf(buf + m, n - (size_t)m, rank == 1 ? ",)" : ")");
}

/* Read a field: all of it, or this rank's rows of a distributed field (independently). */
static herr_t read_rows(hid_t ds, const struct state_field *f, hid_t fsp, void *dst) {
  if (!f->total) return H5Dread(ds, mem_type(f->type), H5S_ALL, H5S_ALL, H5P_DEFAULT, dst);
  if (f->dims[0] == 0) return 0;
  hsize_t start[STATE_MAX_RANK] = {0}, count[STATE_MAX_RANK] = {0};
  for (int i = 0; i < f->rank; i++) count[i] = f->dims[i];
  start[0] = f->offset;
  const hid_t msp = H5Screate_simple(f->rank, count, NULL);
  herr_t rc = H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, count, NULL);
  if (rc >= 0) rc = H5Dread(ds, mem_type(f->type), msp, fsp, H5P_DEFAULT, dst);
  close_keeping_errors(msp, H5Sclose);
  return rc;
}

static int read_field(hid_t file, struct state_field *f, const char *path, char *err,
                      size_t errlen) {
  f->absent = f->optional && !link_exists(file, f->name);
  if (f->absent) return 0;
  if (f->type == STATE_TEXT) {
    char *text = read_text(file, f->name, path, err, errlen);
    if (!text) return 1;
    free(*(char **)f->data);
    *(char **)f->data = text;
    return 0;
  }
  const hid_t ds = open_dataset(file, f->name, path, err, errlen);
  if (ds < 0) return 1;
  int rc = 1;
  const hid_t ft = H5Dget_type(ds), sp = H5Dget_space(ds);
  hsize_t hd[STATE_MAX_RANK + 1] = {0};
  const int rank = H5Sget_simple_extent_ndims(sp);
  size_t dims[STATE_MAX_RANK] = {0};
  if (rank >= 1 && rank <= STATE_MAX_RANK) H5Sget_simple_extent_dims(sp, hd, NULL);
  for (int i = 0; i < rank && i < STATE_MAX_RANK; i++) dims[i] = (size_t)hd[i];
  const int want_rank = f->rank ? f->rank : 1;
  size_t want[STATE_MAX_RANK] = {1};
  for (int i = 0; i < f->rank; i++) want[i] = i == 0 && f->total ? f->total : f->dims[i];
  char have_s[96], want_s[96];
  if (!type_matches(ft, f->type)) {
    snprintf(err, errlen, "%s: dataset /%s has the wrong type (expected %s)", path, f->name,
             type_name(f->type));
  } else if (rank < 1 || rank > STATE_MAX_RANK) {
    snprintf(err, errlen, "%s: dataset /%s has rank %d (expected %d)", path, f->name, rank,
             want_rank);
  } else {
    void *dst = f->data;
    int same = rank == want_rank, reserved = 0;
    for (int i = 0; same && i < rank; i++) same = dims[i] == want[i];
    if (!same && f->reserve && !f->total && rank == f->rank) {
      dst = f->reserve(f->owner, rank, dims);
      if (dst) {
        f->data = dst, same = reserved = 1;
        for (int i = 0; i < rank; i++) f->dims[i] = dims[i];
      }
    }
    size_t n = 1;
    for (int i = 0; i < rank; i++) n *= dims[i];
    if (!same) {
      shape_text(have_s, sizeof have_s, rank, dims);
      shape_text(want_s, sizeof want_s, want_rank, want);
      snprintf(err, errlen,
               "%s: dataset /%s has shape %s, this run needs %s (a checkpoint of another scene?)",
               path, f->name, have_s, want_s);
    } else if (n > 0 && read_rows(ds, f, sp, dst) < 0) {
      fail(err, errlen, "%s: cannot read dataset /%s (checksum mismatch or corrupt data)", path,
           f->name);
    } else {
      rc = 0;
      if (reserved && f->after_read) f->after_read(f->owner, rank, dims);
    }
  }
  H5Sclose(sp), H5Tclose(ft), H5Dclose(ds);
  return rc;
}

/* A shape this build does not read in a file of an older minor format (its records grew
   since): say so, with the versions and the remedies, after the dataset's message in err. */
static void older_format(hid_t file, char *err, size_t errlen) {
  int major = 0, minor = 0;
  if (get_attr_int(file, "format_version_major", H5T_NATIVE_INT32, &major) ||
      get_attr_int(file, "format_version_minor", H5T_NATIVE_INT32, &minor) ||
      (major == CKPT_VERSION_MAJOR && minor >= CKPT_VERSION_MINOR))
    return;
  char *cut = strstr(err, " (a checkpoint of another scene?)");
  if (cut) *cut = '\0';
  const size_t n = strlen(err);
  snprintf(err + n, errlen - n,
           ": written in checkpoint format %d.%d, whose records this build (format %d.%d) does "
           "not read; finish the run with the chansph version that started it, or start a new "
           "segment from its state with init.from (docs/checkpoint-format.md)",
           major, minor, CKPT_VERSION_MAJOR, CKPT_VERSION_MINOR);
}

int ckpt_read(const char *path, struct state_list *L, char *err, size_t errlen) {
  const hid_t file = open_file(path, err, errlen);
  if (file < 0) return 1;
  int rc = 0;
  for (int i = 0; i < L->n && !rc; i++) rc = read_field(file, &L->f[i], path, err, errlen);
  if (rc && strstr(err, " has shape ")) older_format(file, err, errlen);
  if (H5Fclose(file) < 0 && !rc) {
    fail(err, errlen, "%s: error closing the file", path);
    rc = 1;
  }
  return rc;
}
