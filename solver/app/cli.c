/** @file cli.c @brief Implementation of cli.h. */
#include "cli.h"

#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "run.h"
#include "timers.h"

void cli_usage(void) {
  printf(
      "usage:\n"
      "  chansph run SCENE.ini [--out DIR] [--set section.key=value ...] [--overwrite] [--fpe]\n"
      "              [--inject-nan STEP:ID]  (test aid: u of particle ID becomes NaN after STEP)\n"
      "  chansph resume DIR [--set section.key=value ...] [--fpe]\n"
      "      run and resume also take --max-steps N and --walltime HH:MM:SS\n"
      "  chansph bench [SCENE.ini] [--steps N] [--set section.key=value ...]\n"
      "  chansph scene-doc            print the scene key reference (docs/scenes.md)\n"
      "  chansph extract STATS.nc [--var a,b] [--units wall|outer] [--format csv|tsv]\n"
      "                  [--window T0:T1]   print profiles (docs/stats-format.md)\n"
      "  chansph compare STATS.nc --dns FILE [--out DIR]   errors against DNS, PNG plots\n"
      "  chansph --version | --help   (also: chansph run|resume|bench|extract --help)\n"
      "run writes DIR/log.txt, scene.used.ini, stats.nc, particles.nc (default DIR:\n"
      "runs/<scene name>) and DIR/checkpoints/ckpt_<step>.h5; resume continues a run from\n"
      "its newest valid checkpoint. Threads: OMP_NUM_THREADS or run.threads. Exit codes: 0 done,\n"
      "1 input error, 2 internal error, 3 numerical failure (health check), 74 cannot write\n"
      "a checkpoint or output, 75 checkpointed before the end (signal, DIR/STOP, --walltime,\n"
      "--max-steps): resume me (docs/batch-jobs.md).\n");
}

/* The command line as one string, arguments with blanks or quotes single-quoted. */
static char *command_line(int argc, char **argv) {
  size_t n = 1;
  for (int i = 0; i < argc; i++) n += 4 * strlen(argv[i]) + 3;
  char *s = calloc(n, 1);
  if (!s) return NULL;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (i == 0 && strrchr(a, '/')) a = strrchr(a, '/') + 1; /* chansph, not its path */
    if (i) strcat(s, " ");
    if (a[0] && !strpbrk(a, " \t\n'\"\\$;&|<>*?()")) {
      strcat(s, a);
      continue;
    }
    strcat(s, "'");
    for (const char *p = a; *p; p++) strcat(s, *p == '\'' ? "'\\''" : (char[]){*p, 0});
    strcat(s, "'");
  }
  return s;
}

