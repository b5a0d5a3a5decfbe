/**
 * @file resume.c
 * @brief Resume a run from its newest valid checkpoint, falling back to older ones, and check
 *        which scene keys a resume may change.
 */
#include <errno.h>
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "alloc.h"
#include "ckpt.h"
#include "error.h"
#include "euler.h"
#include "init.h"
#include "restart.h"
#include "rotate.h"
#include "timers.h"

/** Keys a resume may change (docs/batch-jobs.md); every other key is refused. */
static const char *const changeable[] = {"time.t_end",
                                         "time.max_steps",
                                         "output.log_every",
                                         "output.series_every",
                                         "output.stats_every",
                                         "output.write_every",
                                         "output.t_average_start",
                                         "stats.window",
                                         "stats.target_stderr",
                                         "stats.target_profiles",
                                         "stats.target_corr_ratio",
                                         "stats.target_windows",
                                         "output.particles",
                                         "health.every",
                                         "sph.wall_collision",
                                         "run.threads",
                                         "run.balance_every",
                                         "run.balance_threshold",
                                         "run.check_ids",
                                         "run.ranks",
                                         "run.partition",
                                         "checkpoint.every_steps",
                                         "checkpoint.every_minutes",
                                         "checkpoint.keep",
                                         "snapshots.every"};
enum { N_CHANGEABLE = sizeof changeable / sizeof changeable[0] };

static int is_changeable(const char *key) {
  for (int i = 0; i < N_CHANGEABLE; i++)
    if (!strcmp(changeable[i], key)) return 1;
  return 0;
}

/* Compare the scene of the checkpoint with the requested one; refuse forbidden changes. */
static int check_changes(const struct scene *old, const struct scene *now, const char *path) {
  int bad = 0;
  for (int k = 0; k < scene_key_count(); k++) {
    char name[64], a[SCENE_VALUE_MAX], b[SCENE_VALUE_MAX];
    scene_key(old, k, name, a);
    scene_key(now, k, name, b);
    if (!strcmp(a, b) || is_changeable(name)) continue;
    error_input(
        "--set %s=%s: key '%s' cannot change on resume (the checkpoint %s has %s): a change "
        "of the domain, resolution, particle count or physics would make the continuation "
        "meaningless; start a new run instead (keys a resume may change: docs/batch-jobs.md)",
        name, b, name, path, a);
    bad++;
  }
  return bad ? CHANSPH_ERR : CHANSPH_OK;
}

/* output.t_average_start may change only before averaging has begun, and not into the past of
   the checkpoint: otherwise the windows would differ in length and the standard errors would
   mix them (issue 13). t: time of the checkpoint. */
