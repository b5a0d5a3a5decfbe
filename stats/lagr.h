/**
 * @file lagr.h
 * @brief Lagrangian statistics of tracked fluid particles (thesis Sec. 5.2.3.2, Eq.
 *        5.60-5.68; set-up Sec. 6.1.3).
 *
 * A release selects the fluid particles within dr/2 of the plane x = x0 and of a y+ level
 * (or of its mirror 2 delta - y, counted with y -> 2 delta - y, v -> -v). They are followed
 * for a horizon and sampled at lags tau_k = k horizon / n_lags (the first statistics sample
 * in each lag interval). Releases start every release_every; with release_every >= horizon
 * they are independent, and each one is a batch of the standard error of T_L.
 *
 * Per level and lag the engine sums (n, then for u, v, w: sums of v0, vt, v0^2, vt^2, v0 vt;
 * the same for the accelerations; sums of dv^2, dv^3, dv^4 with dv = v(t0 + tau) - v(t0);
 * sums of the squared displacements and of the displacements; the sum of the actual lags
 * t - t0 of the samples, which fall up to one statistics sampling interval after the nominal
 * lag). From the sums:
 *   rho^L_ii(tau) = cov(v_i(t0), v_i(t0 + tau)) / (sd(v_i(t0)) sd(v_i(t0 + tau)))   (Eq. 5.60)
 *   T_L,i = int_0^{4 T_E,i} rho^L_ii dt, rho^L_ii(T_E,i / 2) = e^{-1/2}             (Eq. 5.61)
 *   rho^a_ii (Eq. 5.62), D_ii, S_ii, K_ii (Eq. 5.63-5.65), sigma_i^2 (Eq. 5.66),
 * the Lagrangian mean velocities <v_i(t0)>, <v_i(t0 + tau)>, the mean displacement <dr_i>(tau)
 * and the displacement variance <dr_i^2> - <dr_i>^2 (sigma_i^2 without the mean drift), the
 * mean actual lag <t - t0> of the samples of each lag,
 * and at downstream stations x - x0 = X the histogram of y of the particles crossing it,
 * P(y; X), with mu_y and the variance of Eq. 5.67-5.68.
 * The covariance form of Eq. 5.60 measures fluctuations about the ensemble mean of the
 * release at each lag (the mean velocity of a release level is not known in advance).
 */
#ifndef CHANSPH_LAGR_H
#define CHANSPH_LAGR_H

#include <stddef.h>

#include "contract.h"

struct state_list;
struct stats_engine;

enum { LAGR_MAX_LEVELS = 8, LAGR_MAX_STATIONS = 8 };

/** Sums per level and lag. */
enum {
  LG_N = 0,
  LG_VEL = 1,              /* 3 x [S0, St, S00, Stt, S0t] for u, v, w */
  LG_ACC = LG_VEL + 15,    /* the same for ax, ay, az */
  LG_STRUCT = LG_ACC + 15, /* 3 x [sum dv^2, dv^3, dv^4] */
  LG_DISP = LG_STRUCT + 9, /* 3 x sum dr^2 */
  LG_DR = LG_DISP + 3,     /* 3 x sum dr (checkpoint format 1.7) */
  LG_TAU = LG_DR + 3,      /* sum of the actual lags t - t0 of the samples (format 1.9) */
  LG_RATE = LG_TAU + 1,    /* 3 x [sum dr / tau, sum (dr / tau)^2], each sample over its own
                              actual lag: the interval-mean velocity (format 1.10) */
  LG_LEN = LG_RATE + 6
};

/** Sums per level and lag in checkpoints of format <= 1.6 (without LG_DR, LG_TAU and LG_RATE),
    of format 1.7-1.8 (without LG_TAU and LG_RATE) and 1.9 (without LG_RATE): read into the
    layout above with the missing sums NaN where the record has samples, 0 where not (lagr.c). */
enum { LG_LEN_1_6 = LG_DR, LG_LEN_1_8 = LG_TAU, LG_LEN_1_9 = LG_RATE };

