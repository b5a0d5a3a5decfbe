/**
 * @file contract.h
 * @brief The statistics contract: everything the solver hands the statistics engines, and
 *        nothing an engine owns. One snapshot of the particles (struct stats_snapshot), the
 *        parts of the x-acceleration a snapshot may carry (enum stats_part, which the solver's
 *        per-particle parts of part.h are defined from), and the scene as the engines see it
 *        (struct stats_scene: the channel's values and the engines' own keys), and the definition
 *        of a scene key (struct scene_key_def), which each engine gives for its own keys.
 *
 * The engines include this header, base headers and their own; never an engine's header to
 * get the contract, and never a solver header (docs/architecture.md, "Layers").
 */
#ifndef CHANSPH_CONTRACT_H
#define CHANSPH_CONTRACT_H

#include <mpi.h>
#include <stddef.h>
#include <stdint.h>

/** Parts of the acceleration a snapshot may carry (stats_snapshot.sx), STATS_PARTS per
    component and particle: the antisymmetric parts of the pair forces of the fluid neighbours
    (pressure, molecular viscous, eddy-viscous) and everything the walls exert (vertex
    neighbours, wall shear or wall law, the pair forces' non-antisymmetric rest); their sum is
    the particle's acceleration without the body force. The solver's `enum part_sx` (part.h)
    takes its values from these. */
enum stats_part {
  STATS_PART_PRESSURE, /*!< pressure pair force of the fluid neighbours */
  STATS_PART_VISCOUS,  /*!< molecular viscous pair force of the fluid neighbours */
  STATS_PART_MODEL,    /*!< eddy-viscous pair force of the fluid neighbours (LES) */
  STATS_PART_WALL,     /*!< everything the walls exert */
  STATS_PARTS          /*!< parts per component */
};

/** Values per particle in stats_snapshot.sx: the STATS_PARTS parts of the x, then of the y,
    then of the z acceleration. */
enum { STATS_ACC = 3 * STATS_PARTS };

/**
 * One snapshot of the particles, as plain arrays (the engine never sees solver structs).
 *
 * Across MPI ranks (docs/stats-format.md, "Statistics across ranks"): the arrays hold this
 * rank's owned particles, a block of the grid's pencils: columns [col0, col1) by planes
 * [plane0, plane1); particle a lies in the global pencil col[a]; the ranks of a block row
 * (comm_x, or comm without plane cuts) own contiguous column ranges in rank order covering
 * 0 .. ncol - 1, those of a block column (comm_z) contiguous plane ranges in rank order; within
 * a column the particles appear plane by plane in the same order on any decomposition; the
 * scalars are the same on all ranks. The engine state then comes out bitwise identical on every
 * rank and for any number of ranks. col = NULL puts every particle in column col0; with ncol = 0 as
 * well (the layout left unset by an initialiser) the layout is one rank owning column 0. comm =
 * MPI_COMM_NULL (or left zero by an initialiser, or MPI not initialised) is serial and makes no MPI
 * call.
 */
struct stats_snapshot {
  size_t n;                   /*!< particles */
  const double *x, *y, *z;    /*!< positions [m] */
  const double *u, *v, *w;    /*!< velocities [m/s] */
  const double *p, *rho, *m;  /*!< pressure [Pa], density [kg/m^3], mass [kg] */
  const double *ax, *ay, *az; /*!< accelerations without the body force [m/s^2], or NULL */
  /** Parts of the acceleration of the force pass that led to this state, STATS_ACC per
      particle (x, y, z parts, enum stats_part) [m/s^2], or NULL: the budgets. */
  const double *sx;
  /** The configurational part of the pressure part of sx, 3 per particle (x, y, z): the
      pressure pair forces' share 2 p_a / rho_a^2 sum_b m_b grad W_ab (with the gamma factors of
      the symmetric form), which vanishes for a uniform particle arrangement: the scheme's
      pressure noise [m/s^2]; NULL: not split. */
  const double *sx_noise;
  const double *nu_t;     /*!< eddy viscosity [m^2/s], or NULL (no LES) */
  const double *k_r;      /*!< residual kinetic energy [m^2/s^2], or NULL (no LES) */
  const int64_t *id;      /*!< global ids */
  const uint8_t *skip;    /*!< nonzero: not a fluid particle, not sampled */
  double t;               /*!< simulated time [s] */
  double fx;              /*!< streamwise body acceleration applied [m/s^2] */
  double dt;              /*!< the step that led to this state [s], or 0: unknown */
  const double *shift_dy; /*!< y-shift of each particle in that step [m], or NULL (none) */
  long step;              /*!< step number */
  double wall_fx[2];      /*!< x-force of the walls y = 0, 2 delta on the fluid [N];
                               NaN if unknown */
  const int *col;         /*!< global cell pencil of each particle, ix nplane + iz (the cell
                               column ix when nplane <= 1), or NULL (all in col0) */
  int ncol;               /*!< global cell columns along x (0 with col = NULL: serial) */
  int col0, col1;         /*!< this rank's columns [col0, col1) */
  int nplane;             /*!< global cell planes along z (0 or 1: the columns are not cut) */
  int plane0, plane1;     /*!< this rank's planes [plane0, plane1) (with nplane > 1) */
  MPI_Comm comm;          /*!< ranks sharing the snapshot; MPI_COMM_NULL: serial */
  MPI_Comm comm_x;        /*!< with nplane > 1 and the planes cut: the ranks of this rank's
                               block row (the same planes), ordered by column; else
                               MPI_COMM_NULL (then comm is the row) */
  MPI_Comm comm_z;        /*!< the ranks of this rank's block column (the same columns),
                               ordered by plane; MPI_COMM_NULL: the planes are not cut */
};