static int check_average_start(const struct scene *old, const struct scene *now, double t,
                               const char *path) {
  const double a = old->t_average_start, b = now->t_average_start;
  if (a == b) return CHANSPH_OK;
  if (t >= a) {
    error_input(
        "--set output.t_average_start=%g: key 'output.t_average_start' cannot change on resume "
        "once averaging has begun (the checkpoint %s is at t = %.9g s, averaging began at "
        "%g s): the averaging windows would differ in length; keep %g, or start a new run",
        b, path, t, a, a);
    return CHANSPH_ERR;
  }
  if (b < t) {
    error_input(
        "--set output.t_average_start=%g: key 'output.t_average_start' is before the time of "
        "the checkpoint %s (t = %.9g s): the samples since %g s were not taken; choose a start "
        "at or after %.9g s",
        b, path, t, b, t);
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

/* stats.window may change only before averaging has begun: the windows already averaged
   have the old length, and their means are the batches of the standard errors. t: time of the
   checkpoint. */
static int check_window(const struct scene *old, const struct scene *now, double t,
                        const char *path) {
  const double was = scene_stats_num(old, &euler_key_window);
  const double is = scene_stats_num(now, &euler_key_window);
  if (was == is || t < old->t_average_start) return CHANSPH_OK;
  error_input(
      "--set stats.window=%g: key 'stats.window' cannot change on resume once averaging has "
      "begun (the checkpoint %s is at t = %.9g s, averaging began at %g s): the averaging "
      "windows would differ in length; keep %g, or start a new run",
      is, path, t, old->t_average_start, was);
  return CHANSPH_ERR;
}

/* Once averaging has begun, the windows keep the length they have (output/window_length of the
   checkpoint; before format 1.5, the length the checkpoint's scene gives), whatever a new
   time.t_end would give; before, the resumed scene's length. t: time of the checkpoint. */
static void keep_window(struct output *o, const struct scene *old, double t) {
  const double fresh = output_stats_window(o, NULL); /* the resumed scene's */
  double len = o->window_len;
  if (t < old->t_average_start) {
    len = fresh;
  } else if (!(len > 0.0)) {
    len = output_stats_window(o, old);
  }
  output_set_window(o, len);
  if (len != fresh)
    output_log(o,
               "resume: the averaging windows keep their length %.9g s (fixed once averaging "
               "has begun; the resumed scene alone would give %.9g s)\n",
               len, fresh);
}

/* A run that ended at its convergence target stays finished, as one that reached t_end does,
   unless the resume changes the target (then it is evaluated again when a window closes). */
static void keep_converged(struct output *o, const struct scene *old, const struct scene *now,
                           long step) {
  if (!o->converged) return;
  static const struct scene_key_def *const target[] = {
      &euler_key_target_stderr, &euler_key_target_profiles, &euler_key_target_corr_ratio,
      &euler_key_target_windows};
  int same = 1;
  for (int i = 0; i < 4; i++)
    same &= scene_stats_num(old, target[i]) == scene_stats_num(now, target[i]);
  if (same) {
    output_log(o,
               "resume: the run ended at step %ld when its statistics met stats.target_stderr = "
               "%g: it stays finished (to go on, change the convergence target, e.g. --set "
               "stats.target_stderr=...)\n",
               step, scene_stats_num(old, &euler_key_target_stderr));
    return;
  }
  o->converged = 0;
  output_log(o, "resume: the convergence target changed: the run goes on\n");
}

/* Log the accepted changes. */
static void log_changes(struct output *o, const struct scene *old, const struct scene *now) {
  for (int k = 0; k < scene_key_count(); k++) {
    char name[64], a[SCENE_VALUE_MAX], b[SCENE_VALUE_MAX];
    scene_key(old, k, name, a);
    scene_key(now, k, name, b);
    if (strcmp(a, b)) output_log(o, "resume: %s changed from %s to %s\n", name, a, b);
  }
}

/** Files passed over, with the reason. */
struct skipped {
  int n;
  char path[16][4096];
  char why[16][2048];
};

static void skip(struct skipped *sk, const char *path, const char *why) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) warn("%s; skipping this checkpoint", why); /* every rank agrees (ckpt_agree) */
  if (sk->n < 16) {
    snprintf(sk->path[sk->n], sizeof sk->path[0], "%s", path);
    snprintf(sk->why[sk->n], sizeof sk->why[0], "%s", why);
    sk->n++;
  }
}

/* The candidate's identity: the step its name says, and the run of the directory ("": the
   directory has no run_id). */
struct candidate {
  const char *path;
  long name_step;
  const char *dir_id;
  char run_id[CKPT_RUN_ID_MAX]; /* the file's identity, once read */
};

/* Read the candidate's header (info) and check its identity: readable, the step its name says,
   the directory's run. Returns 1 with the reason in err if the file is to be skipped. */