/** Per tracked particle. */
enum {
  TR_SLOT,
  TR_LEVEL,
  TR_MIRROR,
  TR_ID,
  TR_V0,                 /* u, v, w at release (v mirrored) */
  TR_A0 = TR_V0 + 3,     /* ax, ay, az at release */
  TR_LAST = TR_A0 + 3,   /* position at the last sample */
  TR_DISP = TR_LAST + 3, /* displacement since release (unwrapped) */
  TR_DONE = TR_DISP + 3, /* stations passed (bit mask) */
  TR_LEN
};

/** Doubles per particle record gathered from the ranks (lagr.c). */
enum { LAGR_REC = 11 };

/** Per release slot: start time, last lag sampled, tracked particles, active flag. */
enum { SL_T0, SL_LAST_K, SL_N, SL_ACTIVE, SL_LEN };

/** Configuration of the Lagrangian engine. */
struct lagr_config {
  int n_levels;                      /*!< release levels (0: engine off) */
  double y[LAGR_MAX_LEVELS];         /*!< their heights [m] */
  double y_plus[LAGR_MAX_LEVELS];    /*!< the y+ they were given as */
  double x0;                         /*!< release plane [m] */
  double half;                       /*!< half thickness of the release slabs (dr/2) [m] */
  double lx, lz;                     /*!< periodic lengths [m] (lz = 0 in 2-D) */
  double delta;                      /*!< half-width [m] */
  double horizon;                    /*!< lag range [s] */
  double release_every;              /*!< time between releases [s] */
  int n_lags;                        /*!< lag intervals over the horizon */
  int n_stations;                    /*!< PDF stations */
  double station[LAGR_MAX_STATIONS]; /*!< downstream distances x - x0 [m] */
  int pdf_bins;                      /*!< bins over 0 .. 2 delta (or 0 .. delta folded) */
  double t_start;                    /*!< first release not before [s] */
};

/** The engine. */
struct lagr {
  struct lagr_config cfg;
  int n_slots;         /*!< release slots */
  size_t nlag;         /*!< n_lags + 1 */
  double *sums;        /*!< [level][lag][LG_LEN] completed releases */
  double *slot_sums;   /*!< [slot][level][lag][LG_LEN] active releases */
  double *slots;       /*!< [slot][SL_LEN] */
  double *tl;          /*!< [level][3][3] Welford of the per-release T_L over releases */
  double *tl_rel;      /*!< [release][level][3] each completed release's own T_L, in release
                            order (NaN where not finite; checkpoint format 1.13) [s] */
  double *tl_rel_t;    /*!< [release] the simulated time at which it completed [s] */
  size_t n_rel;        /*!< releases in that history: the completed ones (those completed
                            since the resume after a resume from format <= 1.12) */
  size_t rel_cap;      /*!< its capacity (releases) */
  double *rb;          /*!< [level][LF_LEN][lag][3] Welford over the completed releases of each
                            release's own lag functions (checkpoint format 1.12) */
  double *slot_pdf;    /*!< [slot][level][station][pdf_bins + 3] the active releases'
                            crossings, as pdf; [slot][0] of level 0, station 0 ... see lagr.c */
  double *pdf_rb;      /*!< [level][station][pdf_bins + 2][3] Welford over the completed releases
                            of each release's own P(y; x), mu_y and variance */
  double *pdf;         /*!< [level][station][pdf_bins + 3]: counts, then n, sum y, sum y^2 */
  double *tracks;      /*!< [ntracks][TR_LEN] */
  size_t ntracks, cap; /*!< tracked particles, capacity */
  double next_release; /*!< time of the next release [s] */
  double releases;     /*!< completed releases */
  long *index;         /*!< scratch: marks of the tracked ids (-1 between samples) */
  size_t index_len;    /*!< its length */
  double *mine, *all;  /*!< scratch: this rank's / all ranks' particle records (sorted by id) */
  size_t mine_cap, all_cap, nall; /*!< capacities (records), records gathered */
};

/** @brief Set up (allocates only if n_levels > 0). */
void lagr_init(struct lagr *g, const struct lagr_config *cfg);

/** @brief Free. */
void lagr_free(struct lagr *g);

/** @brief Add one snapshot: releases, lag samples, PDF crossings (deterministic, a collective
 *         call on s->comm). Implements: the set-up of thesis Sec. 6.1.3 and the sums of Eq.
 *         5.60-5.68. The tracked particles and the release candidates of all ranks are gathered
 *         to every rank and sorted by id; releases take the candidates in id order, so the
 *         state is bitwise the same on every rank and for any number of ranks. */
