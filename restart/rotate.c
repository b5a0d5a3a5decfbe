/**
 * @file rotate.c
 * @brief Where checkpoints live (DIR/checkpoints/ckpt_<step, 10 digits>.h5), writing one of
 *        the current run and keeping the newest checkpoint.keep of them.
 */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "alloc.h"
#include "ckpt.h"
#include "error.h"
#include "restart.h"
#include "rotate.h"
#include "timers.h"

void rotate_path(char *buf, size_t n, const char *dir, long step) {
  snprintf(buf, n, "%s/checkpoints/ckpt_%010ld.h5", dir, step);
}

/* Step of a checkpoint file name, or -1 if the name is not one. */
static long name_step(const char *name) {
  if (strncmp(name, "ckpt_", 5)) return -1;
  const char *p = name + 5;
  long step = 0;
  int digits = 0;
  for (; isdigit((unsigned char)*p); p++, digits++) step = 10 * step + (*p - '0');
  return digits > 0 && !strcmp(p, ".h5") ? step : -1;
}

static int cmp_long(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

int rotate_list(const char *dir, long **steps) {
  char path[4096];
  snprintf(path, sizeof path, "%s/checkpoints", dir);
  *steps = NULL;
  DIR *d = opendir(path);
  if (!d) return 0;
  int n = 0, cap = 0;
  for (struct dirent *e; (e = readdir(d));) {
    const long s = name_step(e->d_name);
    if (s < 0) continue;
    if (n == cap) {
      cap = cap ? 2 * cap : 16;
      long *t = mem_realloc(*steps, (size_t)cap, sizeof *t, "checkpoint list");
      *steps = t;
    }
    (*steps)[n++] = s;
  }
  closedir(d);
  if (n > 1) qsort(*steps, (size_t)n, sizeof **steps, cmp_long);
  return n;
}

int rotate_remove_tmp(const char *dir) {
  char path[4096];
  snprintf(path, sizeof path, "%s/checkpoints", dir);
  DIR *d = opendir(path);
  if (!d) return 0;
  int n = 0;
  for (struct dirent *e; (e = readdir(d));) {
    const size_t len = strlen(e->d_name);
    if (strncmp(e->d_name, "ckpt_", 5) || len < 8 || strcmp(e->d_name + len - 7, ".h5.tmp"))
      continue;
    char file[4400];
    snprintf(file, sizeof file, "%s/%s", path, e->d_name);
    if (!remove(file)) n++;
  }
  closedir(d);
  return n;
}

/* Whether the checkpoint of a step in dir is one of run id's (its root attribute run_id); an
   unreadable file or one of another run is not. */
static int own_checkpoint(const char *dir, long step, const char *id) {
  char path[4096], err[2048];
  rotate_path(path, sizeof path, dir, step);
  struct ckpt_info info;
  const int rc = ckpt_info(path, &info, err, sizeof err);
  free(info.scene);
  return rc == 0 && id[0] && !strcmp(info.run_id, id);
}

/* Delete the oldest checkpoints of run id at or before step, keeping keep of them. Files of
   another run (a directory deleted and recreated under a running process, a copied file) or
   unreadable ones are neither counted nor deleted. */
static void rotate_keep(const char *dir, long step, int keep, const char *id) {
  long *steps;
  const int n = rotate_list(dir, &steps);
  int older = 0;
  for (int i = 0; i < n; i++) {
    if (steps[i] <= step && own_checkpoint(dir, steps[i], id))
      older++;
    else
      steps[i] = -1; /* not a candidate */
  }
  for (int i = 0; i < n && older > keep; i++) {
    if (steps[i] < 0) continue;
    char path[4096];
    rotate_path(path, sizeof path, dir, steps[i]);
    if (remove(path)) warn("%s: cannot remove an old checkpoint (%s)", path, strerror(errno));
    older--;
  }
  free(steps);
}

double restart_state_bytes(struct output *o, struct sim *S) {
  struct state_list L = {0};
  sim_state(S, &L);
  output_state(o, &L);
  const double b = (double)ckpt_state_bytes(&L);
  state_free(&L);
  return b;
}

int restart_save(struct output *o, struct sim *S, double *seconds) {
  const double t0 = timer_now();
  timer_push("checkpoint");
  char path[4096], err[2048];
  int rank = 0, rc = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  snprintf(path, sizeof path, "%s/checkpoints", o->dir);
  if (rank == 0 && mkdir(path, 0777) && errno != EEXIST) {
    error_input("%s: cannot create the checkpoint directory (%s)", path, strerror(errno));
    rc = 1;
  }
  CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
  if (rc) {
    timer_pop();
    return CHANSPH_ERR;
  }
  /* sim_state sends the particles to the ranks of their id blocks; every rank writes its
     block (parallel HDF5 on several ranks) and learns the outcome */
  struct state_list L = {0};
  sim_state(S, &L);
  output_state(o, &L);
  rotate_path(path, sizeof path, o->dir, S->step);
  rc = ckpt_write_all(path, &L, o->scene_text, S->step, S->t, err, sizeof err);
  state_free(&L);
  timer_pop();
  *seconds = timer_now() - t0;
  CHECK_MPI(MPI_Bcast(seconds, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD));
  if (rc) {
    error_input("%s", err);
    if (o->log) fprintf(o->log, "error: %s\n", err), fflush(o->log);
    return CHANSPH_ERR;
  }
  struct stat st;
  const double mb = stat(path, &st) ? 0.0 : (double)st.st_size / 1048576.0;
  output_log(o, "checkpoint %s (step %ld, %.2f MB, %.3f s)\n", path, S->step, mb, *seconds);
  if (rank == 0) rotate_keep(o->dir, S->step, S->sc->ckpt_keep, o->run_id);
  return CHANSPH_OK;
}

/* Snapshots of an earlier run: refused, or removed with --overwrite (with their index). */
static int remove_snapshots(const char *dir, int overwrite) {
  char path[4096];
  snprintf(path, sizeof path, "%s/snapshots", dir);
  DIR *d = opendir(path);
  if (!d) return CHANSPH_OK;
  int rc = CHANSPH_OK;
  for (struct dirent *e; (e = readdir(d)) && rc == CHANSPH_OK;) {
    if (strncmp(e->d_name, "snap_", 5) && strcmp(e->d_name, "particles.xdmf")) continue;
    char file[4400];
    snprintf(file, sizeof file, "%s/%s", path, e->d_name);
    if (!overwrite) {
      error_input(
          "%s: the output directory holds snapshots of an earlier run; choose another "
          "--out DIR or pass --overwrite",
          file);
      rc = CHANSPH_ERR;
    } else if (remove(file)) {
      error_input("%s: cannot remove (%s)", file, strerror(errno));
      rc = CHANSPH_ERR;
    }
  }
  closedir(d);
  return rc;
}

static int prepare_new(const char *dir, int overwrite) {
  long *steps;
  const int n = rotate_list(dir, &steps);
  int rc = CHANSPH_OK;
  if (n > 0 && !overwrite) {
    error_input(
        "%s/checkpoints holds %d checkpoint(s) of an earlier run (newest: step %ld); continue "
        "it with `chansph resume %s`, or pass --overwrite to start again",
        dir, n, steps[n - 1], dir);
    rc = CHANSPH_ERR;
  }
  for (int i = 0; i < n && rc == CHANSPH_OK; i++) {
    char path[4096];
    rotate_path(path, sizeof path, dir, steps[i]);
    if (remove(path)) {
      error_input("%s: cannot remove (%s)", path, strerror(errno));
      rc = CHANSPH_ERR;
    }
  }
  free(steps);
  if (rc == CHANSPH_OK) rotate_remove_tmp(dir);
  return rc == CHANSPH_OK ? remove_snapshots(dir, overwrite) : rc;
}

int restart_prepare_new(const char *dir, int overwrite) {
  int rank = 0, rc = CHANSPH_OK;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) rc = prepare_new(dir, overwrite); /* the files are rank 0's to touch */
  CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
  return rc;
}