int cli_parse(int argc, char **argv, struct cli *c) {
  memset(c, 0, sizeof *c);
  c->set = calloc((size_t)argc + 1, sizeof *c->set);
  c->cmdline = command_line(argc, argv);
  c->steps = 50;
  c->inject_id = -1;
  if (argc < 2) {
    c->cmd = CMD_HELP;
    return CHANSPH_OK;
  }
  const char *cmd = argv[1];
  if (!strcmp(cmd, "run"))
    c->cmd = CMD_RUN;
  else if (!strcmp(cmd, "resume"))
    c->cmd = CMD_RESUME;
  else if (!strcmp(cmd, "bench"))
    c->cmd = CMD_BENCH;
  else if (!strcmp(cmd, "scene-doc"))
    c->cmd = CMD_SCENE_DOC;
  else if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help"))
    c->cmd = CMD_HELP;
  else if (!strcmp(cmd, "--version"))
    c->cmd = CMD_VERSION;
  else {
    error_input("unknown command '%s'", cmd);
    cli_usage();
    return CHANSPH_ERR;
  }
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i];
    const int has_next = i + 1 < argc;
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) { /* chansph run --help: the usage, exit 0 */
      c->cmd = CMD_HELP;
      return CHANSPH_OK;
    }
    if (!strcmp(a, "--set") && has_next)
      c->set[c->n_set++] = argv[++i];
    else if (!strncmp(a, "--set=", 6))
      c->set[c->n_set++] = argv[i] + 6;
    else if (!strcmp(a, "--out") && has_next)
      snprintf(c->out, sizeof c->out, "%s", argv[++i]);
    else if (!strcmp(a, "--steps") && has_next) {
      char *end;
      c->steps = strtol(argv[++i], &end, 10);
      if (*end || c->steps < 1) {
        error_input("--steps %s: expected a positive integer", argv[i]);
        return CHANSPH_ERR;
      }
    } else if (!strcmp(a, "--max-steps") && has_next) {
      char *end;
      c->max_steps = strtol(argv[++i], &end, 10);
      if (*end || c->max_steps < 1) {
        error_input("--max-steps %s: expected a positive integer", argv[i]);
        return CHANSPH_ERR;
      }
    } else if (!strcmp(a, "--walltime") && has_next)
      c->walltime = argv[++i];
    else if (!strcmp(a, "--overwrite"))
      c->overwrite = 1;
    else if (!strcmp(a, "--fpe"))
      c->fpe = 1;
    else if (!strcmp(a, "--inject-nan") && i + 1 < argc) {
      char *end;
      c->inject_step = strtol(argv[++i], &end, 10);
      c->inject_id = *end == ':' ? strtoll(end + 1, &end, 10) : -1;
      if (*end || c->inject_step < 0 || c->inject_id < 0) {
        error_input("--inject-nan %s: expected STEP:ID with non-negative integers", argv[i]);
        return CHANSPH_ERR;
      }
    } else if (a[0] != '-' && !c->scene)
      c->scene = a;
    else {
      error_input("unexpected argument '%s'%s", a,
                  (!strcmp(a, "--set") || !strcmp(a, "--out") || !strcmp(a, "--steps") ||
                   !strcmp(a, "--max-steps") || !strcmp(a, "--walltime"))
                      ? " (missing value)"
                      : "");
      cli_usage();
      return CHANSPH_ERR;
    }
  }
  if (c->cmd == CMD_RUN && !c->scene) {
    error_input("run: missing SCENE.ini");
    cli_usage();
    return CHANSPH_ERR;
  }
  if (c->cmd == CMD_RESUME) {
    if (!c->scene) {
      error_input("resume: missing DIR (the run directory)");
      cli_usage();
      return CHANSPH_ERR;
    }
    snprintf(c->out, sizeof c->out, "%s", c->scene);
  }
  if (c->cmd == CMD_RUN && !c->out[0]) {
    const char *base = strrchr(c->scene, '/');
    base = base ? base + 1 : c->scene;
    const char *dot = strrchr(base, '.');
    snprintf(c->out, sizeof c->out, "runs/%.*s", dot ? (int)(dot - base) : (int)strlen(base), base);
  }
  return CHANSPH_OK;
}

int cli_bench_scene(struct scene *sc, const struct cli *c) {
  static char *defaults[] = {"domain.dimension=3", "domain.lx=1.6",   "domain.delta=0.5",
                             "domain.lz=1.0",      "domain.dr=0.025", "sph.h_over_dr=1.3",
                             "fluid.nu=0.1",       "fluid.c0=10",     "fluid.rho0=1000",
                             "drive.force=0.8",    "time.t_end=1e6"};
  enum { ND = sizeof defaults / sizeof defaults[0] };
  char **set = calloc((size_t)(ND + c->n_set), sizeof *set);
  int n = 0;
  if (!c->scene)
    for (int i = 0; i < ND; i++) set[n++] = defaults[i];
  for (int i = 0; i < c->n_set; i++) set[n++] = c->set[i];
  const int rc = scene_load(sc, c->scene, n, set);
  free(set);
  return rc;
}

/* The yardstick of the benchmark: one plain scalar loop in double over the current neighbour
   lists with the Wendland gradient, the symmetric pressure term and Morris' viscous term and
   nothing else (no walls, no normalisation, no vectorisation), timed over `reps` sweeps.
   Returns its particle-loops per second; the step is compared with it. */
