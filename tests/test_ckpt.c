/**
 * @file test_ckpt.c
 * @brief Unit test of the checkpoint file (restart/ckpt.c): a state list of every type and rank
 *        round-trips bitwise (a field sized on reading included); a write to a full disk
 *        (/dev/full) fails with the system's reason and leaves no file; a missing dataset and a
 *        wrong shape are named; the Lagrangian sums of a format 1.6 file (records without the
 *        sums of the displacements, the actual lags and the interval-mean velocities), of a
 *        format 1.8 file (without the last two) and of a 1.9 file (without the last) resume in
 *        the layout of format 1.10.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ckpt.h"
#include "lagr.h"
#include "state.h"

static int failures;

static void check(int ok, const char *what) {
  printf("%s: %s\n", ok ? "ok  " : "FAIL", what);
  if (!ok) failures++;
}

/** Memory for a growing field: one static buffer. */
static double grow[64];
static void *reserve(void *owner, int rank, const size_t *dims) {
  (void)owner;
  return rank == 2 && dims[0] * dims[1] <= 64 ? grow : NULL;
}

/* A checkpoint whose stats/lagrangian/sums and slot_sums have the records of an older format
   (w = LG_LEN_1_6 wide in format 1.6, LG_LEN_1_8 in 1.7-1.8, LG_LEN_1_9 in 1.9) is read by an
   engine of format 1.10: the stored sums as they were, the sums it lacks (of dr, of the actual
   lags, of the interval-mean velocities) NaN where a record has samples, 0 where not; a record of
   another width is refused, naming the file and the dataset. */
static void lagr_format_old(const char *dir, size_t w, const char *version) {
  char path[256], err[2048], what[160];
  snprintf(path, sizeof path, "%s/ckpt_lagr_old.h5", dir);
  const struct lagr_config cfg = {.n_levels = 1,
                                  .y = {0.5},
                                  .half = 0.05,
                                  .lx = 1.0,
                                  .delta = 1.0,
                                  .horizon = 1.0,
                                  .release_every = 1.0,
                                  .n_lags = 4,
                                  .pdf_bins = 4};
  struct lagr a, b;
  lagr_init(&a, &cfg), lagr_init(&b, &cfg);
  const size_t rows = a.nlag, srows = (size_t)a.n_slots * a.nlag;
  double old[64 * LG_LEN], sold[64 * LG_LEN];
  for (size_t i = 0; i < rows * w; i++) old[i] = 0.25 * (double)i + 1.0;
  for (size_t i = 0; i < srows * w; i++) sold[i] = (i / w) % 2 ? 0.0 : 0.5 * i + 1.0;
  a.releases = 3.0;
  struct state_list L = {0};
  lagr_state(&a, &L);
  struct state_field *f = state_find(&L, "stats/lagrangian/sums");
  f->data = old, f->dims[2] = w;
  f = state_find(&L, "stats/lagrangian/slot_sums");
  f->data = sold, f->dims[2] = w;
  snprintf(what, sizeof what, "write format %s sums (%zu per record)", version, w);
  check(ckpt_write(path, &L, "[domain]\n", 1, 0.0, err, sizeof err) == 0, what);
  struct state_list R = {0};
  lagr_state(&b, &R);
  const int rc = ckpt_read(path, &R, err, sizeof err);
  if (rc) printf("  %s\n", err);
  int same = 1, lack = 1;
  for (size_t r = 0; r < rows; r++) {
    same = same && !memcmp(b.sums + r * LG_LEN, old + r * w, w * 8);
    for (size_t i = w; i < LG_LEN; i++) lack = lack && isnan(b.sums[r * LG_LEN + i]);
  }
  for (size_t r = 0; r < srows; r++) {
    same = same && !memcmp(b.slot_sums + r * LG_LEN, sold + r * w, w * 8);
    for (size_t i = w; i < LG_LEN; i++) {
      const double s = b.slot_sums[r * LG_LEN + i];
      lack = lack && (r % 2 ? s == 0.0 : isnan(s));
    }
  }
  snprintf(what, sizeof what,
           "Lagrangian sums of format %s resume: stored sums kept, the %zu missing sums NaN (0 "
           "without samples)",
           version, (size_t)LG_LEN - w);
  check(rc == 0 && same && lack && b.releases == 3.0, what);
  state_free(&R);
  f = state_find(&L, "stats/lagrangian/sums");
  f->dims[2] = LG_LEN_1_6 + 1;
  check(ckpt_write(path, &L, "[domain]\n", 1, 0.0, err, sizeof err) == 0, "write a wrong width");
  lagr_state(&b, &R);
  check(ckpt_read(path, &R, err, sizeof err) != 0 && strstr(err, "ckpt_lagr_old.h5") &&
            strstr(err,
                   "dataset /stats/lagrangian/sums has shape (1, 5, 44), this run needs "
                   "(1, 5, 53)"),
        err);
  state_free(&L), state_free(&R);
  lagr_free(&a), lagr_free(&b);
  remove(path);
}

