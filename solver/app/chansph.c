/**
 * @file chansph.c
 * @brief The chansph program: parse, validate, initialise, step loop, finalise.
 */
#define _GNU_SOURCE /* feenableexcept */
#include <fenv.h>
#include <math.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "error.h"
#include "extract.h"
#include "health.h"
#include "output.h"
#include "restart.h"
#include "sim.h"
#include "snapshot.h"

/** Write a checkpoint and tell the triggers how long it took. */
static int save(struct output *out, struct sim *S, struct trigger *T) {
  double seconds = 0.0;
  if (restart_save(out, S, &seconds)) {
    output_log(out,
               "error: stopped at step %ld: cannot write a checkpoint (the previous ones are "
               "intact); fix the cause, then `chansph resume %s`\n",
               S->step, out->dir);
    return CHANSPH_ERR;
  }
  trigger_wrote(T, S->step, seconds);
  return CHANSPH_OK;
}

/** Whether the run directory is lost before the run's files are written (rundir_check: deleted
    and recreated by another run, or moved away); then the run stops without writing. */
static int dir_lost(struct output *out, const struct sim *S) {
  if (rundir_check(out->dir) == CHANSPH_OK) return 0;
  output_log(out, "error: stopped at step %ld: %s is no longer this run's directory\n", S->step,
             out->dir);
  return 1;
}

/** Health check of the state before it is written or sampled, once per step (checked: the
    step last checked); a failure is reported (step, particle id, position) and returns 1. */
static int unhealthy(struct output *out, struct sim *S, long *checked) {
  struct health_report rep;
  if (*checked == S->step) return 0;
  if (health_check(&S->M, &S->P, S->step, S->t, &rep)) {
    output_fail(out, S, &rep);
    return 1;
  }
  *checked = S->step;
  return 0;
}

/** Open the run: resume it from DIR's checkpoints, or build the scene's initial state and
    create DIR; returns 0 or EXIT_INPUT (message printed, nothing left allocated). */
static int open_run(struct scene *sc, const struct cli *c, struct sim *S, struct output *out) {
  if (c->cmd == CMD_RESUME) {
    /* the directory is locked for the life of the process (DIR/.lock) */
    if (rundir_lock(c->out, 0) || restart_resume(c->out, c->n_set, c->set, sc, S, out))
      return EXIT_INPUT;
    output_resume(out, S);
    return 0;
  }
  if (sim_init(S, sc)) return EXIT_INPUT; /* before the run directory exists */
  if (rundir_lock(c->out, 1) || restart_prepare_new(c->out, c->overwrite) ||
      output_open(out, c->out, sc, c->overwrite)) {
    sim_free(S);
    return EXIT_INPUT;
  }
  if (rundir_new_id(c->out, out->run_id)) {
    output_close(out);
    sim_free(S);
    return EXIT_INPUT;
  }
  output_begin(out, S);
  return 0;
}

/** End the run with exit code rc: a finished run is checked, checkpointed and its files written;
    a stopped one (EXIT_RESUBMIT) says how to continue. Returns the final exit code. */
static int close_run(struct output *out, struct sim *S, struct trigger *T, int why, int rc,
                     long *checked) {
  if ((rc == EXIT_DONE || rc == EXIT_RESUBMIT) && dir_lost(out, S)) rc = EXIT_IOERR;
  if (rc == EXIT_DONE && unhealthy(out, S, checked)) rc = EXIT_NUMERICAL;
  if (rc == EXIT_DONE && T->last_step != S->step && save(out, S, T)) rc = EXIT_IOERR;
  /* with particles.nc, the final state also as a snapshot: ParaView opens the snapshots
     (XDMF), not particles.nc (docs/formats.md); none twice if the last step wrote one */
  if (rc == EXIT_DONE && S->sc->particles && !(S->step > 0 && snapshot_due(S)) &&
      snapshot_write(out->dir, S))
    rc = EXIT_IOERR;
  if (rc == EXIT_DONE && output_finish(out, S)) rc = EXIT_IOERR;
  if (rc == EXIT_RESUBMIT) {
    if (output_stop(out, S, trigger_text(T, why)))
      rc = EXIT_IOERR;
    else
      output_log(out, "checkpointed: continue with `chansph resume %s` (exit code %d)\n", out->dir,
                 EXIT_RESUBMIT);
  }
  output_close(out);
  sim_free(S);
  return rc;
}

/** Run a scene, or resume a run, in a directory; returns the process exit code. The loop is the
    whole life of a step: advance, check, sample the statistics, write, checkpoint. */