/** Types of a scene key (struct scene_key_def). */
enum scene_key_type {
  SCENE_INT,    /*!< an integer (int) */
  SCENE_LONG,   /*!< an integer (long) */
  SCENE_DOUBLE, /*!< a number */
  SCENE_CHOICE, /*!< one of the names of choices; the value is its index */
  SCENE_STRING, /*!< text (the solver's keys only) */
  SCENE_LIST    /*!< up to SCENE_LIST_MAX comma-separated numbers */
};

/** Flags of a scene key: it has no default and must be given; its lower bound is excluded; it
    is a list of y+ levels, which (when not empty) need a friction velocity (stats.u_tau_ref, or
    a positive drive.force). */
enum { SCENE_REQUIRED = 1, SCENE_LO_OPEN = 2, SCENE_Y_PLUS = 4 };

/** A bound of +-SCENE_NO_BOUND is no bound: any finite value. */
#define SCENE_NO_BOUND 1e300

enum { SCENE_LIST_MAX = 8 };

/** The value of a numeric key: a list entry by entry; a number (an integer exactly, a choice as
    its index) as its one entry. */
struct scene_list {
  int n;                    /*!< entries */
  double v[SCENE_LIST_MAX]; /*!< values */
};

/**
 * One scene key, declared by the module that reads it: an engine declares its own keys beside
 * its code (struct stats_engine.keys, engine.h); the scene (solver/scene.c) collects them
 * into its one table, which parses, validates, documents and writes every key.
 */
struct scene_key_def {
  const char *section, *name; /*!< "[section]" and "name" of the key */
  enum scene_key_type type;   /*!< its type */
  const char *def;            /*!< default as scene text; NULL for a required key */
  double lo, hi;              /*!< allowed range (inclusive unless SCENE_LO_OPEN; list entries) */
  int flags;                  /*!< SCENE_REQUIRED, SCENE_LO_OPEN, SCENE_Y_PLUS */
  const char *const *choices; /*!< SCENE_CHOICE: the names, NULL-terminated */
  const char *unit, *help;    /*!< unit and the line of docs/scenes.md */
};

/**
 * The scene as the engines see it: the channel, the fluid and the averaging as resolved
 * values (derived ones computed by the solver, so no engine repeats a formula of the scene),
 * and the values of the engines' own keys ([stats], [correlations], [lagrangian], ...), which
 * an engine reads by its own key definitions (stats_scene_int() and its kin below,
 * stats_scene.c). Each engine builds its configuration from it (struct
 * stats_engine.init_scene, engine.h).
 */
struct stats_scene {
  int dim;                /*!< 2 or 3 */
  double delta;           /*!< channel half-width [m] */
  double lx, lz;          /*!< periodic lengths [m] (lz unused in 2-D) */
  double dr;              /*!< initial particle spacing [m] */
  double h;               /*!< smoothing length [m] */
  double nu;              /*!< kinematic viscosity [m^2/s] */
  double rho0;            /*!< reference density [kg/m^3] */
  int les;                /*!< 1: an eddy-viscosity model runs (nu_t, k_r in the snapshots) */
  double u_tau;           /*!< friction velocity that places y+ levels [m/s] */
  double t_average_start; /*!< start of the averaging [s] */
  double t_end;           /*!< end of the run [s] */
  double window;          /*!< length of an averaging window [s] (stats_window_length()) */
  int bins;               /*!< wall-normal bins: output.n_bins, or if that is 0 one per
                               particle layer, 2 delta / dr - 1 */
  int bins_uniform;       /*!< 1: output.n_bins gave the bins (uniform between the walls) */
  int columns;            /*!< cell columns of the global grid along x (the Eulerian engine's
                               per-column sums) */
  int n_keys;             /*!< the engines' keys */
  const struct scene_key_def *const *key_def; /*!< their definitions, n_keys */
  const struct scene_list *key_value;         /*!< and their values, n_keys */
};

/**
 * @brief The value of an engine's key, found by its definition (the engine's own table).
 *        Dies if the scene does not hold the key (an engine not in the list, a bug).
 */
const struct scene_list *stats_scene_value(const struct stats_scene *sc,
                                           const struct scene_key_def *key);

/** @brief An integer or choice key of an engine (a choice as its index). */
int stats_scene_int(const struct stats_scene *sc, const struct scene_key_def *key);

/** @brief A number key of an engine. */
double stats_scene_double(const struct stats_scene *sc, const struct scene_key_def *key);

/**
 * @brief A list key of an engine ("lagrangian.pdf_x"): up to max values into v.
 * @return the number of values the key holds
 */
int stats_scene_list(const struct stats_scene *sc, const struct scene_key_def *key, double *v,
                     int max);

/**
 * @brief Wall-normal levels given in wall units by a list key ("correlations.y_plus"): y+ as
 *        given and the heights y = y+ nu / u_tau from the lower wall [m] (sc->u_tau).
 * @param[out] y_plus,y up to max levels each
 * @return the number of levels (at most max)
 */
int stats_scene_levels(const struct stats_scene *sc, const struct scene_key_def *key,
                       double *y_plus, double *y, int max);

/**
 * @brief Length of an averaging window [s]: the key stats.window, or if that is 0 a tenth of
 *        t_end - t_average_start (a tenth of t_end, or 1 s, if that is not positive).
 */
double stats_window_length(double key, double t_average_start, double t_end);

#endif
