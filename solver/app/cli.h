/**
 * @file cli.h
 * @brief Command line of the chansph program, and the benchmark command.
 */
#ifndef CHANSPH_CLI_H
#define CHANSPH_CLI_H

#include "scene.h"

enum command { CMD_HELP, CMD_VERSION, CMD_RUN, CMD_BENCH, CMD_SCENE_DOC, CMD_RESUME };

/** Parsed command line. */
struct cli {
  enum command cmd;
  const char *scene;    /*!< scene file (bench: optional) */
  char out[2048];       /*!< run directory */
  int n_set;            /*!< number of --set overrides */
  char **set;           /*!< the overrides (pointers into argv) */
  int overwrite;        /*!< --overwrite */
  int fpe;              /*!< --fpe: trap floating-point exceptions */
  long steps;           /*!< bench: --steps */
  long inject_step;     /*!< --inject-nan STEP:ID (fault injection for the stability tests) */
  long long inject_id;  /*!< particle whose u becomes NaN after that step; -1 = none */
  long max_steps;       /*!< run/resume: --max-steps, steps of this process (0: no limit) */
  const char *walltime; /*!< run/resume: --walltime HH:MM:SS (NULL: none) */
  char *cmdline;        /*!< the command line (malloc'd), for the history of the run */
  int help;             /*!< COMMAND --help: print the command's usage and exit 0 */
};

/**
 * @brief Parse argv.
 * @return CHANSPH_OK, or CHANSPH_ERR after printing what is wrong and the usage
 */
int cli_parse(int argc, char **argv, struct cli *c);

/** @brief Print the usage text of every command. */
void cli_usage(void);

/** @brief Print the usage of one command (`chansph COMMAND --help`). */
void cli_command_usage(enum command cmd);

/**
 * @brief The default benchmark case (issue 2, acceptance 8): 3-D channel 1.6 x 1.0 x 1.0,
 *        dr = 0.025, h = 1.3 dr, c0 = 10, nu = 0.1, rho0 = 1000, body force 0.8, from rest.
 *        Settings given with --set are applied on top.
 * @param[out] sc scene
 * @param[in] c command line (scene file, if any, replaces the default case)
 * @return CHANSPH_OK or CHANSPH_ERR
 */
int cli_bench_scene(struct scene *sc, const struct cli *c);

/**
 * @brief Run a fixed number of steps and print the cost; last line "particle-steps/s: N".
 * @return process exit code
 */
int cli_bench(const struct scene *sc, long steps);

#endif