static int check_identity(const char *dir, const struct candidate *cd, struct ckpt_info *ip,
                          char *err, size_t errlen) {
  const char *path = cd->path;
  struct ckpt_info info;
  int bad_file = ckpt_agree(ckpt_info(path, &info, err, errlen), err, errlen);
  if (!bad_file && info.step != cd->name_step) {
    snprintf(err, errlen,
             "%.1900s: the file name says step %ld but the checkpoint holds step %ld (a renamed "
             "or copied file)",
             path, cd->name_step, info.step);
    bad_file = 1;
  } else if (!bad_file && cd->dir_id[0] && strcmp(info.run_id, cd->dir_id)) {
    if (info.run_id[0])
      snprintf(err, errlen,
               "%.1900s: a checkpoint of another run (run_id %s; this directory's run is %s, "
               "see %s/run_id)",
               path, info.run_id, cd->dir_id, dir);
    else
      snprintf(err, errlen,
               "%.1900s: a checkpoint without a run identity (format %d.%d) in the directory "
               "of run %s",
               path, info.major, info.minor, cd->dir_id);
    bad_file = 1;
  }
  *ip = info;
  return bad_file;
}

/* The statistics datasets (stats/...) the checkpoint lacked, being of an earlier format: what
   they accumulate starts at this resume (the Reynolds-stress budgets, before format 1.6, cover
   only the windows after it). Said in the log and kept in o->resumed_without (the global
   attribute resumed_without of stats.nc, and checkpointed, so that later resumes keep it). */
static void note_absent(struct output *o, const struct state_list *L, const char *path, double t) {
  char list[1024] = "";
  size_t m = 0;
  for (int i = 0; i < L->n && m < sizeof list; i++)
    if (L->f[i].absent && !strncmp(L->f[i].name, "stats/", 6))
      m += (size_t)snprintf(list + m, sizeof list - m, "%s%s", m ? ", " : "", L->f[i].name);
  if (!list[0]) return;
  output_log(o,
             "resume: note: %s lacks %s (an earlier checkpoint format): what %s "
             "starts at this resume, t = %.9g%s; stats.nc says so (attribute resumed_without)\n",
             path, list, strchr(list, ',') ? "they accumulate" : "it accumulates", t,
             strstr(list, "reynolds_budget") ? " (the Reynolds-stress budgets cover only the "
                                               "windows after it)"
                                             : "");
  const char *old = o->resumed_without ? o->resumed_without : "";
  const size_t n = strlen(old) + strlen(list) + 64;
  char *note = mem_alloc(n, 1, "resume");
  snprintf(note, n, "%s%s%s from t = %.9g", old, old[0] ? "; " : "", list, t);
  free(o->resumed_without), o->resumed_without = note;
}

