/**
 * @file restart.h
 * @brief Checkpoint and restart of a run: where checkpoints live and how they rotate
 *        (rotate.c), when to write one and when to stop (trigger.c), and resuming from the
 *        newest valid one (resume.c). docs/checkpoint-format.md, docs/batch-jobs.md.
 */
#ifndef CHANSPH_RESTART_H
#define CHANSPH_RESTART_H

#include "output.h"
#include "scene.h"
#include "sim.h"

/** Exit codes of chansph (also in `chansph --help` and docs/batch-jobs.md). */
enum exit_code {
  EXIT_DONE = 0,      /*!< the run reached its end (final checkpoint written) */
  EXIT_INPUT = 1,     /*!< input error: scene, command line, no valid checkpoint */
  EXIT_INTERNAL = 2,  /*!< internal error (a bug) */
  EXIT_NUMERICAL = 3, /*!< numerical failure found by a health check; no checkpoint written */
  EXIT_IOERR = 74,    /*!< a checkpoint or output could not be written; the run stopped */
  EXIT_RESUBMIT = 75  /*!< checkpointed before the end (signal, STOP, walltime, --max-steps):
                           resume with `chansph resume DIR` */
};

/** Why a checkpoint is due after a step. */
enum trigger_why {
  TRIG_NONE = 0,  /*!< nothing to do */
  TRIG_PERIODIC,  /*!< every_steps or every_minutes: checkpoint and continue */
  TRIG_SIGNAL,    /*!< SIGTERM, SIGINT or SIGUSR1: checkpoint and stop */
  TRIG_STOP_FILE, /*!< DIR/STOP exists: checkpoint and stop (the file is removed) */
  TRIG_WALLTIME,  /*!< --walltime would be exceeded by one more step and a checkpoint */
  TRIG_MAX_STEPS  /*!< --max-steps reached */
};

/** Trigger state of one process (one job of a chain). */
struct trigger {
  char dir[2048];          /*!< run directory (DIR/STOP) */
  long every_steps;        /*!< checkpoint.every_steps (0: off) */
  double every_seconds;    /*!< checkpoint.every_minutes in seconds (0: off) */
  double walltime;         /*!< --walltime in seconds from the start of the process (0: none) */
  long max_steps;          /*!< --max-steps: steps of this process (0: no limit) */
  long step0;              /*!< step when this process started stepping */
  double wall_start;       /*!< wall clock at process start [s] */
  double last_wall;        /*!< wall clock of the last checkpoint or start [s] */
  long last_step;          /*!< step of the last checkpoint written or read (-1: none) */
  double step_wall;        /*!< wall clock of the end of the last step [s] */
  double step_seconds_max; /*!< longest step of this process [s] */
  double write_seconds;    /*!< longest checkpoint write so far, or an estimate [s] */
  int measured;            /*!< write_seconds was measured (else estimated from bytes) */
  double bytes;            /*!< state size [bytes], for the write-time estimate */
  int signal;              /*!< signal that stopped the run (0: none) */
};

/**
 * @brief Call first in main: the walltime counts from here, and the signal handlers are
 *        installed at once (a signal during start-up stops the run after its first step).
 */
void trigger_mark_start(void);

/**
 * @brief Install the signal handlers (SIGTERM, SIGINT, SIGUSR1 set a flag; SIGXFSZ is ignored so
 *        that a file-size limit turns into a write error) and start the clocks.
 * @param[out] T triggers
 * @param[in] dir run directory
 * @param[in] sc scene (checkpoint intervals)
 * @param[in] walltime seconds (0: none); max_steps steps of this process (0: no limit)
 * @param[in] step current step; state_bytes size of the state
 */
void trigger_init(struct trigger *T, const char *dir, const struct scene *sc, double walltime,
                  long max_steps, long step, double state_bytes);

/**
 * @brief After a step: is a checkpoint due, and does the run stop after it?
 * @return enum trigger_why (stop if > TRIG_PERIODIC)
 */
int trigger_check(struct trigger *T, long step);

/** @brief Text of a trigger reason for the log ("SIGTERM", "STOP file", ...). */
const char *trigger_text(const struct trigger *T, int why);

/** @brief Record a checkpoint written at step, taking seconds (learns the walltime margin). */
void trigger_wrote(struct trigger *T, long step, double seconds);

/**
 * @brief Parse "HH:MM:SS" (or "MM:SS" or seconds) into seconds.
 * @return 0 on success, nonzero if malformed
 */
int trigger_parse_walltime(const char *text, double *seconds);

