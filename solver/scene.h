/**
 * @file scene.h
 * @brief The scene (input file): one table of keys drives parsing, validation, --help and
 *        docs/scenes.md. After scene_load() the struct is passed as const.
 */
#ifndef CHANSPH_SCENE_H
#define CHANSPH_SCENE_H

#include <stdio.h>

#include "contract.h" /* struct scene_key_def, struct scene_list */

enum drive_mode { DRIVE_FORCE = 0, DRIVE_FLUX = 1 };
enum flux_controller { CONTROLLER_EQ343 = 0, CONTROLLER_EQ338 = 1 };
enum viscous_form { VISCOUS_MORRIS = 0, VISCOUS_VIOLEAU = 1 };
enum wall_weight { WALL_WEIGHT_DISCRETE = 0, WALL_WEIGHT_ANALYTIC = 1 };
enum wall_pressure {
  WALL_PRESSURE_LATTICE = 0,
  WALL_PRESSURE_CONSISTENT = 1,
  WALL_PRESSURE_ANALYTIC = 2
};
enum laplacian_norm { LAPNORM_WALL_NORMAL = 0, LAPNORM_TRACE = 1, LAPNORM_NONE = 2 };
enum init_profile {
  INIT_REST = 0,
  INIT_LAMINAR = 1,
  INIT_REICHARDT = 2,
  INIT_WAVE = 3,
  INIT_SYNTHETIC = 4
};
/** init.density: the densities of an init.from state kept, or shifted to the mean rho0. */
enum init_density { INIT_DENSITY_KEEP = 0, INIT_DENSITY_RHO0 = 1 };
enum les_model { LES_NONE = 0, LES_SMAGORINSKY = 1, LES_PROFILE = 2 };
/** A prescribed eddy-viscosity profile (les.model = profile): nu_r / nu at wall distances y /
    delta, linear in between and constant beyond the first and the last point. */
enum { NU_PROFILE_MAX = 256 };
struct nu_profile {
  int n;                    /*!< points */
  double y[NU_PROFILE_MAX]; /*!< wall distance over delta, increasing [-] */
  double v[NU_PROFILE_MAX]; /*!< nu_r / nu there, > -1 [-] */
};
enum les_strain { STRAIN_GRADIENT = 0, STRAIN_VIOLEAU_ISSA = 1 };
enum pressure_gradient { PGRAD_STANDARD = 0, PGRAD_CORRECTED = 1, PGRAD_KGC = 2 };
/** Pair form of the volume diffusion (term_diffusion.h). */
enum diffusion_form { DIFFUSION_FERRAND = 0, DIFFUSION_DELTA_SPH = 1 };
enum shifting { SHIFT_NONE = 0, SHIFT_FICKIAN = 1 };
enum shift_velocity { SHIFT_KEEP = 0, SHIFT_TAYLOR = 1, SHIFT_CONSERVATIVE = 2 };
enum wall_collision { WALL_STOP = 0, WALL_REFLECT = 1 };

/** Room for the keys the engines declare (struct stats_engine.keys), and for all the keys. */
enum { SCENE_STATS_KEYS = 64, SCENE_MAX_KEYS = 256 };

