/**
 * @file trigger.c
 * @brief When to checkpoint and when to stop: step and wall-clock intervals, signals (the
 *        handler only sets a flag, read at the step boundary), a STOP file, --walltime with a
 *        margin learnt from the measured checkpoint write time, and --max-steps.
 */
#include <errno.h>
#include <math.h>
#include <mpi.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "error.h"
#include "restart.h"
#include "timers.h"

/** Signal received, or 0; set by the handler, read after each step. */
static volatile sig_atomic_t got_signal;

static void on_signal(int sig) {
  got_signal = sig;
}

/** Fixed part of the walltime margin [s]: final stats.nc, closing files, process exit. */
static const double MARGIN_FIXED = 1.0;
/** Write rate assumed before the first checkpoint of a process was timed [bytes/s]. */
static const double RATE_GUESS = 50e6;

/** Wall clock at trigger_mark_start() [s], or 0. */
static double process_start;

static void install_handlers(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);
  sa.sa_flags = SA_RESETHAND; /* a second Ctrl-C interrupts at once */
  sigaction(SIGINT, &sa, NULL);
  signal(SIGXFSZ, SIG_IGN); /* a file-size limit: write() fails with EFBIG, reported */
}

void trigger_mark_start(void) {
  process_start = timer_now();
  install_handlers();
}

void trigger_init(struct trigger *T, const char *dir, const struct scene *sc, double walltime,
                  long max_steps, long step, double state_bytes) {
  memset(T, 0, sizeof *T);
  snprintf(T->dir, sizeof T->dir, "%s", dir);
  T->every_steps = sc->ckpt_every_steps;
  T->every_seconds = 60.0 * sc->ckpt_every_minutes;
  T->walltime = walltime;
  T->max_steps = max_steps;
  T->step0 = step;
  T->last_step = step;
  T->bytes = state_bytes;
  T->write_seconds = 0.2 + state_bytes / RATE_GUESS;
  if (!process_start) install_handlers();
  T->last_wall = T->step_wall = timer_now();
  T->wall_start = process_start ? process_start : T->last_wall;
}

static int stop_file(struct trigger *T) {
  char path[4096];
  struct stat st;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) return 0; /* rank 0 looks and removes it; trigger_check shares the result */
  snprintf(path, sizeof path, "%s/STOP", T->dir);
  if (stat(path, &st)) return 0;
  if (!rundir_is_held(T->dir)) return 1; /* another run's STOP now: the run stops, keeps it */
  if (remove(path)) warn("%s: cannot remove the STOP file (%s)", path, strerror(errno));
  return 1;
}

/* The reason on this rank alone; trigger_check() makes every rank agree. */
static int local_check(struct trigger *T, long step) {
  const double now = timer_now();
  const double last = now - T->step_wall;
  T->step_wall = now;
  if (last > T->step_seconds_max) T->step_seconds_max = last;
  if (got_signal) {
    T->signal = got_signal;
    got_signal = 0;
    return TRIG_SIGNAL;
  }
  if (stop_file(T)) return TRIG_STOP_FILE;
  if (T->max_steps > 0 && step - T->step0 >= T->max_steps) return TRIG_MAX_STEPS;
  /* stop now if another step, a checkpoint and the margin would not fit */
  if (T->walltime > 0.0 &&
      now - T->wall_start + T->step_seconds_max + 2.0 * T->write_seconds + MARGIN_FIXED >=
          T->walltime)
    return TRIG_WALLTIME;
  if (T->every_steps > 0 && step % T->every_steps == 0) return TRIG_PERIODIC;
  if (T->every_seconds > 0.0 && now - T->last_wall >= T->every_seconds) return TRIG_PERIODIC;
  return TRIG_NONE;
}

int trigger_check(struct trigger *T, long step) {
  int why = local_check(T, step);
  /* the strongest reason of any rank (signals, the STOP file and the clocks differ) */
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &why, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD));
  return why;
}

const char *trigger_text(const struct trigger *T, int why) {
  static char buf[64];
  switch (why) {
    case TRIG_PERIODIC:
      return "periodic checkpoint";
    case TRIG_SIGNAL:
      snprintf(buf, sizeof buf, "signal %s",
               T->signal == SIGTERM   ? "SIGTERM"
               : T->signal == SIGINT  ? "SIGINT"
               : T->signal == SIGUSR1 ? "SIGUSR1"
                                      : "?");
      return buf;
    case TRIG_STOP_FILE:
      return "STOP file";
    case TRIG_WALLTIME:
      snprintf(buf, sizeof buf, "--walltime %.0f s", T->walltime);
      return buf;
    case TRIG_MAX_STEPS:
      snprintf(buf, sizeof buf, "--max-steps %ld", T->max_steps);
      return buf;
    default:
      return "end of run";
  }
}

void trigger_wrote(struct trigger *T, long step, double seconds) {
  T->last_step = step;
  T->last_wall = timer_now();
  T->step_wall = T->last_wall; /* the write is not part of the next step's time */
  if (!T->measured || seconds > T->write_seconds) T->write_seconds = seconds;
  T->measured = 1;
}

int trigger_parse_walltime(const char *text, double *seconds) {
  double s = 0.0;
  const char *p = text;
  for (int n = 0;; n++) {
    char *end;
    errno = 0;
    const double v = strtod(p, &end);
    if (n == 3 || end == p || errno || v < 0.0 || !isfinite(v) || *p == '-' || *p == '+') return 1;
    if (n > 0 && v >= 60.0) return 1; /* minutes and seconds after a ':' are below 60 */
    s = 60.0 * s + v;
    if (*end == '\0') break;
    if (*end != ':') return 1;
    p = end + 1;
  }
  if (s <= 0.0) return 1;
  *seconds = s;
  return 0;
}
