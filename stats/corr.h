/**
 * @file corr.h
 * @brief Two-point correlations and spectra in wall-parallel planes (thesis Eq. 5.57-5.59),
 *        with FFTW.
 *
 * At each level the particles of a thin slab are bin-averaged onto an nx x nz grid (Eq.
 * 5.54-5.55), the plane mean is removed, and the 2-D FFTs of u', v', w' give the spectra
 * S_ij(k) = conj(u_i(k)) u_j(k), summed over samples (a level and its mirror 2 delta - y,
 * with v -> -v, are two samples of one snapshot). The sums are the whole state: mergeable by
 * addition, serialisable, and every result derives from them:
 *   R_ij(l) = <u_i'(r) u_j'(r + l)> = IFFT(S_ij)(l) / (N^2 samples)            (Eq. 5.57)
 *   rho_ij(l) = R_ij(l) / R_ii(0)                                               (Eq. 5.58)
 *   E_ii(k_x) one-sided, normalised so that sum_k E_ii(k) dk = <u_i'^2>       (Eq. 5.59)
 *
 * Per averaging window (stats.window, the windows of the Eulerian and PDF engines) the engine
 * also keeps the 1-D sums of the same spectra (issue 25): per level, the sum over k_z of
 * S_ij(k_x, k_z) for k_x = 0 .. nx/2 and the sum over k_x for k_z = 0 .. nz/2 (complex: the
 * uv slots keep the phase), from which each window's own E(k_x), E(k_z), R(l_x) and R(l_z)
 * follow exactly; over the complete windows their batch means give the standard errors. The
 * whole-run sums are untouched (the 1-D sums are added beside them from the same transform).
 *
 * Gaps. A grid cell that holds no particle of the slab has no value: it is set to zero
 * fluctuation, so the sums above hold the product of the field with the mask m (1 where a cell
 * is filled). Their correlation is P(l) R(l), P(l) the fraction of cell pairs at separation l
 * that are both filled (P(0) = p, about p^2 elsewhere): with a fifth of the cells empty it
 * lowers R(l) by a third at every l != 0 and moves the lost part into a white floor of the
 * spectra. The engine therefore also sums the mask's own spectrum |F m|^2 (2-D and per
 * window, with the planes and empty cells it counted) and divides: R(l) = (sum over the planes
 * of f'm f'm at l) / (sum of m m at l), the mean over the filled pairs only (the estimator of
 * gappy records, e.g. laser-Doppler and PIV data), and the spectra are the cosine transforms
 * of that R. Where no cell was empty, or the mask sums do not cover every plane (a resume
 * from a checkpoint written before them), the results are the uncorrected ones.
 */
#ifndef CHANSPH_CORR_H
#define CHANSPH_CORR_H

#include <stddef.h>

#include "contract.h"

struct state_list;
struct stats_engine;

enum { CORR_MAX_LEVELS = 8 };
/** Spectrum slots per wavenumber: S_uu, S_vv, S_ww, Re S_uv, Im S_uv. */
enum { CS_UU, CS_VV, CS_WW, CS_UV_RE, CS_UV_IM, CS_LEN };
/** After the mask's spectrum sums (2-D: nk entries; per window: n1d), per level: the planes
    whose mask was summed and the empty cells among them. */
enum { CM_PLANES, CM_EMPTY, CM_LEN };
/** Per-window scalars: nominal interval, snapshots, and 1 if the window is partial (it holds
    the resume of a checkpoint written without window records: not a batch). */
enum { CW_T0, CW_T1, CW_NSNAP, CW_PARTIAL, CW_LEN };

/** Configuration of the correlation engine. */
struct corr_config {
  int n_levels;                   /*!< levels (0: engine off) */
  double y[CORR_MAX_LEVELS];      /*!< level heights from the lower wall [m] */
  double y_plus[CORR_MAX_LEVELS]; /*!< the y+ they were given as */
  int nx, nz;                     /*!< grid (nz = 1 in 2-D) */
  double lx, lz;                  /*!< periodic lengths [m] (lz unused in 2-D) */
  double half;                    /*!< half thickness of the slabs [m] */
  double delta;                   /*!< channel half-width [m] (mirror levels) */
  double t_start;                 /*!< start of the averaging [s] */
  double window;                  /*!< length of an averaging window [s] (<= 0: one window) */
};