void lagr_sample(struct lagr *g, const struct stats_snapshot *s);

/** @brief Expose the complete state to a state list (rebuild before each checkpoint). */
void lagr_state(struct lagr *g, struct state_list *L);

/**
 * @brief The lag functions of one level from the sums (completed releases only).
 *        Implements: thesis Eq. 5.60, 5.62-5.66 (and 5.61 through lagr_tl).
 * @param[in] g engine
 * @param[in] level release level
 * @param[out] out [quantity][nlag], quantities: rho_L u v w, rho_a u v w, D u v w, S u v w,
 *             K u v w, sigma2 x y z, <v_i(t0)> u v w, <v_i(t0 + tau)> u v w, <dr_i> x y z,
 *             <dr_i^2> - <dr_i>^2 x y z, n, mean actual lag <t - t0> (32 rows)
 * @param[out] tl T_L of u, v, w from the merged releases (Eq. 5.61) [s]
 */
void lagr_functions(const struct lagr *g, int level, double *out, double *tl);

/** Rows of lagr_functions. */
enum {
  LF_RHO_L = 0,
  LF_RHO_A = 3,
  LF_D = 6,
  LF_S = 9,
  LF_K = 12,
  LF_SIG2 = 15,
  LF_U0 = 18,   /* Lagrangian mean velocity at release */
  LF_UT = 21,   /* and at the lag */
  LF_DR = 24,   /* mean displacement (NaN after a resume from format <= 1.6) */
  LF_DVAR = 27, /* displacement variance about it (likewise) */
  LF_N = 30,
  LF_TAU = 31,  /* mean actual lag time of the samples (NaN after a resume from format <= 1.8) */
  LF_RVAR = 32, /* variance of the interval-mean velocity dr / tau (NaN: from format <= 1.9) */
  LF_LEN = 35
};

/**
 * @brief Warnings about the Lagrangian statistics (issue 13): lags left without samples (the lag
 *        interval horizon / n_lags is shorter than the statistics sampling interval), T_L that
 *        is NaN (rho_L never falls to e^{-1/2} within the horizon), no completed release.
 *        One line per level, each starting "warning: ".
 * @param[out] buf,len the text ("" if nothing to say)
 * @return the number of warnings
 */
int lagr_warnings(const struct lagr *g, char *buf, size_t len);

/**
 * @brief T_L of Eq. 5.61 from a sampled rho(tau_k), tau_k = k dtau: T_E from the first
 *        crossing of e^{-1/2} (linear interpolation), trapezoidal integral to 4 T_E (or to
 *        the last lag if shorter). NaN if rho never falls to e^{-1/2}.
 */
double lagr_tl(const double *rho, size_t nlag, double dtau);

/** @brief Write group "lagrangian" into an open netCDF-4 file; returns a netCDF status. */
int lagr_nc_write(const struct lagr *g, int ncid, char *err, size_t errlen);

/**
 * @brief Read the raw state of group `lagrangian` of a stats.nc (ncid: the file): the
 *        configuration its writer needs, the completed releases' sums (raw_sums), their
 *        per-release Welford records (release_welford, T_L_welford, pdf_release_welford), the
 *        PDF sums (raw_pdf), the history of T_L and the count of releases. The releases in
 *        flight are not in the file: the engine read has none.
 * @return 0 (g set up; lagr_free it), 1 no group (engine off), 2 no raw records (a file of an
 *         earlier version), -1 not this layout; err says why
 */
int lagr_nc_read(struct lagr *g, int ncid, char *err, size_t errlen);

/**
 * @brief Pool the completed releases of b (a later segment of the run, whose times start at 0)
 *        into g: sums and PDF sums added, the per-release Welford records merged pairwise
 *        (scal_merge), b's history of T_L appended with its completion times shifted by offset,
 *        the release counts added. Nonzero if b was configured otherwise (why says how); g is
 *        then unchanged.
 */
int lagr_join(struct lagr *g, const struct lagr *b, double offset, char *why, size_t len);

/** The Lagrangian engine's table of operations (engine.h; lagr.c). */
extern const struct stats_engine lagr_engine;

#endif