/* Read one candidate; on failure everything it set up is released. */
static int try_one(const char *dir, struct candidate *cd, int n_set, char *const *set,
                   struct scene *sc, struct sim *S, struct output *o, struct skipped *sk,
                   struct scene *old, int *fatal, double seconds[2]) {
  const char *path = cd->path;
  char err[2048];
  struct ckpt_info info;
  const int bad_file = check_identity(dir, cd, &info, err, sizeof err);
  if (bad_file) {
    free(info.scene);
    skip(sk, path, err);
    return CHANSPH_ERR;
  }
  snprintf(cd->run_id, sizeof cd->run_id, "%s", info.run_id);
  char name[4200];
  snprintf(name, sizeof name, "%s:/scene", path);
  if (scene_load_text(old, name, info.scene, 0, NULL)) {
    snprintf(err, sizeof err, "%.1900s: the stored scene is not valid for this chansph (above)",
             path);
    skip(sk, path, err);
    free(info.scene);
    return CHANSPH_ERR;
  }
  const int bad = scene_load_text(sc, name, info.scene, n_set, set) ||
                  check_changes(old, sc, path) || check_average_start(old, sc, info.time, path) ||
                  check_window(old, sc, info.time, path);
  free(info.scene);
  /* the ranks must fit the slabs before anything is read (an input error, exit 1) */
  struct dd probe;
  const int fits = !bad && dd_init(&probe, sc, NULL, NULL) == CHANSPH_OK;
  if (!bad) dd_free(&probe);
  if (bad || !fits) {
    *fatal = 1;
    return CHANSPH_ERR;
  }
  /* the initial condition is replaced by the checkpoint: do not read init.from again, */
  struct scene bare = *sc;
  bare.init_from[0] = '\0';
  /* nor build (and announce) an initial profile: the checkpoint holds the velocities */
  bare.init_profile = INIT_REST, bare.init_noise = bare.init_modes = bare.init_streaks = 0.0;
  if (sim_create(S, &bare, 1)) {
    *fatal = 1;
    return CHANSPH_ERR;
  }
  S->sc = sc;
  /* the state the run started from: unknown unless the checkpoint says (since format 1.11) */
  free(S->init_run_id);
  init_origin(NULL, &S->init_run_id, &S->init_time);
  if (output_reopen(o, dir, sc)) {
    sim_free(S);
    *fatal = 1;
    return CHANSPH_ERR;
  }
  struct state_list L = {0};
  sim_state(S, &L);
  output_state(o, &L);
  o->window_len = NAN; /* stays NaN if the checkpoint has no window length (before 1.5) */
  const double t0 = timer_now();
  /* each rank reads its id block of the particles and all other fields; a checksum error
     seen by any rank skips the file on all */
  const int rc = ckpt_agree(ckpt_read(path, &L, err, sizeof err), err, sizeof err);
  seconds[0] = timer_now() - t0;
  if (!rc) note_absent(o, &L, path, info.time);
  state_free(&L);
  if (!rc && S->step != info.step)
    snprintf(err, sizeof err,
             "%.1900s: dataset /sim/step (%ld) differs from the root attribute 'step' "
             "(%ld)",
             path, S->step, info.step);
  if (rc || S->step != info.step) {
    skip(sk, path, err);
    output_close(o);
    sim_free(S);
    return CHANSPH_ERR;
  }
  const size_t differ = sim_restored(S);
  if (differ)
    die("restoring %s is not bitwise: %zu wall values differ from the stored ones", path, differ);
  seconds[1] = timer_now() - t0 - seconds[0];
  return CHANSPH_OK;
}

/* Rename the skipped checkpoints (rank 0's files) to *.skipped and log why each was skipped. */
static void rename_skipped(struct output *o, const struct skipped *sk, int rank) {
  for (int i = 0; i < sk->n; i++) {
    char to[4200];
    struct stat st;
    snprintf(to, sizeof to, "%s.skipped", sk->path[i]);
    for (int k = 1; lstat(to, &st) == 0 && k < 1000; k++) /* never replace an earlier one */
      snprintf(to, sizeof to, "%s.skipped.%d", sk->path[i], k);
    const int moved = rank == 0 && rename(sk->path[i], to) == 0; /* rank 0's files */
    output_log(o, "resume: skipped %s%s: %s\n", sk->path[i], moved ? " (renamed *.skipped)" : "",
               sk->why[i]);
  }
}

/* Rank 0: the identity a directory without DIR/run_id takes, the one every readable checkpoint
   stores (id; "" when none stores one: a run started before identities existed). Checkpoints of
   two runs are an input error: which run is this directory's cannot be known. */
static int agreed_id(const char *dir, const long *steps, int n, char *id) {
  char first[4096] = "", path[4096], err[2048];
  id[0] = '\0';
  for (int i = n - 1; i >= 0; i--) {
    rotate_path(path, sizeof path, dir, steps[i]);
    struct ckpt_info info;
    const int bad = ckpt_info(path, &info, err, sizeof err);
    free(info.scene);
    if (bad || !info.run_id[0]) continue; /* unreadable, or from before run identities */
    if (!id[0]) {
      snprintf(id, CKPT_RUN_ID_MAX, "%s", info.run_id);
      snprintf(first, sizeof first, "%s", path);
    } else if (strcmp(id, info.run_id)) {
      error_input(
          "%s/run_id is missing and the checkpoints are of two runs (%s: run_id %s; %s: run_id "
          "%s): which one is this directory's cannot be known; write the run's identity into "
          "%s/run_id, or move the other run's checkpoints away, then resume again",
          dir, first, id, path, info.run_id, dir);
      return CHANSPH_ERR;
    }
  }
  return CHANSPH_OK;
}

