/**
 * @file euler.h
 * @brief Eulerian statistics of the channel: wall-normal bins (bin sampling, thesis Eq.
 *        5.54-5.55), averaged over x, z and time (optionally folded over the two halves).
 *
 * The engine keeps one moment record (moments.h) per bin and averaging window. A window is a
 * scene-chosen interval of simulated time; closed windows are kept, so any range of them can
 * be re-averaged afterwards (chansph extract --window) and their means are the batch means
 * of the standard errors. The windows are the whole state: the results are a pure function
 * of them (euler_finalise), for the running engine and for the extract command alike.
 *
 * Rows of the window arrays: 0 .. nwin-1 are closed windows, row nwin is the open one.
 */
#ifndef CHANSPH_EULER_H
#define CHANSPH_EULER_H

#include <stddef.h>
#include <stdint.h>

#include "contract.h"

struct state_list;
struct stats_engine;

/** Per window and profile point, the momentum budget by the method of planes (docs/theory.md,
    "Momentum budget"): snapshots with the parts, then sums over them of the x-momentum flux
    through the plane y = y_i per unit area and rho0 carried by the pressure, viscous and
    eddy-viscous pair forces and the walls, the body force on the fluid between the plane and
    the centre (what the flux must balance) and the net pair force on the fluid of that side
    (the scheme's momentum source, zero if it conserves momentum) [m^2/s^2]; and the momentum
    of that fluid at the window's first and last such snapshot, for its rate of change. */
enum {
  PL_N,
  PL_PRESSURE,
  PL_VISCOUS,
  PL_MODEL,
  PL_WALL,
  PL_DRIVE,
  PL_SOURCE,
  PL_MU_FIRST, /* not sums: the x-momentum of that fluid per unit area and rho0 [m^2/s] */
  PL_MU_LAST,  /* at the first and the last snapshot of the window with forces, */
  PL_T_FIRST,  /* and their times [s]: its rate of change is the unsteady term */
  PL_T_LAST,
  PL_LEN
};

/** Per window and bin (format 1.4; a separate record, so that earlier checkpoints stay
    readable): the snapshots with the particles' kinetic flux through the bin's planes and the
    sum over them of -(sum of m u v over the bin) / (rho0 A w) [m^2/s^2]; then the window's
    first such snapshot: 1, and its values of PL_PRESSURE .. PL_DRIVE and of the kinetic flux.
    A range leaves its first snapshot's fluxes out: each snapshot's forces stand for the steps
    since the one before, and the momentum changes from the first snapshot on. */
enum { KN_N, KN_SUM, KN_FIRST, KN_F, KN_F_KINETIC = KN_F + PL_DRIVE - PL_PRESSURE + 1, KN_LEN };

/** Per window and bin (format 1.14; optional, so that earlier checkpoints stay readable): the
    total of the momentum budget from every statistics snapshot, not only the budget ones. The
    records are those of the parts (PL_LEN and KN_LEN, the same sums and the same first
    snapshot apart) with the whole acceleration of the force pass in place of its parts:
    PL_PRESSURE holds the flux of all the forces, PL_VISCOUS, PL_MODEL, PL_WALL are zero. The
    force pass gives the whole acceleration on every step; its split into parts needs another
    pass over the pairs (stats.budget_every). total_stress_all and momentum_change_all come
    from these: a budget that closes over every snapshot while the parts are sampled sparsely. */
enum { TL_FORCES = PL_PRESSURE };

/** Per-window scalars: nominal interval, snapshots, sums over snapshots. */
enum { WIN_T0, WIN_T1, WIN_NSNAP, WIN_SUM_FX, WIN_SUM_TW0, WIN_SUM_TW1, WIN_LEN };