/** Every parameter of a run, with units. Derived quantities are marked. */
struct scene {
  /* [domain] */
  int dim;      /*!< 2 or 3 */
  double delta; /*!< channel half-width [m]; walls at y = 0 and y = 2 delta */
  double lx;    /*!< periodic length in x [m] */
  double lz;    /*!< periodic length in z [m] (3-D) */
  double dr;    /*!< initial particle spacing [m] */
  /* [sph] */
  double h_over_dr;   /*!< smoothing length over spacing [-] */
  int kernel;         /*!< enum kernel_shape (kernel.h) */
  double xi;          /*!< volume-diffusion constant [-]; 0 selects 1000 dr / (2 delta) */
  int diffusion;      /*!< enum diffusion_form: the volume diffusion's pair form */
  double diff_delta;  /*!< delta of the delta-SPH form [-] */
  int diff_substeps;  /*!< sub-steps of the volume diffusion in a time step [-] */
  double damper;      /*!< acoustic damper alpha of zeta = alpha rho0 c0 h [-]; 0 = off */
  double wall_dmin;   /*!< delta r of Eq. 2.148 over dr [-] */
  double eta2;        /*!< regularisation of 1/r^2 in the viscous term, over h^2 [-] */
  int viscous;        /*!< enum viscous_form */
  int lap_norm;       /*!< enum laplacian_norm */
  int wall_weight;    /*!< enum wall_weight */
  int wall_pressure;  /*!< enum wall_pressure */
  int pgrad;          /*!< enum pressure_gradient */
  int shifting;       /*!< enum shifting: particle shifting after each step */
  double shift_coef;  /*!< shifting coefficient C of delta r = -C h^2 grad C_a [-] */
  int shift_velocity; /*!< enum shift_velocity: what the shift does to the velocities */
  int wall_collision; /*!< enum wall_collision: a particle that reaches a wall */
  /* [les] */
  int les;         /*!< enum les_model */
  double cs;       /*!< Smagorinsky constant C_S [-] */
  double filter_h; /*!< filter width Delta_G over h [-] */
  int strain;      /*!< enum les_strain */
  int strain_lag;  /*!< strain sums in the force loop, applied one step later (1) or not (0) */
  int van_driest;  /*!< van Driest damping on (1) or off (0) */
  double a_plus;   /*!< A+ of the damping [-] */
  double cy;       /*!< Yoshizawa constant C_Y [-]; 0 = no residual kinetic energy */
  char les_profile[512];     /*!< les.model = profile: the file of nu_r / nu against y / delta */
  struct nu_profile nu_prof; /*!< derived: that file's table, read by validate() */
  /* [wall] */
  int wall_law; /*!< enum wall_law (walllaw.h) */
  double kappa; /*!< von Karman constant [-] */
  double log_b; /*!< log-law intercept B [-] */
  /* [fluid] */
  double nu;           /*!< kinematic viscosity [m^2/s] */
  double rho0;         /*!< reference density [kg/m^3] */
  double c0;           /*!< numerical speed of sound [m/s] */
  double zeta;         /*!< Tait exponent [-] */
  double p_background; /*!< background pressure over rho0 c0^2 [-] */
  double gravity_y;    /*!< wall-normal body acceleration [m/s^2] */
  double nu_start;     /*!< viscosity at t = 0 of the schedule [m^2/s]; 0 = no schedule */
  double nu_ramp_begin, nu_ramp_end; /*!< the schedule ramps nu_start -> nu over this [s] */
  /* [drive] */
  int drive_mode; /*!< enum drive_mode */
  double force;   /*!< body acceleration along x in force mode [m/s^2] */
  double u_bulk;  /*!< target bulk velocity in flux mode [m/s] */
  int controller; /*!< enum flux_controller */
  /* [time] */
  double t_end;       /*!< end time [s] */
  double dt_fixed;    /*!< fixed time step [s]; 0 = adaptive */
  double cfl;         /*!< CFL factor of Eq. 2.160 [-] */
  double c_visc;      /*!< factor of Eq. 2.161 [-] */
  double c_force;     /*!< factor of Eq. 2.162 [-] */
  double c_gamma;     /*!< factor of Eq. 2.163 [-]; 0 disables */
  double c_diffusion; /*!< factor of the volume diffusion's limit [-]; 0 disables */
  long max_steps;     /*!< stop after this many steps (0 = no limit) */
  /* [init] */
  int init_profile;      /*!< enum init_profile */
  double init_wave;      /*!< amplitude of the wall-normal wave [m/s] */
  double init_streaks;   /*!< amplitude of streamwise streaks [m/s] */
  int init_streak_kz;    /*!< streaks across lz [-] */
  double init_modes;     /*!< amplitude of the divergence-free sinusoidal modes [m/s] */
  int init_mode_kx;      /*!< their wavenumber along x (periods in lx) [-] */
  int init_mode_kz;      /*!< their wavenumber along z (periods in lz) [-] */
  double init_noise;     /*!< amplitude of the random noise per component [m/s] */
  long init_seed;        /*!< key of the counter-based generator [-] */
  long init_eddies;      /*!< synthetic eddies (0 = box volume / sigma^3) [-] */
  double init_eddy_size; /*!< synthetic-eddy half-width sigma [delta] */
  char init_from[512];   /*!< particles.nc of an earlier run to start from, or empty */
  int init_density;      /*!< enum init_density: init.from's densities kept or shifted */
  /* [output] */
  int log_every;          /*!< steps between log lines */
  int series_every;       /*!< steps between time-series records */
  int stats_every;        /*!< steps between statistics samples */
  double write_every;     /*!< simulated seconds between stats.nc rewrites; 0 = only at the end */
  double t_average_start; /*!< start of the averaging window [s] */
  int n_bins;             /*!< wall-normal bins; 0 = 2 delta / dr - 1 */
  int particles;          /*!< write the final particle state to particles.nc (1) or not (0) */
  int q_criterion;        /*!< add the Q criterion to particles.nc (1) or not (0) */
  /* [health] */
  int health_every; /*!< steps between full health checks */
  /* [run] */
  int threads;                 /*!< OpenMP threads; 0 = OMP_NUM_THREADS / all */
  int balance_every;           /*!< steps between load-balance checks (MPI) */
  int check_ids;               /*!< debug: check every step that each id is on exactly one rank */
  struct scene_list partition; /*!< cell columns per rank at the start (empty: even split) */
  struct scene_list ranks;     /*!< Px, Pz blocks (empty: the factorisation with fewest ghosts) */
  double balance_threshold;    /*!< re-partition above (1 + this) x mean particles per rank */
  /* [checkpoint] */
  long ckpt_every_steps;     /*!< steps between checkpoints; 0 = not by steps */
  double ckpt_every_minutes; /*!< wall-clock minutes between checkpoints; 0 = not by time */
  int ckpt_keep;             /*!< checkpoints kept in DIR/checkpoints */
  /* [snapshots] */
  double snap_every; /*!< simulated time between particle snapshots [s]; 0 = none */