/**
 * @brief Write a checkpoint of the run to DIR/checkpoints/ckpt_<step>.h5 atomically, then
 *        delete the oldest beyond checkpoint.keep. Logs the size and time.
 * @param[in] o output (run directory, accumulators, log)
 * @param[in] S simulation
 * @param[out] seconds wall time of the write
 * @return CHANSPH_OK, or CHANSPH_ERR with a message (earlier checkpoints untouched)
 */
int restart_save(struct output *o, struct sim *S, double *seconds);

/**
 * @brief Before a new run in DIR: refuse if DIR/checkpoints holds checkpoints, unless
 *        overwrite is set, in which case they are removed (the user asked for it).
 * @return CHANSPH_OK or CHANSPH_ERR with a message
 */
int restart_prepare_new(const char *dir, int overwrite);

/**
 * @brief Resume the run in DIR from its newest valid checkpoint: a corrupt, truncated,
 *        incomplete or future-version file, one of another run (its run_id is not DIR/run_id)
 *        and one whose file name disagrees with the step inside are reported and renamed
 *        NAME.skipped (nothing is deleted), and the previous one is tried. Overrides may change
 * only the keys documented as changeable (end time, output, statistics windows, health, threads,
 *        checkpoints); changes are logged.
 * @param[in] dir run directory
 * @param[in] n_set,set --set overrides
 * @param[out] sc scene (must outlive S)
 * @param[out] S simulation, restored
 * @param[out] o output, reopened and restored
 * @return CHANSPH_OK or CHANSPH_ERR with a message
 */
int restart_resume(const char *dir, int n_set, char *const *set, struct scene *sc, struct sim *S,
                   struct output *o);

/**
 * @brief Lock the run directory for the life of the process (rank 0 holds an fcntl write lock
 *        on DIR/.lock): a second chansph in the same directory gets a message naming the
 *        holder's process id. create: make DIR first if it does not exist (run); otherwise a
 *        missing DIR is not locked (resume then reports it). Collective.
 * @return CHANSPH_OK, or CHANSPH_ERR after a message
 */
int rundir_lock(const char *dir, int create);

/**
 * @brief Whether DIR is still the directory this process locked (the same inode, and DIR/.lock
 *        the same file): a directory deleted and recreated by another run, or moved away, is
 *        not; then nothing more may be written there. Called before every write of the run's
 *        files (stats.nc, particles.nc, snapshots, checkpoints). Collective.
 * @return CHANSPH_OK, or CHANSPH_ERR after a message
 */
int rundir_check(const char *dir);

/** @brief rundir_check() on rank 0 alone, without a message: 1 if DIR is still the directory
    this process locked (or it locked none). */
int rundir_is_held(const char *dir);

/**
 * @brief A new run's identity: CHANSPH_RUN_ID if set, else a random UUID; written to
 *        DIR/run_id and into every following checkpoint and snapshot (ckpt_set_run_id).
 * @param[out] id the identity (CKPT_RUN_ID_MAX bytes), the same on every rank
 * @return CHANSPH_OK, or CHANSPH_ERR after a message
 */
int rundir_new_id(const char *dir, char *id);

/**
 * @brief Read DIR/run_id. Collective.
 * @param[out] id the identity, or "" (CKPT_RUN_ID_MAX bytes)
 * @return 0, or 1 if the directory has none (a run started before run identities existed)
 */
int rundir_read_id(const char *dir, char *id);

/** @brief Record an identity in DIR/run_id and for the following writes. Collective. */
int rundir_set_id(const char *dir, const char *id);

/**
 * @brief Record this process in DIR/history, newest first: "YYYY-MM-DDTHH:MM:SSZ: COMMAND LINE
 *        (R MPI ranks x T threads)"; a new run (fresh) starts the file again. Rank 0 only (other
 *        ranks get NULL); a file that cannot be written is a warning, not an error.
 * @return the history text for the attribute `history` of stats.nc and particles.nc
 *         (malloc'd, no trailing newline), or NULL on ranks other than 0
 */
char *rundir_history(const char *dir, const char *cmdline, int fresh, int ranks, int threads);

/** @brief 1 if id is a valid run identity: 1 to 36 letters, digits, '.', '_', '-'. */
int rundir_valid_id(const char *id);

/** @brief State size in bytes of a run (for the write-time estimate and reports). */
double restart_state_bytes(struct output *o, struct sim *S);

/**
 * @brief (layout.c) Append the state a continuation needs to a list (particles by id with their
 * ids, wall values, step, time, last dt and force, flux-controller history). The particle and wall
 * fields are distributed (state.h): rank r of P names the ids [r N / P, (r+1) N / P). After
 * sim_init the particles are first sent to the ranks of their blocks (collective); after sim_create
 * the fields are those slots of the full arrays, to read a block into.
 * @param[in] S simulation (the fields point into its memory)
 * @param[in,out] L list
 */
void sim_state(struct sim *S, struct state_list *L);

#endif