/** Geometry and physics the Eulerian engine needs (filled from the scene by the caller). */
struct euler_config {
  int nb;            /*!< bins */
  double y0, y1;     /*!< range of the uniform bins [m]; samples outside go to the end bins */
  int fold;          /*!< 1: map the upper half onto the lower one (y -> 2 delta - y, v -> -v) */
  double delta;      /*!< channel half-width [m] */
  double nu;         /*!< kinematic viscosity [m^2/s] */
  double rho0;       /*!< reference density [kg/m^3] */
  double area;       /*!< area of one wall (lx lz in 3-D, lx in 2-D) [m^2 or m] */
  double wall_layer; /*!< thickness of the fluid layer the wall vertices stand for: their mass
                          per wall over rho0 and the wall area, dr/2 (part_create) [m] */
  double t_start;    /*!< start of the averaging [s] */
  double window;     /*!< length of an averaging window [s] */
  int les;           /*!< 1: eddy viscosity and residual kinetic energy profiles too */
  int method;        /*!< EULER_BINS (Eq. 5.54-5.55) or EULER_SPH (Eq. 5.56) */
  double h;          /*!< smoothing length of the SPH interpolation [m] */
  int dim;           /*!< 2 or 3 (shape of the plane-averaged kernel) */
};

/** How particles are assigned to the wall-normal profile points. */
enum { EULER_BINS = 0, EULER_SPH = 1 };

enum { EULER_W1_N = 512 }; /*!< table points of the plane-averaged kernel over q in [0, 2] */

/** The engine's scene keys, section [stats] (euler_nc.c): the solver reads the switch, the
    budget interval, the window, u_tau_ref and the convergence target through them too. */
extern const struct scene_key_def euler_key_eulerian, euler_key_budget_every, euler_key_window,
    euler_key_fold, euler_key_method, euler_key_u_tau_ref, euler_key_target_stderr,
    euler_key_target_profiles, euler_key_target_corr_ratio, euler_key_target_windows;

/** The per-window arrays of struct euler (win, mom, snp, pln, kin, rsb, tpl, tkn), in the order
    of their table in euler.c (checkpoint names, record widths, formats). */
enum { EULER_ARRAYS = 8 };

struct euler;
/** What the checkpoint callbacks of one per-window array receive: the engine and the array's
    line of the table in euler.c. */
struct euler_array_owner {
  struct euler *e; /*!< the engine */
  int a;           /*!< the array, 0 .. EULER_ARRAYS - 1 */
};

/** The raw state: windows of per-bin moment records. */
struct euler {
  struct euler_config cfg;
  size_t nwin;               /*!< closed windows */
  size_t cap;                /*!< rows allocated (>= nwin + 1) */
  double *win;               /*!< [row][WIN_LEN] */
  double *mom;               /*!< [row][nb][MOM_LEN] moment records of the samples */
  double *snp;               /*!< [row][nb][SCAL_LEN] moments of the per-snapshot bin means of u */
  double *pln;               /*!< [row][nb][PL_LEN] momentum budget sums (enum above) */
  double *kin;               /*!< [row][nb][KN_LEN] kinetic flux of the budget (enum above) */
  double *rsb;               /*!< [row][nb][RW_LEN] Reynolds-stress budget sums (euler_rs.h) */
  double *tpl;               /*!< [row][nb][PL_LEN] the budget's total, every snapshot */
  double *tkn;               /*!< [row][nb][KN_LEN] its kinetic flux, every snapshot */
  void *work;                /*!< scratch of euler_sample across ranks (euler.c) */
  size_t nsub;               /*!< column subtrees gathered at the last snapshot (diagnostic) */
  double w1[EULER_W1_N + 1]; /*!< plane-averaged kernel W1(q), q = |y_a - y_i| / h (SPH) */
  struct euler_array_owner owners[EULER_ARRAYS]; /*!< set by euler_state() */
};

/** Components of the Reynolds-stress budgets (EP_RSB + component * RS_NTERM + term). */
enum { RS_UU, RS_VV, RS_WW, RS_UV, RS_K, RS_NCOMP };

/** Terms of each budget, contributions to d<u_i'u_j'>/dt per unit mass [m^2/s^3]
    (docs/theory.md, "Reynolds-stress budgets"): the pair parts of the acceleration (pressure,
    molecular viscous, eddy-viscous), the walls, the body force, the transfer by the particles'
    displacements (production + turbulent transport), the production from the profiles, the
    transport (transfer - production), the rate of change, the closure (sum of the first
    six less the rate) and the configurational (noise) part of the pressure term. */