/** The engine. */
struct corr {
  struct corr_config cfg;
  int nzh;         /*!< nz / 2 + 1 (r2c output along z) */
  double *spec;    /*!< [level][nx][nzh][CS_LEN] summed spectra */
  double *samples; /*!< [level] planes accumulated */
  double *empty;   /*!< [level] empty grid cells met (diagnostic) */
  double *mspec;   /*!< [level][nk + CM_LEN] summed |F m|^2 of the mask, then CM_PLANES, CM_EMPTY
                        (format 1.15; zero when resumed from an older checkpoint) */
  double *grid;    /*!< fftw_malloc'd work: 3 planes nx*nz (+ counts) */
  void *out;       /*!< fftw_malloc'd complex output, 3 x nx*nzh */
  void *plan;      /*!< r2c plan (FFTW_ESTIMATE, fixed: deterministic) */
  double *mgrid;   /*!< fftw_malloc'd mask plane nx*nz (1 filled, 0 empty) */
  void *mout;      /*!< fftw_malloc'd complex output of the mask, nx*nzh */
  void *mplan;     /*!< its r2c plan */
  void *hits;      /*!< scratch: this rank's slab particles of a snapshot */
  double *ent;     /*!< scratch: [entry][CORR_ENT] this rank's per-column partial sums */
  double *all;     /*!< scratch: the same gathered from all ranks */
  size_t hits_cap, ent_cap, all_cap; /*!< capacities (particles, entries, entries) */
  size_t nall;                       /*!< entries gathered at the last snapshot */
  /* per window: rows 0 .. nwin-1 closed, row nwin open */
  size_t nwin, cap; /*!< closed windows, rows allocated (>= nwin + 1) */
  size_t n1d;       /*!< 1-D entries of a level: nx/2 + 1 (k_x) then nz/2 + 1 (k_z) */
  double *win;      /*!< [row][CW_LEN] */
  double *wsamp;    /*!< [row][level] planes accumulated */
  double *wspec;    /*!< [row][level][n1d][CS_LEN] 1-D sums of the spectra */
  double *wmask;    /*!< [row][level][n1d + CM_LEN] 1-D sums of |F m|^2, CM_PLANES, CM_EMPTY */
  size_t rows;      /*!< rows of an engine read back or cut to a range (corr_nc.c; the last
                         closed too if rows == nwin); 0 in a running engine: nwin + 1 */
};

/** The window rows an engine holds. */
static inline size_t corr_rows(const struct corr *c) {
  return c->rows ? c->rows : c->nwin + 1;
}

/** A per-(plane, column, grid point) partial sum: plane np + grid point, sums of u v w, count. */
enum { CORR_ENT = 6 };

/** @brief Set up (allocates only if n_levels > 0). */
void corr_init(struct corr *c, const struct corr_config *cfg);

/** @brief Free. */
void corr_free(struct corr *c);

/** @brief Add one snapshot (deterministic, a collective call on s->comm). Implements: Eq.
 *         5.54-5.55 on the plane grid and the spectra behind Eq. 5.57-5.59.
 *         Each grid point's sums are the per-column partials (particles in memory order)
 *         added in column order, gathered to every rank: the spectra are bitwise the same on
 *         every rank and for any number of ranks. */
void corr_sample(struct corr *c, const struct stats_snapshot *s);

/* The per-window records (corr_win.c), used by corr.c. */
/** @brief Allocate the window records (row 0 open at t_start). */
void corr_win_init(struct corr *c);
/** @brief Move the open window to the one holding time t (marks a partial window after a
 *         resume from a checkpoint without window records); counts the snapshot. */
void corr_win_advance(struct corr *c, double t);

/** @brief Close the open window if t lies at or past its end (engine.h, close). */
void corr_win_close(struct corr *c, double t);

/** @brief Add one plane's transforms U, V, W and its mask's M (fftw_complex, nx x (nz/2+1))
 *         of level l, with its empty cells, to the open window's 1-D sums. */
void corr_win_add(struct corr *c, int l, const double (*U)[2], const double (*V)[2],
                  const double (*W)[2], const double (*M)[2], double empty);

/**
 * @brief The gap correction of one level's results: R(l) over the fraction P(l) of filled
 *        cell pairs, the spectra recomputed as the cosine transforms of the corrected R.
 * @param[in,out] rx [4][nx] R along x, rz [4][nz] along z (R_uu, R_vv, R_ww, R_uv)
 * @param[out] ex [3][nx/2+1], ez [3][nz/2+1] the one-sided spectra of the corrected R
 * @param[in] px [nx], pz [nz] P(l) along x and z (> 0; NaN R where it is not)
 */
void corr_gap_correct(const struct corr *c, double *rx, double *rz, double *ex, double *ez,
                      const double *px, const double *pz);
