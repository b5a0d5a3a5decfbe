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
#include "run.h"

/** Run a scene into a directory; returns the process exit code. */
static int run(const struct scene *sc, const struct cli *c) {
  struct sim S;
  if (sim_init(&S, sc)) return 1; /* before the run directory exists: nothing to clean up */
  struct output out;
  if (output_open(&out, c->out, sc, c->overwrite)) {
    sim_free(&S);
    return 1;
  }
  output_begin(&out, &S);
  int rc = 0;
  while (!sim_done(&S)) {
    sim_step(&S);
    if (c->inject_id >= 0 && S.step == c->inject_step)
      for (size_t a = 0; a < S.P.n; a++)
        if (S.P.id[a] == c->inject_id) S.P.u[a] = NAN; /* fault injection (tests only) */
    struct health_report rep;
    if (S.violation[0]) snprintf(rep.what, sizeof rep.what, "%s", S.violation);
    if (S.violation[0] ||
        (S.step % sc->health_every == 0 && health_check(&S.M, &S.P, S.step, S.t, &rep))) {
      output_fail(&out, &S, &rep);
      rc = 3;
      break;
    }
    output_step(&out, &S);
  }
  if (rc == 0 && output_finish(&out, &S)) rc = 1;
  output_close(&out);
  sim_free(&S);
  return rc;
}

int main(int argc, char **argv) {
  /* post-processing commands: serial, no MPI */
  if (argc > 1 && !strcmp(argv[1], "extract")) return extract_main(argc - 2, argv + 2);
  if (argc > 1 && !strcmp(argv[1], "compare"))
    return compare_main(argc - 2, argv + 2, CHANSPH_STATS_DIR);
  MPI_Init(&argc, &argv);
  int size = 1, rc = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  struct cli c;
  struct scene sc;
  if (cli_parse(argc, argv, &c)) {
    rc = 1;
  } else if (c.cmd == CMD_HELP) {
    cli_usage();
  } else if (c.cmd == CMD_VERSION) {
    printf("chansph %s\n", CHANSPH_VERSION);
  } else if (c.cmd == CMD_SCENE_DOC) {
    scene_write_doc(stdout);
  } else if (size > 1) {
    error_input(
        "this version runs on one MPI rank (got %d); domain decomposition is not "
        "implemented yet",
        size);
    rc = 1;
  } else if ((c.cmd == CMD_BENCH ? cli_bench_scene(&sc, &c)
                                 : scene_load(&sc, c.scene, c.n_set, c.set))) {
    rc = 1;
  } else {
    if (sc.threads > 0) omp_set_num_threads(sc.threads);
    if (c.fpe) feenableexcept(FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW);
    rc = c.cmd == CMD_BENCH ? cli_bench(&sc, c.steps) : run(&sc, &c);
  }
  free(c.set);
  MPI_Finalize();
  return rc;
}