int restart_resume(const char *dir, int n_set, char *const *set, struct scene *sc, struct sim *S,
                   struct output *o) {
  long *steps;
  const int n = rotate_list(dir, &steps);
  if (n == 0) {
    error_input("%s/checkpoints: no checkpoint to resume from (is %s the directory of a run?)", dir,
                dir);
    return CHANSPH_ERR;
  }
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  CHECK_MPI(
      MPI_Barrier(MPI_COMM_WORLD)); /* every rank listed the files before rank 0 removes any */
  const int tmp = rank == 0 ? rotate_remove_tmp(dir) : 0;
  /* the checkpoints skipped, with why: 98 KB, on the heap */
  struct skipped *sk = mem_calloc(1, sizeof *sk, "the list of skipped checkpoints");
  struct scene old;
  int fatal = 0, found = -1;
  double seconds[2] = {0.0, 0.0}; /* read, restore */
  char path[4096], dir_id[CKPT_RUN_ID_MAX];
  const int no_id = rundir_read_id(dir, dir_id);
  if (no_id) { /* only checkpoints of one run: theirs (checked as the directory's below) */
    int rc = rank == 0 ? agreed_id(dir, steps, n, dir_id) : CHANSPH_OK;
    CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
    CHECK_MPI(MPI_Bcast(dir_id, CKPT_RUN_ID_MAX, MPI_CHAR, 0, MPI_COMM_WORLD));
    if (rc) {
      free(steps), free(sk);
      return CHANSPH_ERR;
    }
  }
  struct candidate cd = {.path = path, .dir_id = dir_id};
  for (int i = n - 1; i >= 0 && !fatal && found < 0; i--) {
    rotate_path(path, sizeof path, dir, steps[i]);
    cd.name_step = steps[i];
    if (!try_one(dir, &cd, n_set, set, sc, S, o, sk, &old, &fatal, seconds)) found = i;
  }
  free(steps);
  if (fatal || found < 0) {
    if (!fatal)
      error_input(
          "%s/checkpoints: none of the %d checkpoint(s) is valid (see above); nothing was "
          "deleted",
          dir, n);
    free(sk);
    return CHANSPH_ERR;
  }
  /* the run's identity: the directory's; a directory without one (a run started before
     identities existed) takes the checkpoint's, or a new one */
  if (no_id) {
    const int had = cd.run_id[0] != '\0';
    const int rc = had ? rundir_set_id(dir, cd.run_id) : rundir_new_id(dir, cd.run_id);
    if (rc) {
      output_close(o);
      sim_free(S);
      free(sk);
      return CHANSPH_ERR;
    }
    output_log(o, "resume: %s/run_id was missing: the run's identity is now %s (%s)\n", dir,
               cd.run_id, had ? "the checkpoint's" : "new");
  } else {
    ckpt_set_run_id(dir_id);
  }
  snprintf(o->run_id, sizeof o->run_id, "%s", no_id ? cd.run_id : dir_id);
  output_log(o, "resume: from %s (step %ld, t = %.9g s; read in %.3f s, restored in %.3f s)\n",
             path, S->step, S->t, seconds[0], seconds[1]);
  if (tmp) output_log(o, "resume: removed %d temporary file(s) of interrupted writes\n", tmp);
  rename_skipped(o, sk, rank);
  free(sk);
  log_changes(o, &old, sc);
  keep_window(o, &old, S->t);
  keep_converged(o, &old, sc, S->step);
  return CHANSPH_OK;
}