static int run(struct scene *sc, const struct cli *c) {
  double walltime = 0.0;
  if (c->walltime && trigger_parse_walltime(c->walltime, &walltime)) {
    error_input("--walltime %s: expected HH:MM:SS, MM:SS or seconds", c->walltime);
    return EXIT_INPUT;
  }
  struct output out;
  struct sim S;
  if (open_run(sc, c, &S, &out)) return EXIT_INPUT;
  out.max_steps = c->max_steps; /* the ETA counts it */
  if (sc->threads > 0) omp_set_num_threads(sc->threads);
  out.history =
      rundir_history(c->out, c->cmdline, c->cmd == CMD_RUN, S.dd.size, omp_get_max_threads());
  struct trigger T;
  trigger_init(&T, c->out, sc, walltime, c->max_steps, S.step, restart_state_bytes(&out, &S));
  int rc = EXIT_DONE, why = TRIG_NONE;
  /* the start state counts as checked: read from a checkpoint (checked when it was written), or
     built from the scene (analytic profiles; init.from is refused if not finite) */
  long checked = S.step;
  while (!out.converged && !sim_done(&S)) { /* converged: a resumed run that had ended */
    sim_step(&S);
    if (c->inject_id >= 0 && S.step == c->inject_step)
      for (size_t a = 0; a < S.P.n; a++)
        if (S.P.id[a] == c->inject_id) S.P.u[a] = NAN; /* fault injection (tests only) */
    if (S.violation[0]) {
      struct health_report rep;
      snprintf(rep.what, sizeof rep.what, "%s", S.violation);
      output_fail(&out, &S, &rep);
      rc = EXIT_NUMERICAL;
      break;
    }
    /* every state that is written or sampled is checked first, whatever health.every */
    if ((S.step % sc->health_every == 0 || output_takes_state(&out, &S) || snapshot_due(&S)) &&
        unhealthy(&out, &S, &checked)) {
      rc = EXIT_NUMERICAL;
      break;
    }
    output_sample(&out, &S); /* statistics (stats/), when due */
    if ((S.t >= out.next_write || snapshot_due(&S)) && dir_lost(&out, &S)) {
      rc = EXIT_IOERR;
      break;
    }
    if (output_step(&out, &S)) {
      output_log(&out, "stopped at step %ld: cannot write stats.nc (the checkpoints are intact)\n",
                 S.step);
      rc = EXIT_IOERR;
      break;
    }
    if (snapshot_due(&S) && snapshot_write(out.dir, &S)) {
      rc = EXIT_IOERR;
      break;
    }
    if (out.converged) break; /* stats.target_stderr met: final checkpoint and files, exit 0 */
    why = trigger_check(&T, S.step);
    if (why == TRIG_NONE) continue;
    if (unhealthy(&out, &S, &checked)) {
      rc = EXIT_NUMERICAL;
      break;
    }
    if (dir_lost(&out, &S) || save(&out, &S, &T)) {
      rc = EXIT_IOERR;
      break;
    }
    if (why != TRIG_PERIODIC) {
      rc = EXIT_RESUBMIT;
      break;
    }
  }
  return close_run(&out, &S, &T, why, rc, &checked);
}

int main(int argc, char **argv) {
  trigger_mark_start();
  /* post-processing commands: serial, no MPI */
  if (argc > 1 && !strcmp(argv[1], "extract")) return extract_main(argc - 1, argv + 1);
  if (argc > 1 && !strcmp(argv[1], "compare"))
    return compare_main(argc - 2, argv + 2, CHANSPH_STATS_DIR);
  MPI_Init(&argc, &argv);
  /* failed MPI calls return to CHECK_MPI, which names the call, file and line */
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  int rc = 0;
  struct cli c;
  struct scene sc;
  if (cli_parse(argc, argv, &c)) {
    rc = 1;
  } else if (c.help) {
    cli_command_usage(c.cmd);
  } else if (c.cmd == CMD_HELP) {
    cli_usage();
  } else if (c.cmd == CMD_VERSION) {
    printf("chansph %s\n", CHANSPH_VERSION);
  } else if (c.cmd == CMD_SCENE_DOC) {
    scene_write_doc(stdout);
  } else if (c.cmd == CMD_RESUME) {
    if (c.fpe) feenableexcept(FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW);
    rc = run(&sc, &c);
  } else if ((c.cmd == CMD_BENCH ? cli_bench_scene(&sc, &c)
                                 : scene_load(&sc, c.scene, c.n_set, c.set))) {
    rc = 1;
  } else {
    if (sc.threads > 0) omp_set_num_threads(sc.threads);
    if (c.fpe) feenableexcept(FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW);
    rc = c.cmd == CMD_BENCH ? cli_bench(&sc, c.steps) : run(&sc, &c);
  }
  free(c.set);
  free(c.cmdline);
  MPI_Finalize();
  return rc;
}
