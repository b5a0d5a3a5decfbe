/** @file cli.c @brief Implementation of cli.h. */
#include "cli.h"

#include <getopt.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "alloc.h"
#include "error.h"
#include "sim.h"
#include "timers.h"

/* One entry per command: its name and its usage lines (cli_usage prints them all, and
   `chansph COMMAND --help` the command's own). */
static const struct cli_command {
  const char *name;
  enum command cmd;
  const char *usage;
} commands[] = {
    {"run", CMD_RUN,
     "  chansph run SCENE.ini [--out DIR] [--set section.key=value ...] [--overwrite] [--fpe]\n"
     "              [--inject-nan STEP:ID]  (test aid: u of particle ID becomes NaN after STEP)\n"
     "              [--max-steps N] [--walltime HH:MM:SS]\n"},
    {"resume", CMD_RESUME,
     "  chansph resume DIR [--set section.key=value ...] [--fpe] [--max-steps N]\n"
     "                 [--walltime HH:MM:SS]\n"},
    {"bench", CMD_BENCH, "  chansph bench [SCENE.ini] [--steps N] [--set section.key=value ...]\n"},
    {"scene-doc", CMD_SCENE_DOC,
     "  chansph scene-doc            print the scene key reference (docs/scenes.md)\n"},
    {"help", CMD_HELP, NULL},
    {"--help", CMD_HELP, NULL},
    {"-h", CMD_HELP, NULL},
    {"--version", CMD_VERSION, NULL},
};
enum { N_COMMANDS = sizeof commands / sizeof commands[0] };

static const char *const cli_notes =
    "run writes DIR/log.txt, scene.used.ini, stats.nc, particles.nc (default DIR:\n"
    "runs/<scene name>) and DIR/checkpoints/ckpt_<step>.h5; resume continues a run from\n"
    "its newest valid checkpoint. Threads: OMP_NUM_THREADS or run.threads. Exit codes: 0 done,\n"
    "1 input error, 2 internal error, 3 numerical failure (health check), 74 cannot write\n"
    "a checkpoint or output, 75 checkpointed before the end (signal, DIR/STOP, --walltime,\n"
    "--max-steps): resume me (docs/batch-jobs.md).\n";

/* The options of run, resume and bench, for `chansph COMMAND --help` (bench: its own). */
static const char *const cli_options_help =
    "options:\n"
    "  --out DIR        run directory (run; default runs/<scene file name without .ini>)\n"
    "  --set SEC.KEY=V  override a scene key, repeatable (e.g. --set time.t_end=20); the keys:\n"
    "                   chansph scene-doc, docs/scenes.md; resume accepts only the keys of\n"
    "                   docs/batch-jobs.md (time.t_end, time.max_steps, output and checkpoint\n"
    "                   intervals ...)\n"
    "  --overwrite      run: replace the results of an earlier run in DIR\n"
    "  --fpe            trap floating-point exceptions (division by zero, invalid, overflow):\n"
    "                   SIGFPE kills the process at the first one (exit 136; a debugger\n"
    "                   stops at the faulting line), instead of a NaN that health finds later\n"
    "  --max-steps N    stop after N steps of this process (counted from the start or from\n"
    "                   where resume began), checkpoint and exit 75; time.max_steps, by\n"
    "                   contrast, is the step number at which the run itself ends (exit 0)\n"
    "  --walltime T     stop with a checkpoint (exit 75) before T (HH:MM:SS, MM:SS or s) of\n"
    "                   wall time, with a safety margin (docs/batch-jobs.md)\n";
static const char *const cli_bench_help =
    "Times N steps (--steps, default 50) of SCENE.ini, or of the built-in 3-D reference case\n"
    "without one, after a warm-up, and reports the cost per phase and per particle-step;\n"
    "nothing is written. --set SEC.KEY=V overrides a scene key (repeatable; chansph\n"
    "scene-doc lists them). OMP_NUM_THREADS sets the threads.\n";

void cli_usage(void) {
  printf("usage:\n");
  for (int i = 0; i < N_COMMANDS; i++)
    if (commands[i].usage && commands[i].cmd != CMD_SCENE_DOC) printf("%s", commands[i].usage);
  printf(
      "  chansph scene-doc            print the scene key reference (docs/scenes.md)\n"
      "  chansph extract STATS.nc [LATER.nc ...] [--var a,b] [--units wall|outer]\n"
      "                  [--format csv|tsv] [--window T0:T1] [--pdfs] [--nc OUT.nc] [--force]\n"
      "                  print profiles or the one-point PDFs, or join a run's segments\n"
      "                  into one file (docs/stats-format.md)\n"
      "  chansph compare STATS.nc --dns FILE [--out DIR]   errors against DNS, PNG plots\n"
      "  chansph --version | --help   (also: chansph COMMAND --help)\n"
      "%s",
      cli_notes);
}