static double yardstick(struct sim *S, long reps) {
  const struct particles *P = &S->P;
  const struct nbr *nb = &S->nb;
  const struct kernel K = S->M.k;
  const double lx = S->M.lx, lz = S->M.lz, nu = S->M.nu;
  double *out = S->scratch[0];
  long loops = 0;
  const double t0 = timer_now();
  for (long r = 0; r < reps; r++) {
#pragma omp parallel for schedule(static) reduction(+ : loops)
    for (size_t a = 0; a < P->n; a++) {
      if (P->kind[a] != KIND_FLUID) continue;
      const int32_t *nl = nb->list + a * (size_t)nb->stride;
      double gx = 0, gy = 0, gz = 0, vx = 0, vy = 0, vz = 0;
      for (int j = 0; j < nb->count[a]; j++) {
        const int32_t b = nl[j];
        const double dx = nbr_wrap(P->x[a] - P->x[b], lx), dy = P->y[a] - P->y[b];
        const double dz = nbr_wrap(P->z[a] - P->z[b], lz);
        const double r2 = dx * dx + dy * dy + dz * dz, f = kernel_f(&K, sqrt(r2));
        const double pp = P->m[b] * (P->pr2[a] + P->pr2[b]) * f;
        const double vc = (P->m[b] / P->rho[a] + P->vol[b]) * f;
        gx += pp * dx, gy += pp * dy, gz += pp * dz;
        vx += vc * (P->u[a] - P->u[b]), vy += vc * (P->v[a] - P->v[b]);
        vz += vc * (P->w[a] - P->w[b]);
      }
      out[a] = -gx - gy - gz + nu * (vx + vy + vz);
      loops++;
    }
  }
  const double wall = timer_now() - t0;
  return wall > 0.0 ? (double)loops / wall : 0.0;
}

int cli_bench(const struct scene *sc, long steps) {
  struct sim S;
  const double t_setup = timer_now();
  if (sim_init(&S, sc)) return 1;
  const double setup = timer_now() - t_setup;
  const int root = S.dd.rank == 0, ranks = S.dd.size;
  double nbr = 0.0, mine = (double)S.P.n;
  for (size_t a = 0; a < S.P.n; a++)
    if (S.P.kind[a] == KIND_FLUID) nbr += S.nb.count[a];
  MPI_Allreduce(MPI_IN_PLACE, &nbr, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  const int warm = 3;
  for (int i = 0; i < warm; i++) sim_step(&S);
  timer_reset();
  const double halo0 = S.dd.seconds, bytes0 = S.dd.bytes, msg0 = (double)S.dd.messages;
  MPI_Barrier(MPI_COMM_WORLD);
  const double t0 = timer_now(), sim0 = S.t;
  for (long i = 0; i < steps; i++) sim_step(&S);
  MPI_Barrier(MPI_COMM_WORLD);
  const double wall = timer_now() - t0, simt = S.t - sim0;
  double yard = S.dd.size == 1 ? yardstick(&S, steps) : 0.0;
  /* the exchanges per rank: max and mean of time, bytes and messages; particles per rank */
  double x[4] = {S.dd.seconds - halo0, S.dd.bytes - bytes0, (double)S.dd.messages - msg0, mine};
  double mx[4], sum[4];
  MPI_Allreduce(x, mx, 4, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(x, sum, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  if (root) {
    printf("chansph bench: %dD, %zu fluid + %zu vertex particles, %d MPI ranks x %d threads\n",
           sc->dim, S.P.n_fluid, S.P.n_vertex, ranks, omp_get_max_threads());
    printf("neighbours per fluid particle (within 2h, self excluded): %.2f\n",
           nbr / (double)S.P.n_fluid);
    printf("set-up %.3f s; %d warm-up steps, then %ld timed steps in %.3f s (%.3f ms/step)\n",
           setup, warm, steps, wall, 1e3 * wall / steps);
    printf("dt = %.4e s (limits: acoustic %.3e, viscous %.3e, force %.3e, wall %.3e)\n", S.dt,
           S.dt_limits[0], S.dt_limits[1], S.dt_limits[2], S.dt_limits[3]);
    printf("wall seconds per simulated second: %.1f\n", simt > 0 ? wall / simt : 0.0);
    if (ranks > 1) {
      printf("particles per rank: max %.0f, mean %.1f (imbalance %.3f)\n", mx[3], sum[3] / ranks,
             mx[3] / (sum[3] / ranks));
      printf(
          "halo exchange and migration per step: %.3f ms max over ranks (%.1f%% of the "
          "step), %.3f ms mean; %.1f kB and %.1f messages sent per rank per step (mean)\n",
          1e3 * mx[0] / steps, 100.0 * mx[0] / wall, 1e3 * sum[0] / ranks / steps,
          sum[1] / ranks / steps / 1024.0, sum[2] / ranks / steps);
    }
    timer_report(stdout, wall);
    part_memory_report(stdout);
    if (yard > 0.0)
      printf(
          "yardstick (one plain scalar double loop over the lists: kernel gradient, pressure "
          "and Morris terms): %.0f particle-loops/s; the step runs at %.2f of it\n",
          yard, (double)S.P.n_fluid * steps / wall / yard);
    printf("particle-steps/s: %.0f\n", (double)S.P.n_fluid * steps / wall);
  }
  sim_free(&S);
  return 0;
}