enum {
  RT_PRESSURE,
  RT_VISCOUS,
  RT_MODEL,
  RT_WALL,
  RT_DRIVE,
  RT_TRANSFER,
  RT_PRODUCTION,
  RT_TRANSPORT,
  RT_RATE,
  RT_CLOSURE,
  RT_NOISE, /* the configurational part of RT_PRESSURE (pressure noise), not in the closure */
  RS_NTERM
};

/** Finished profiles: names, units and long names are in euler_prof_meta. */
enum {
  EP_Y,
  EP_Y_MEAN,
  EP_N,
  EP_U,
  EP_V,
  EP_W,
  EP_P,
  EP_RHO,
  EP_UU,
  EP_VV,
  EP_WW,
  EP_UV,
  EP_UW,
  EP_VW,
  EP_SE_U, /* stderr of u, v, w, p, rho, uu, vv, ww, uv, uw, vw in that order */
  EP_SE_END = EP_SE_U + 11,
  EP_SKEW_U = EP_SE_END,
  EP_SKEW_V,
  EP_SKEW_W,
  EP_FLAT_U,
  EP_FLAT_V,
  EP_FLAT_W,
  EP_VISC,
  EP_TOTAL,
  EP_TOTAL_EXPECTED,
  EP_NUT,
  EP_KR,
  EP_TAU_REYNOLDS, /* the momentum budget, method of planes: see euler_prof_meta */
  EP_TAU_VISCOUS,
  EP_TAU_MODEL,
  EP_TAU_PAIR,
  EP_TAU_WALL,
  EP_TAU_ADVECT,
  EP_TAU_SOURCE,
  EP_TAU_INERTIA,
  EP_SE_TAU, /* stderr of the six above and of total_stress, in that order */
  EP_SE_TAU_END = EP_SE_TAU + 7,
  EP_RSB = EP_SE_TAU_END, /* the Reynolds-stress budgets: [component][term] (enums above) */
  EP_RSB_END = EP_RSB + RS_NCOMP * RS_NTERM,
  EP_RSB_SE = EP_RSB_END, /* their standard errors, in the same order */
  EP_RSB_SE_END = EP_RSB_SE + RS_NCOMP * RS_NTERM,
  EP_SE_SF = EP_RSB_SE_END, /* stderr of u, v, w skewness, then u, v, w flatness (batch means) */
  EP_SE_SF_END = EP_SE_SF + 6,
  EP_UU_BIN = EP_SE_SF_END, /* uu .. vw about the bin mean (with the mean's spread over the bin) */
  EP_LOCAL = EP_UU_BIN + 6, /* 1: EP_UU .. EP_VW are about the local mean U(y); 0: the bin mean */
  EP_CORR_TIME,             /* the bin's correlation time of its bin means of u [s] */
  EP_NEFF,                  /* effective number of independent windows of its batch means */
  EP_SHORT,                 /* 1: the windows are shorter than the bin's correlation time */
  EP_ALL_TOTAL,             /* the momentum budget's total from every snapshot (TL_FORCES), */
  EP_ALL_EXPECTED,          /* its expected value, */
  EP_ALL_INERTIA,           /* the momentum change over the same snapshots */
  EP_ALL_SE,                /* and the total's standard error */
  EP_NPROF
};

/** Name, units and long name of each finished profile. */
struct euler_meta {
  const char *name, *units, *long_name;
};
extern const struct euler_meta euler_prof_meta[EP_NPROF];