void cli_command_usage(enum command cmd) {
  for (int i = 0; i < N_COMMANDS; i++)
    if (commands[i].cmd == cmd && commands[i].usage) {
      printf("usage:\n%s", commands[i].usage);
      if (cmd == CMD_RUN || cmd == CMD_RESUME) printf("%s%s", cli_options_help, cli_notes);
      if (cmd == CMD_BENCH) printf("%s", cli_bench_help);
      return;
    }
  cli_usage();
}

/* The command line as one string, arguments with blanks or quotes single-quoted. */
static char *command_line(int argc, char **argv) {
  size_t n = 1;
  for (int i = 0; i < argc; i++) n += 4 * strlen(argv[i]) + 3;
  char *s = mem_calloc(n, 1, "command line");
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

/* The long options of the commands (getopt_long); the value is the option's code. */
enum {
  OPT_SET = 256,
  OPT_OUT,
  OPT_STEPS,
  OPT_MAX_STEPS,
  OPT_WALLTIME,
  OPT_OVERWRITE,
  OPT_FPE,
  OPT_INJECT_NAN
};
static const struct option cli_options[] = {
    {"help", no_argument, NULL, 'h'},
    {"set", required_argument, NULL, OPT_SET},
    {"out", required_argument, NULL, OPT_OUT},
    {"steps", required_argument, NULL, OPT_STEPS},
    {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
    {"walltime", required_argument, NULL, OPT_WALLTIME},
    {"overwrite", no_argument, NULL, OPT_OVERWRITE},
    {"fpe", no_argument, NULL, OPT_FPE},
    {"inject-nan", required_argument, NULL, OPT_INJECT_NAN},
    {NULL, 0, NULL, 0},
};

/* A positive integer option value, or an input error naming the option. */
static int positive(const char *opt, const char *s, long *v) {
  char *end;
  *v = strtol(s, &end, 10);
  if (!*s || *end || *v < 1) {
    error_input("%s %s: expected a positive integer", opt, s);
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

/* Apply one option (code from getopt_long, arg its value); 1: --help. */
static int cli_option(struct cli *c, int code, char *arg) {
  switch (code) {
    case OPT_SET:
      c->set[c->n_set++] = arg;
      return CHANSPH_OK;
    case OPT_OUT:
      snprintf(c->out, sizeof c->out, "%s", arg);
      return CHANSPH_OK;
    case OPT_STEPS:
      return positive("--steps", arg, &c->steps);
    case OPT_MAX_STEPS:
      return positive("--max-steps", arg, &c->max_steps);
    case OPT_WALLTIME:
      c->walltime = arg;
      return CHANSPH_OK;
    case OPT_OVERWRITE:
      c->overwrite = 1;
      return CHANSPH_OK;
    case OPT_FPE:
      c->fpe = 1;
      return CHANSPH_OK;
    case OPT_INJECT_NAN: {
      char *end;
      c->inject_step = strtol(arg, &end, 10);
      c->inject_id = *end == ':' ? strtoll(end + 1, &end, 10) : -1;
      if (*end || c->inject_step < 0 || c->inject_id < 0) {
        error_input("--inject-nan %s: expected STEP:ID with non-negative integers", arg);
        return CHANSPH_ERR;
      }
      return CHANSPH_OK;
    }
  }
  return CHANSPH_ERR;
}

/* The name of a command. */
static const char *cli_name(enum command cmd) {
  for (int i = 0; i < N_COMMANDS; i++)
    if (commands[i].cmd == cmd) return commands[i].name;
  return "chansph";
}

/* After the options: the positional argument each command needs, the default run directory. */
static int cli_finish(struct cli *c) {
  if (c->cmd == CMD_RUN && !c->scene) {
    error_input("run: missing SCENE.ini");
    cli_command_usage(c->cmd);
    return CHANSPH_ERR;
  }
  struct stat st;
  if ((c->cmd == CMD_RUN || c->cmd == CMD_BENCH) && c->scene && !stat(c->scene, &st) &&
      S_ISDIR(st.st_mode)) {
    error_input("%s: %s is a directory, not a scene file (SCENE.ini)%s%s", cli_name(c->cmd),
                c->scene, c->cmd == CMD_RUN ? "; to continue the run in it: chansph resume " : "",
                c->cmd == CMD_RUN ? c->scene : "");
    return CHANSPH_ERR;
  }
  if (c->cmd == CMD_RESUME) {
    if (!c->scene) {
      error_input("resume: missing DIR (the run directory)");
      cli_command_usage(c->cmd);
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

/* The command named by argv[1], or -1 after an error. */
static int cli_command(const char *name) {
  for (int i = 0; i < N_COMMANDS; i++)
    if (!strcmp(name, commands[i].name)) return (int)commands[i].cmd;
  error_input("unknown command '%s'", name);
  cli_usage();
  return -1;
}

int cli_parse(int argc, char **argv, struct cli *c) {
  memset(c, 0, sizeof *c);
  c->set = mem_calloc((size_t)argc + 1, sizeof *c->set, "command line");
  c->cmdline = command_line(argc, argv);
  c->steps = 50;
  c->inject_id = -1;
  const int cmd = argc < 2 ? (int)CMD_HELP : cli_command(argv[1]);
  if (cmd < 0) return CHANSPH_ERR;
  c->cmd = (enum command)cmd;
  if (c->cmd == CMD_HELP || c->cmd == CMD_VERSION) return CHANSPH_OK;
  /* argv[1], the command, plays the program name for getopt_long; a leading '-' returns the
     positional arguments in order (code 1), ':' reports a missing value as ':' */
  opterr = 0, optind = 1;
  char **args = argv + 1;
  for (;;) {
    const int at = optind; /* the argument getopt_long reads now */
    const int code = getopt_long(argc - 1, args, "-:h", cli_options, NULL);
    if (code == -1) break;
    if (code == 'h') { /* chansph COMMAND --help: the command's usage, exit 0 */
      c->help = 1;
      return CHANSPH_OK;
    }
    if (code == 1 && !c->scene) {
      c->scene = optarg;
    } else if (code == 1 || code == '?' || code == ':') {
      error_input("unexpected argument '%s'%s", code == 1 ? optarg : args[at],
                  code == ':' ? " (missing value)" : "");
      cli_command_usage(c->cmd);
      return CHANSPH_ERR;
    } else if (cli_option(c, code, optarg)) {
      return CHANSPH_ERR;
    }
  }
  for (int i = optind; i < argc - 1; i++) { /* after "--": positional arguments only */
    if (c->scene) {
      error_input("unexpected argument '%s'", args[i]);
      cli_command_usage(c->cmd);
      return CHANSPH_ERR;
    }
    c->scene = args[i];
  }
  return cli_finish(c);
}

int cli_bench_scene(struct scene *sc, const struct cli *c) {
  static char *defaults[] = {"domain.dimension=3", "domain.lx=1.6",   "domain.delta=0.5",
                             "domain.lz=1.0",      "domain.dr=0.025", "sph.h_over_dr=1.3",
                             "fluid.nu=0.1",       "fluid.c0=10",     "fluid.rho0=1000",
                             "drive.force=0.8",    "time.t_end=1e6"};
  enum { ND = sizeof defaults / sizeof defaults[0] };
  char **set = mem_calloc((size_t)(ND + c->n_set), sizeof *set, "bench settings");
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
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &nbr, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD));
  const int warm = 3;
  for (int i = 0; i < warm; i++) sim_step(&S);
  timer_reset();
  const double halo0 = S.dd.seconds, bytes0 = S.dd.bytes, msg0 = (double)S.dd.messages;
  CHECK_MPI(MPI_Barrier(MPI_COMM_WORLD));
  const double t0 = timer_now(), sim0 = S.t;
  for (long i = 0; i < steps; i++) sim_step(&S);
  CHECK_MPI(MPI_Barrier(MPI_COMM_WORLD));
  const double wall = timer_now() - t0, simt = S.t - sim0;
  double yard = S.dd.size == 1 ? yardstick(&S, steps) : 0.0;
  /* the exchanges per rank: max and mean of time, bytes and messages; particles per rank */
  double x[4] = {S.dd.seconds - halo0, S.dd.bytes - bytes0, (double)S.dd.messages - msg0, mine};
  double mx[4], sum[4];
  CHECK_MPI(MPI_Allreduce(x, mx, 4, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD));
  CHECK_MPI(MPI_Allreduce(x, sum, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD));
  if (root) {
    printf("chansph bench: %dD, %zu fluid + %zu vertex particles, %d MPI ranks x %d threads\n",
           sc->dim, S.P.n_fluid, S.P.n_vertex, ranks, omp_get_max_threads());
    printf("neighbours per fluid particle (within 2h, self excluded): %.2f\n",
           nbr / (double)S.P.n_fluid);
    printf("set-up %.3f s; %d warm-up steps, then %ld timed steps in %.3f s (%.3f ms/step)\n",
           setup, warm, steps, wall, 1e3 * wall / steps);
    printf(
        "dt = %.4e s (limits: acoustic %.3e, viscous %.3e, force %.3e, wall %.3e, "
        "diffusion %.3e)\n",
        S.dt, S.dt_limits[0], S.dt_limits[1], S.dt_limits[2], S.dt_limits[3], S.dt_limits[4]);
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