/** @brief Expose the window records to a state list (optional fields, format 1.8). */
void corr_win_state(struct corr *c, struct state_list *L);
/** @brief Make room for rows window records (new rows zeroed; corr_nc.c reads them back). */
void corr_win_reserve(struct corr *c, size_t rows);

/** @brief Expose the sums to a state list. */
void corr_state(struct corr *c, struct state_list *L);

/**
 * @brief Implements: thesis Eq. 5.57-5.59.
 *        Results of the sums: correlations along x and z, their normalised forms and the
 *        one-sided 1-D spectra of each level.
 * @param[in] c engine
 * @param[out] rx [level][4][nx] R_uu, R_vv, R_ww, R_uv along x (l = i lx/nx)
 * @param[out] rz [level][4][nz] the same along z
 * @param[out] ex [level][3][nx/2+1] E_uu, E_vv, E_ww over k_x = 2 pi m / lx
 * @param[out] ez [level][3][nz/2+1] the same over k_z
 */
void corr_results(const struct corr *c, double *rx, double *rz, double *ex, double *ez);

/**
 * @brief The fraction P(l) of filled cell pairs along x and z behind corr_results, and
 *        whether the results of each level are gap-corrected (corr.h, Gaps).
 * @param[out] px [level][nx], pz [level][nz] (NaN where the mask sums do not cover the level)
 * @param[out] corrected [level] 1 if corrected, 0 if not (no empty cell, or no mask sums)
 */
void corr_pair_fraction(const struct corr *c, double *px, double *pz, int *corrected);

/**
 * @brief Batch-means standard errors of the results of corr_results(), same layouts; each
 *        complete window with planes at a level is one batch (its own normalised R and E).
 *        NaN where fewer than 2 batches.
 * @param[out] nb [level] batches used
 */
void corr_stderr(const struct corr *c, double *rx, double *rz, double *ex, double *ez, int *nb);

/** @brief Values per level of corr_range_values and corr_range_stderr: R along x [4][nx],
 *         along z [4][nz], E over k_x [3][nx/2+1], over k_z [3][nz/2+1], rho along x [4][nx],
 *         along z [4][nz] (rho_ij = R_ij / R_ii(0), rho_uv = R_uv / R_uu(0)). */
size_t corr_nv(const struct corr *c);

/** @brief The results of the window rows r0 .. r1-1 pooled (their 1-D sums added in row
 *         order): v [level][corr_nv]; NaN at a level without planes. The whole run's when the
 *         rows are all of them and none is partial (to round-off: corr_results uses the 2-D
 *         sums). */
void corr_range_values(const struct corr *c, size_t r0, size_t r1, double *v);

/** @brief P(l) along x [level][nx] and z [level][nz] of the window rows r0 .. r1-1 pooled, and
 *         whether each level's results of corr_range_values are gap-corrected (corr.h, Gaps). */
void corr_range_pair_fraction(const struct corr *c, size_t r0, size_t r1, double *px, double *pz,
                              int *corrected);

/** @brief Batch-means standard errors over the batches among rows r0 .. r1-1 (complete
 *         windows with planes at the level; each its own R, E and rho): se [level][corr_nv],
 *         NaN where fewer than 2; nb [level] batches used. */
void corr_range_stderr(const struct corr *c, size_t r0, size_t r1, double *se, int *nb);

/** @brief Write group "correlations" into an open netCDF-4 file; returns a netCDF status.
 *         With c->spec NULL (an engine read back by corr_nc_read, or a range of its windows),
 *         R and E come from the pooled 1-D sums of the window records and the 2-D sums
 *         (`spectra`, `empty_cells`) are left out (corr_nc.c). */
int corr_nc_write(const struct corr *c, int ncid, char *err, size_t errlen);

/** @brief Write the window rows r0 .. r1-1 of c as group "correlations" of an engine that
 *         gathered only them (chansph extract --window --nc); a netCDF status. */
int corr_nc_write_range(const struct corr *c, size_t r0, size_t r1, int ncid, char *err,
                        size_t errlen);

/** @brief Read group "correlations" of stats.nc back: configuration and window records (no
 *         2-D sums: c->spec, samples, empty are NULL). Returns 0, 1 if the file has no such
 *         group, 2 if the group has no window records (written before they were, or a run
 *         without snapshots: err says which), -1 on an error (err says what). */
int corr_nc_read(struct corr *c, int ncid, char *err, size_t errlen);

/** The correlation engine's table of operations (engine.h; corr.c). */
extern const struct stats_engine corr_engine;

#endif
