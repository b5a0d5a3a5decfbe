/**
 * @file pdf.h
 * @brief One-point probability density functions of the velocity fluctuations u', v', w' at
 *        wall-normal levels, in bins of the local rms, with batch-means standard errors
 *        (issue 25; compare Moser, Kim & Mansour 1999, chan180/pdfs).
 *
 * At each level (and its mirror 2 delta - y, with v -> -v) the fluid particles within a slab
 * of pdfs.thickness dr are sampled. The rms that sets the bins is only known at the end, so
 * the engine keeps, per averaging window, level and component, two things that do not need
 * it (docs/stats-format.md, group pdfs):
 *   - the power sums of x = u_i / u_tau (u_tau of the scene): n, sum x, x^2, x^3, x^4, from
 *     which the mean, rms, skewness and flatness of any range of windows follow exactly;
 *   - the counts of x on a fixed fine grid of width pdfs.fine (in u_tau) over a range wide
 *     enough for channel flow (PDF_LO, PDF_HI; values beyond go to the end bins and are
 *     reported as clipped).
 * The result for a range of windows (the running file, or `chansph extract --pdfs --window`)
 * takes the mean and rms of the whole range, then rebins the fine counts onto pdfs.bins bins
 * of (u_i - <u_i>) / u_i,rms over +-pdfs.range, each fine bin shared among the bins it
 * overlaps in proportion to the overlap; the fluctuation is about the mean of the range (the
 * same <u_i> as the Eulerian profiles), not about an instantaneous plane mean. Each complete
 * window's PDF and moments, with the mean and rms of the range, are the batch means of the
 * standard errors.
 *
 * Determinism: the power sums are per (plane, cell column) partial sums in memory order,
 * gathered in column order (spar.h); the fine counts are integers held in doubles, whose sums
 * are exact in any order (below 2^53), so they are reduced with one MPI_Allreduce. The state
 * is bitwise independent of the number of ranks and threads.
 */
#ifndef CHANSPH_PDF_H
#define CHANSPH_PDF_H

#include <stddef.h>

struct stats_snapshot;
struct state_list;
struct stats_engine;

enum { PDF_MAX_LEVELS = 8, PDF_COMP = 3, PDF_MAX_BINS = 1000 };
/** Power sums per window, level and component: n, sum x, x^2, x^3, x^4 (x = u_i / u_tau). */
enum { PDF_POW = 5 };
/** Per-window scalars: nominal interval and snapshots. */
enum { PW_T0, PW_T1, PW_NSNAP, PW_LEN };

/** Range of the fine grid of x = u_i / u_tau per component (u, v, w). */
extern const double pdf_lo[PDF_COMP], pdf_hi[PDF_COMP];

/** Configuration of the PDF engine. */
struct pdf_config {
  int n_levels;                  /*!< levels (0: engine off) */
  double y[PDF_MAX_LEVELS];      /*!< level heights from the lower wall [m] */
  double y_plus[PDF_MAX_LEVELS]; /*!< the y+ they were given as */
  double half;                   /*!< half thickness of the slabs [m] */
  double delta;                  /*!< channel half-width [m] (mirror levels) */
  double t_start;                /*!< start of the averaging [s] */
  double window;                 /*!< length of an averaging window [s] */
  double u_tau;                  /*!< velocity unit of the fine grid [m/s] */
  double fine;                   /*!< fine bin width [u_tau] */
  int bins;                      /*!< bins of the PDF over [-range, range] */
  double range;                  /*!< half-width of the PDF [local rms] */
};

/** The engine: rows 0 .. nwin-1 are the closed windows, row nwin the open one. */
struct pdf {
  struct pdf_config cfg;
  int nf[PDF_COMP];                 /*!< fine bins per component */
  size_t nfine;                     /*!< fine bins of a level (all components) */
  size_t nwin;                      /*!< closed windows */
  size_t cap;                       /*!< rows allocated (>= nwin + 1) */
  double *win;                      /*!< [row][PW_LEN] */
  double *pow;                      /*!< [row][level][PDF_COMP][PDF_POW] power sums */
  double *hist;                     /*!< [row][level][nfine] fine counts */
  double *ent;                      /*!< scratch: this rank's per-(column, plane) power sums */
  double *all;                      /*!< scratch: the same gathered from all ranks */
  double *cnt;                      /*!< scratch: [plane][nfine] counts of a snapshot */
  size_t ent_cap, all_cap, cnt_cap; /*!< capacities (doubles, records, doubles) */
  size_t rec;                       /*!< doubles per column record */
};

/** Finished PDFs and moments of a range of windows; arrays [level][PDF_COMP](...). */
struct pdf_result {
  int n_batches;       /*!< complete windows used as batches (< 2: no standard errors) */
  double t0, t1;       /*!< averaged interval [s] */
  double snapshots;    /*!< snapshots in the range */
  double *n;           /*!< [level] samples (particles x planes) */
  double *mom;         /*!< [level][comp][4] mean [m/s], rms [m/s], skewness, flatness */
  double *mom_err;     /*!< the same: standard errors (NaN with fewer than 2 batches) */
  double *p, *p_err;   /*!< [level][comp][bins] PDF of (u_i - <u_i>) / rms and its stderr */
  double *outside;     /*!< [level][comp] fraction of the samples beyond +-range */
  double *clipped;     /*!< [level][comp] fraction in the end bins of the fine grid */
  double *bin_centres; /*!< [bins] in units of the rms */
};

/** @brief Set up (allocates only if n_levels > 0). */
void pdf_init(struct pdf *p, const struct pdf_config *cfg);

/** @brief Free. */
void pdf_free(struct pdf *p);

/** @brief Make room for rows windows (zeroed), for sampling and reading. */
void pdf_reserve(struct pdf *p, size_t rows);

/** @brief Add one snapshot (deterministic; a collective call on s->comm). */
void pdf_sample(struct pdf *p, const struct stats_snapshot *s);

/** @brief Close the open window if t lies at or past its end (engine.h, close). */
void pdf_close(struct pdf *p, double t);

/** @brief Expose the windows to a state list (checkpoints; optional fields). */
void pdf_state(struct pdf *p, struct state_list *L);

/** @brief Rows holding data (closed windows plus the open one if it has samples). */
size_t pdf_rows(const struct pdf *p);

/**
 * @brief The PDFs and moments of rows r0 .. r1-1 (rows below p->nwin are complete windows,
 *        the batches of the standard errors).
 * @param[out] r allocated here; free with pdf_result_free()
 */
void pdf_finalise(const struct pdf *p, size_t r0, size_t r1, struct pdf_result *r);

/** @brief Free a result. */
void pdf_result_free(struct pdf_result *r);

/** @brief Warnings ("warning: ..." lines into buf) for PDFs the fine grid cannot resolve (a
 *         fine bin wider than half a PDF bin) or that it clips; returns how many. */
int pdf_warnings(const struct pdf *p, char *buf, size_t len);

/** @brief Define and write the group `pdfs` of stats.nc (netCDF status, message in err). */
int pdf_nc_write(const struct pdf *p, int ncid, char *err, size_t errlen);

/**
 * @brief Read the group `pdfs` of an open stats.nc back into an engine (for extract).
 * @return 0, or -1 with a message in err if the file has no such group or it is malformed
 */
int pdf_nc_read(struct pdf *p, int ncid, char *err, size_t errlen);

/** The PDF engine's table of operations (engine.h; pdf.c). */
extern const struct stats_engine pdf_engine;

#endif