int main(void) {
  char dir[] = "/tmp/test_ckpt_XXXXXX";
  if (!mkdtemp(dir)) return 1;
  char path[256], err[2048];
  snprintf(path, sizeof path, "%s/ckpt_0000000007.h5", dir);

  double x[6] = {0.1, -2.5e-300, NAN, INFINITY, 1.0 / 3.0, -0.0}, t = 1.25, series[12];
  int64_t id[6] = {5, 4, 3, 2, 1, INT64_MAX};
  int32_t flag = -7;
  uint8_t kind[6] = {0, 1, 0, 1, 255, 0};
  long step = 7;
  char *text = strdup("[domain]\ndimension = 2\n");
  for (int i = 0; i < 12; i++) series[i] = i * 0.5;
  struct state_list L = {0};
  const size_t n6[1] = {6}, s34[2] = {4, 3};
  state_add(&L, "particles/x", STATE_F64, 1, n6, x, "m");
  state_add(&L, "particles/id", STATE_I64, 1, n6, id, NULL);
  state_add(&L, "particles/kind", STATE_U8, 1, n6, kind, NULL);
  state_add(&L, "a/b/c/flag", STATE_I32, 0, NULL, &flag, NULL);
  state_add(&L, "sim/step", STATE_I64, 0, NULL, &step, NULL);
  state_add(&L, "sim/time", STATE_F64, 0, NULL, &t, "s");
  state_add(&L, "notes", STATE_TEXT, 0, NULL, &text, NULL);
  state_add(&L, "stats/series", STATE_F64, 2, s34, series, NULL);
  check(ckpt_write(path, &L, "[domain]\n", 7, t, err, sizeof err) == 0, "write");
  struct ckpt_info info;
  check(ckpt_info(path, &info, err, sizeof err) == 0 && info.step == 7 && info.time == t &&
            info.major == CKPT_VERSION_MAJOR && !strcmp(info.scene, "[domain]\n"),
        "info: step, time, version, scene");
  free(info.scene);

  /* read into fresh memory */
  double x2[6];
  int64_t id2[6];
  uint8_t kind2[6];
  int32_t flag2 = 0;
  long step2 = 0;
  double t2 = 0;
  char *text2 = NULL;
  struct state_list R = {0};
  state_add(&R, "particles/x", STATE_F64, 1, n6, x2, "m");
  state_add(&R, "particles/id", STATE_I64, 1, n6, id2, NULL);
  state_add(&R, "particles/kind", STATE_U8, 1, n6, kind2, NULL);
  state_add(&R, "a/b/c/flag", STATE_I32, 0, NULL, &flag2, NULL);
  state_add(&R, "sim/step", STATE_I64, 0, NULL, &step2, NULL);
  state_add(&R, "sim/time", STATE_F64, 0, NULL, &t2, "s");
  state_add(&R, "notes", STATE_TEXT, 0, NULL, &text2, NULL);
  const size_t s03[2] = {0, 3};
  state_add(&R, "stats/series", STATE_F64, 2, s03, NULL, NULL)->reserve = reserve;
  const int rc = ckpt_read(path, &R, err, sizeof err);
  if (rc) printf("  %s\n", err);
  check(rc == 0, "read");
  check(!memcmp(x, x2, sizeof x) && !memcmp(id, id2, sizeof id) &&
            !memcmp(kind, kind2, sizeof kind) && flag2 == flag && step2 == step && t2 == t,
        "arrays and scalars bitwise equal (NaN, inf, -0 and tiny values included)");
  check(text2 && !strcmp(text, text2), "text");
  check(R.f[7].dims[0] == 4 && R.f[7].data == grow && !memcmp(grow, series, sizeof series),
        "field sized on reading: shape (4, 3) and data");

  /* a missing dataset and a wrong shape are named */
  struct state_list M = {0};
  state_add(&M, "stats/extra/sum", STATE_F64, 1, n6, x2, NULL);
  check(ckpt_read(path, &M, err, sizeof err) != 0 && strstr(err, "group /stats/extra is missing"),
        err);
  struct state_list S = {0};
  const size_t n5[1] = {5};
  state_add(&S, "particles/x", STATE_F64, 1, n5, x2, NULL);
  check(ckpt_read(path, &S, err, sizeof err) != 0 &&
            strstr(err, "dataset /particles/x has shape (6,), this run needs (5,)"),
        err);
  struct state_list T = {0};
  state_add(&T, "particles/id", STATE_F64, 1, n6, x2, NULL);
  check(ckpt_read(path, &T, err, sizeof err) != 0 &&
            strstr(err, "dataset /particles/id has the wrong type (expected 64-bit float)"),
        err);

  /* a full disk: the temporary name leads to /dev/full */
  char full[256], tmp[300];
  snprintf(full, sizeof full, "%s/ckpt_0000000008.h5", dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", full);
  if (symlink("/dev/full", tmp) == 0) {
    const int w = ckpt_write(full, &L, "[domain]\n", 8, t, err, sizeof err);
    printf("  %s\n", err);
    struct stat st;
    check(w != 0 && strstr(err, "No space left on device") && stat(full, &st) != 0 &&
              lstat(tmp, &st) != 0,
          "full disk: error with the reason, no checkpoint, no temporary file");
  }
  check(ckpt_info(path, &info, err, sizeof err) == 0, "the earlier checkpoint is intact");
  free(info.scene);
  lagr_format_old(dir, LG_LEN_1_6, "1.6");
  lagr_format_old(dir, LG_LEN_1_8, "1.8");
  lagr_format_old(dir, LG_LEN_1_9, "1.9");
  remove(path), rmdir(dir);
  state_free(&L), state_free(&R), state_free(&M), state_free(&S), state_free(&T);
  free(text), free(text2);
  printf("%s\n", failures ? "FAILED" : "PASS");
  return failures ? 1 : 0;
}