  /* the statistics engines' sections ([stats], [correlations], [lagrangian], [quadrants],
     [pdfs]): the values of the keys each engine declares (struct stats_engine.keys), in the
     order of the scene's table; read through scene_stats_value() and, by the engines,
     through struct stats_scene */
  struct scene_list stats_keys[SCENE_STATS_KEYS];

  /* bookkeeping, not keys */
  char path[512]; /*!< scene file path */
};

/**
 * @brief Fill a scene with the table defaults, parse a file and apply --set overrides.
 * @param[out] s the scene
 * @param[in] path INI file, or NULL to start from defaults only
 * @param[in] n_set, set "section.key=value" overrides
 * @return CHANSPH_OK or CHANSPH_ERR after printing every problem with file, line and key
 */
int scene_load(struct scene *s, const char *path, int n_set, char *const *set);

/**
 * @brief Like scene_load(), but the scene is a text in memory (e.g. from a checkpoint).
 * @param[out] s the scene
 * @param[in] name what to call the text in messages (e.g. "ckpt_000100.h5:/scene")
 * @param[in] text INI text
 * @param[in] n_set, set overrides
 * @return CHANSPH_OK or CHANSPH_ERR
 */
int scene_load_text(struct scene *s, const char *name, const char *text, int n_set,
                    char *const *set);

/** @brief Number of keys in the scene table. */
int scene_key_count(void);

enum { SCENE_VALUE_MAX = 640 }; /*!< room for any key's value text (paths, lists) */

/**
 * @brief Name and current value of key k, as "section.key" and as scene text.
 * @param[in] s scene
 * @param[in] k key index, 0 .. scene_key_count()-1
 * @param[out] name buffer of at least 64 bytes
 * @param[out] value buffer of at least SCENE_VALUE_MAX bytes
 */
void scene_key(const struct scene *s, int k, char *name, char *value);

/**
 * @brief Derived smoothing length h = h_over_dr * dr [m].
 */
double scene_h(const struct scene *s);

/** @brief Effective volume-diffusion constant xi (mixing-length default, thesis Sec. 3.2). */
double scene_xi(const struct scene *s);

/** @brief The eddy viscosity is on (les.model != none). */
int scene_les(const struct scene *s);

/** @brief The LES force loop forms the next step's eddy viscosity (les.strain = gradient and
           les.strain_lag = 1). */
int scene_strain_lag(const struct scene *s);

/** @brief Wall stresses are carried to the vertices: the Smagorinsky model (its van Driest
           damping) or a turbulent wall law; a prescribed nu_r(y) needs none. */
int scene_wall_tau(const struct scene *s);

/** @brief Effective number of wall-normal bins. */
int scene_bins(const struct scene *s);

/**
 * @brief Write the fully resolved scene (defaults included) as INI text.
 * @return malloc'd string
 */
char *scene_text(const struct scene *s);

/** @brief Write docs/scenes.md (the key reference) to a stream. */
void scene_write_doc(FILE *f);

/**
 * @brief The value of an engine's key (struct stats_engine.keys), found by its definition:
 *        a list entry by entry, a number (a choice as its index) as its one entry. Dies if the
 *        key is not an engine's key of the scene.
 */
const struct scene_list *scene_stats_value(const struct scene *s, const struct scene_key_def *key);

/** @brief The number (a choice as its index) of an engine's key: scene_stats_value()->v[0]. */
double scene_stats_num(const struct scene *s, const struct scene_key_def *key);

/**
 * @brief The engines' keys of the scene's table, in the order of their values in
 *        struct scene.stats_keys (the view of the statistics engines, struct stats_scene).
 * @param[out] n how many
 */
const struct scene_key_def *const *scene_stats_defs(int *n);

/** @brief Name of an enum value of a choice key, e.g. scene_choice("drive.mode", 1) = "flux". */
const char *scene_choice(const char *key, int value);

#endif