/** Finished statistics of a range of windows. */
struct euler_result {
  int nb;
  double *prof[EP_NPROF]; /*!< each nb values; NaN where a bin has no samples */
  double u_tau_wall;      /*!< from the mean wall shear stress the solver applied [m/s] */
  double u_tau_force;     /*!< from the force balance tau_w = rho delta <f_x> (Eq. 5.14) [m/s] */
  double u_tau;           /*!< the one used for wall units (wall, else force) [m/s] */
  double u_tau_stderr;    /*!< batch-means standard error of u_tau [m/s] */
  double re_tau;          /*!< u_tau delta / nu */
  double corr_time;       /*!< integrated correlation time of the bin means of u [s] */
  double n_eff;           /*!< effective independent windows at corr_time (NaN: not measured) */
  int local_mean;         /*!< 1: every bin's stresses are about the local mean U(y) */
  double balance_error;   /*!< max |total - expected| / u_tau_force^2 over interior bins */
  int budget;             /*!< 1: total_stress is the method-of-planes budget (snapshots with
                               the parts of the acceleration); 0: nu dU/dy - <u'v'> */
  int rs_budget;          /*!< 1: the Reynolds-stress budgets (EP_RSB ..) were sampled */
  double t0, t1;          /*!< averaged interval [s] */
  double snapshots;       /*!< snapshots averaged */
  int n_batches;          /*!< complete windows used as batches for the standard errors */
};

/** @brief Set up an empty engine. */
void euler_init(struct euler *e, const struct euler_config *cfg);

/** @brief Free the engine. */
void euler_free(struct euler *e);

/** @brief Bytes of the scratch of euler_sample (per-column partials, gathered subtrees). */
size_t euler_work_bytes(const struct euler *e);

/** @brief Lower bound of those bytes before the engine exists: the per-column partials of nb
    bins over ncol cell columns (the memory check of a scene). */
size_t euler_sample_bytes(int nb, int ncol);

/**
 * @brief Add one snapshot. Implements: thesis Eq. 5.54-5.55 (bins) or 5.56 (stats.method =
 *        sph), and the wall-stress sample of Eq. 5.13-5.14.
 *        Each fluid particle to its bin (Eq. 5.54-5.55), one wall-stress
 *        and body-force sample to the window; closes windows that ended before s->t.
 *        The particles of each column go, in memory order, into per-(column, bin) records;
 *        these are merged pairwise over a fixed binary tree on the global column index
 *        (each rank merges the subtrees inside its columns, the subtree records are gathered
 *        to every rank) into one record per bin and snapshot, merged into the window:
 *        independent of the thread count and of the number of ranks (a collective call on
 *        s->comm).
 */
void euler_sample(struct euler *e, const struct stats_snapshot *s);

/** @brief Close the open window if t (the time the run reached) lies at or past its end, as
 *         the next snapshot would (engine.h, close). */
void euler_close(struct euler *e, double t);

/**
 * @brief Statistics of rows [r0, r1) merged in row order (bitwise reproducible).
 *        Implements: means and Reynolds stresses of Sec. 5.2.3.1, u_tau (Eq. 5.14 and the wall
 *        force), the total shear stress of Eq. 5.11-5.13.
 *        Standard errors from the batch means of the complete windows in the range.
 * @param[in] cfg configuration (bins, delta, nu, rho0, area)
 * @param[in] win,mom,snp,pln,kin,rsb,tpl,tkn raw rows, as in struct euler (pln may be NULL: no
 *            budget; kin may be NULL: no advective part; rsb may be NULL: no Reynolds-stress
 *            budget; tpl, tkn may be NULL or without snapshots: no total_stress_all)
 * @param[in] complete per-row flag: 1 for a closed window (batch), 0 for a partial one
 * @param[out] res result (allocated; free with euler_result_free)
 */
void euler_finalise(const struct euler_config *cfg, const double *win, const double *mom,
                    const double *snp, const double *pln, const double *kin, const double *rsb,
                    const double *tpl, const double *tkn, const int *complete, size_t r0, size_t r1,
                    struct euler_result *res);

/** @brief Free a result. */
void euler_result_free(struct euler_result *res);

/** @brief Widen records moment records of width fields (MOM_LEN_1_11: checkpoint format
           1.11 or older, stats.nc likewise) in place to MOM_LEN (the buffer holds records x
           MOM_LEN); the co-moments with y they lack become NaN in records with samples. */
void euler_widen_moments(double *mom, size_t records, size_t width);

/** @brief Read the moment records of variable var of group g (a stats.nc's `moments`: records
           of MOM_LEN or MOM_LEN_1_11 fields) into mom (records x MOM_LEN), widened
           (euler_widen_moments); a netCDF status (NC_EINVAL: another shape). */
int euler_nc_read_moments(int g, int var, size_t records, double *mom);

/** @brief Effective number of independent windows of n batch means of windows of length
           window, for an exponential correlation of integral time tau: n times the ratio of
           the variance of one window mean to n times that of the n windows' mean (n when
           window >> tau, 1 when n window << tau; NaN if tau is not known). */
double euler_n_eff(double n, double window, double tau);

/** @brief Rows holding data (closed windows plus the open one if it has samples). */
size_t euler_rows(const struct euler *e);

/** @brief The running result of the accumulators: every row with data, the closed windows as
    the batches (free with euler_result_free). */
void euler_running_result(const struct euler *e, struct euler_result *res);

/** @brief Expose the complete state (rows 0..nwin, open window included) to a state list. */
void euler_state(struct euler *e, struct state_list *L);

/** @brief Bin centre i of a configuration [m]. */
double euler_centre(const struct euler_config *cfg, int i);

/** Is it turbulent? Indicators of a finished Eulerian result (wall units of its u_tau). */
struct euler_turb {
  double uv_peak;        /*!< peak of -u'v'+ (upper half mirrored) */
  double y_peak;         /*!< its y+ */
  double r_uv;           /*!< -u'v' / (u_rms v_rms) averaged over 30 <= y+ <= 100 (about 0.4-0.5
                              in wall turbulence, near 0 for particle noise) */
  double resolved_share; /*!< reynolds_stress / total_stress in the bin nearest y+ = 30 */
  double pair_share;     /*!< pair_stress / total_stress there (the scheme's numerical stress) */
};

/** @brief The indicators of a result (NaN where not available: no budget, no samples). */
void euler_turbulence(const struct euler_config *c, const struct euler_result *r,
                      struct euler_turb *t);

/** A convergence target (scene keys stats.target_*). */
struct euler_target {
  double rel_stderr; /*!< target relative standard error (> 0) */
  int profiles;      /*!< 0: u_mean and the -u'v' peak, 1: u_mean, 2: the -u'v' peak */
  double corr_ratio; /*!< smallest window length / correlation time (0: none) */
  int windows;       /*!< fewest complete windows */
};

/** Where the statistics stand against a target. */
struct euler_progress {
  double rel_u;          /*!< max stderr(u_mean) / max |u_mean| (NaN: not yet) */
  double rel_uv;         /*!< stderr / value of -u'v' at its peak (NaN: not yet) */
  double worst;          /*!< the largest of the chosen ones (NaN: not yet) */
  int windows;           /*!< complete windows */
  double ratio;          /*!< window length / correlation time (NaN: not measured) */
  double windows_needed; /*!< projected complete windows at the target (stderr ~ n^-1/2) */
  double t_reach;        /*!< projected simulated time at which they are complete [s] */
  int met;               /*!< the target is met */
};

/**
 * @brief The standard errors against a target, and the projection to reach it (the batch-means
 *        standard error falls as one over the square root of the number of windows).
 * @param[in] e the engine, or NULL (not running: everything NaN, not met)
 */
void euler_target_progress(const struct euler *e, const struct euler_target *tg,
                           struct euler_progress *p);

/**
 * @brief The engine's lines for the log: windows, correlation time, largest standard error of
 *        u_mean, friction velocities, the shear-stress balance and whether it is turbulent.
 * @param[out] buf,len the text (ends with a newline; empty if nothing is gathered yet)
 */
void euler_log(const struct euler *e, char *buf, size_t len);

/** The engine's table of operations (engine.h; euler_nc.c). */
extern const struct stats_engine euler_engine;

/** @brief The averaging window length [s] the engine takes from a scene (stats.window, or a
           tenth of the averaging span). */
double euler_scene_window(const struct stats_scene *sc);

#endif
