/** @file pdf_nc.c @brief The group `pdfs` of stats.nc (pdf.h): its writer, its reader for
 *         `chansph extract --pdfs`, and the engine's table of operations. */
#include "contract.h"
#include "engine.h"
#include "ncutil.h"
#include "pdf.h"

#include <math.h>
#include <netcdf.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "ncout.h"

#define CK(call) NC_TRY(call, done)

/* Configuration attributes of the group, in this order (read back by pdf_nc_read). */
static const char *const cfg_att[] = {"u_tau_ref",     "fine_width", "range", "bins",
                                      "window_length", "slab_half",  "delta", "average_start"};
enum { N_CFG_ATT = 8 };

static void cfg_values(const struct pdf_config *c, double v[N_CFG_ATT]) {
  v[0] = c->u_tau, v[1] = c->fine, v[2] = c->range, v[3] = c->bins;
  v[4] = c->window, v[5] = c->half, v[6] = c->delta, v[7] = c->t_start;
}

/* The finished results of every row with data: moments, PDFs and their standard errors.
   d: dimension ids {level, component, bin}. */
static int write_results(const struct pdf *p, int g, const int d[3], char *err, size_t errlen) {
  struct pdf_result r;
  pdf_finalise(p, 0, pdf_rows(p), &r);
  const size_t nl = (size_t)p->cfg.n_levels, B = (size_t)p->cfg.bins, nc = nl * PDF_COMP;
  double *t = mem_alloc(nc, sizeof(double), "PDF results");
  int rc = NC_NOERR, v;
  const int d2[2] = {d[0], d[1]}, d3[3] = {d[0], d[1], d[2]};
  static const char *const mname[4] = {"mean", "rms", "skewness", "flatness"};
  static const char *const munits[4] = {"m/s", "m/s", "1", "1"};
  static const char *const mlong[4] = {
      "mean velocity component in the slab, <u_i>", "rms of the fluctuation, <u_i'^2>^(1/2)",
      "skewness <u_i'^3> / <u_i'^2>^(3/2)", "flatness <u_i'^4> / <u_i'^2>^2"};
  for (int k = 0; k < 8; k++) {
    char name[32], ln[160];
    const double *src = k < 4 ? r.mom : r.mom_err;
    snprintf(name, sizeof name, "%s%s", mname[k % 4], k < 4 ? "" : "_stderr");
    snprintf(ln, sizeof ln, "%s%s", k < 4 ? "" : "standard error (batch means) of the ",
             mlong[k % 4]);
    for (size_t i = 0; i < nc; i++) t[i] = src[i * 4 + (size_t)(k % 4)];
    CK(ncout_def(g, name, NC_DOUBLE, 2, d2, munits[k % 4], ln, &v));
    CK(ncout_fill(g, v));
    CK(ncout_put_filled(g, v, NULL, NULL, t, nc));
  }
  CK(ncout_def(g, "pdf", NC_DOUBLE, 3, d3, "1",
               "probability density of (u_i - <u_i>) / u_i,rms (integrates to 1 - outside)", &v));
  CK(ncout_fill(g, v));
  CK(ncout_put_filled(g, v, NULL, NULL, r.p, nc * B));
  CK(ncout_def(g, "pdf_stderr", NC_DOUBLE, 3, d3, "1",
               "standard error (batch means over the complete windows) of pdf", &v));
  CK(ncout_fill(g, v));
  CK(ncout_put_filled(g, v, NULL, NULL, r.p_err, nc * B));
  CK(ncout_def(g, "outside", NC_DOUBLE, 2, d2, "1",
               "fraction of the samples beyond +-range rms (not in pdf)", &v));
  CK(ncout_fill(g, v));
  CK(ncout_put_filled(g, v, NULL, NULL, r.outside, nc));
  CK(ncout_def(g, "clipped", NC_DOUBLE, 2, d2, "1",
               "fraction of the samples in the end bins of the fine grid (beyond its range)", &v));
  CK(ncout_fill(g, v));
  CK(ncout_put_filled(g, v, NULL, NULL, r.clipped, nc));
  CK(ncout_def(g, "samples", NC_DOUBLE, 1, d, "1", "particle samples at the level", &v));
  CK(nc_put_var_double(g, v, r.n));
  const int nb = r.n_batches;
  CK(nc_put_att_int(g, NC_GLOBAL, "n_windows", NC_INT, 1, &nb));
done:
  free(t);
  pdf_result_free(&r);
  return rc;
}

/* The axes: levels, components, PDF bins with their bounds, fine-grid layout. */
static int write_axes(const struct pdf *p, int g, const int d[4], char *err, size_t errlen) {
  const int B = p->cfg.bins;
  double *lo = mem_alloc(3 * (size_t)B, sizeof(double), "PDF results"), *hi = lo + B;
  double *mid = hi + B;
  int rc = NC_NOERR, v;
  static const char *const comp[PDF_COMP] = {"u", "v", "w"};
  CK(ncout_labels(g, "component", d[1], "velocity component (v -> -v on the mirror levels)", comp));
  CK(ncout_def(g, "level", NC_DOUBLE, 1, d, "m", "height of the plane above the lower wall", &v));
  CK(nc_put_var_double(g, v, p->cfg.y));
  CK(ncout_def(g, "y_plus", NC_DOUBLE, 1, d, "1", "level in wall units of stats.u_tau_ref", &v));
  CK(nc_put_var_double(g, v, p->cfg.y_plus));
  const double db = 2.0 * p->cfg.range / B;
  for (int j = 0; j < B; j++)
    lo[j] = -p->cfg.range + j * db, hi[j] = lo[j] + db, mid[j] = lo[j] + 0.5 * db;
  CK(ncout_def(g, "pdf_bin", NC_DOUBLE, 1, d + 2, "1",
               "centre of the PDF bin: fluctuation in units of the local rms", &v));
  CK(nc_put_var_double(g, v, mid));
  CK(ncout_bounds(g, "pdf_bin", v, d[2], "1", "edges of the PDF bin", lo, hi, (size_t)B));
  const double flo[PDF_COMP] = {pdf_lo[0], pdf_lo[1], pdf_lo[2]};
  const int nf[PDF_COMP] = {p->nf[0], p->nf[1], p->nf[2]};
  CK(ncout_def(g, "fine_lower", NC_DOUBLE, 1, d + 1, "1",
               "lower end of the fine grid of u_i / u_tau_ref (in the raw counts)", &v));
  CK(nc_put_var_double(g, v, flo));
  CK(ncout_def(g, "fine_bins", NC_INT, 1, d + 1, "1",
               "fine bins of the component (consecutive in fine_counts, u then v then w)", &v));
  CK(nc_put_var_int(g, v, nf));
done:
  free(lo);
  return rc;
}

/* The coordinates of the raw records: the middle of each window (bounds: its nominal start
   and end) and the lower edge of each fine bin. d as for write_raw. */
static int write_grid_axes(const struct pdf *p, int g, const int d[6], char *err, size_t errlen) {
  const size_t rows = pdf_rows(p);
  double *t = mem_alloc(3 * rows + p->nfine, sizeof(double), "PDF results");
  double *t0 = t + rows, *t1 = t0 + rows, *f = t1 + rows;
  int rc = NC_NOERR, v;
  for (size_t r = 0; r < rows; r++) {
    t0[r] = p->win[r * PW_LEN + PW_T0], t1[r] = p->win[r * PW_LEN + PW_T1];
    t[r] = 0.5 * (t0[r] + t1[r]);
  }
  for (int c = 0, k = 0; c < PDF_COMP; c++)
    for (int i = 0; i < p->nf[c]; i++) f[k++] = pdf_lo[c] + i * p->cfg.fine;
  CK(ncout_def(g, "window", NC_DOUBLE, 1, &d[2], "s", "middle of the averaging window", &v));
  CK(nc_put_var_double(g, v, t));
  CK(ncout_bounds(g, "window", v, d[2], "s", "nominal start and end of the window", t0, t1, rows));
  CK(ncout_def(g, "fine", NC_DOUBLE, 1, &d[5], "1",
               "lower edge of the fine bin in units of u_tau_ref (u, v, w bins in turn)", &v));
  CK(nc_put_var_double(g, v, f));
done:
  free(t);
  return rc;
}

/* The raw windows: the whole state, from which extract re-averages any range. d: {level,
   component, window, window_field, power, fine}. */
static int write_raw(const struct pdf *p, int g, const int d[6], char *err, size_t errlen) {
  const size_t rows = pdf_rows(p);
  int rc = NC_NOERR, v;
  if (rows == 0) return rc;
  static const char *const wf[PW_LEN] = {"t_start", "t_end", "snapshots"};
  static const char *const pw[PDF_POW] = {"n", "x", "x2", "x3", "x4"};
  CK(ncout_labels(g, "window_field", d[3], "field of the window records", wf));
  CK(ncout_labels(g, "power", d[4], "power k of the sums of x^k, x = u_i / u_tau_ref", pw));
  const int dw[2] = {d[2], d[3]}, dp[4] = {d[2], d[0], d[1], d[4]}, dh[3] = {d[2], d[0], d[5]};
  if ((rc = write_grid_axes(p, g, d, err, errlen)) != NC_NOERR) goto done;
  CK(ncout_def(g, "windows", NC_DOUBLE, 2, dw, NULL,
               "per window: nominal start and end [s], snapshots", &v));
  CK(nc_put_var_double(g, v, p->win));
  CK(ncout_def(g, "power_sums", NC_DOUBLE, 4, dp, "1",
               "per window: sums over the samples of x^k, x = u_i / u_tau_ref, k = 0..4", &v));
  CK(nc_put_var_double(g, v, p->pow));
  CK(ncout_def(g, "fine_counts", NC_DOUBLE, 3, dh, "1",
               "per window: samples in each fine bin of u_i / u_tau_ref (u, v, w bins in turn)",
               &v));
  CK(nc_put_var_double(g, v, p->hist));
  const int nwin = (int)p->nwin;
  CK(nc_put_att_int(g, NC_GLOBAL, "closed_windows", NC_INT, 1, &nwin));
done:
  return rc;
}

int pdf_nc_write(const struct pdf *p, int ncid, char *err, size_t errlen) {
  int rc = NC_NOERR, g, d[6];
  double cv[N_CFG_ATT];
  CK(nc_def_grp(ncid, "pdfs", &g));
  static const char desc[] =
      "one-point PDFs of u', v', w' in slabs at each level and its mirror (v -> -v), in bins of "
      "the local rms about the mean of the averaged windows; rebinned at output from fine counts "
      "of u_i / u_tau_ref kept per window (docs/stats-format.md, group pdfs)";
  CK(nc_put_att_text(g, NC_GLOBAL, "description", strlen(desc), desc));
  cfg_values(&p->cfg, cv);
  for (int k = 0; k < N_CFG_ATT; k++)
    CK(nc_put_att_double(g, NC_GLOBAL, cfg_att[k], NC_DOUBLE, 1, cv + k));
  const size_t rows = pdf_rows(p);
  CK(nc_def_dim(g, "level", (size_t)p->cfg.n_levels, &d[0]));
  CK(nc_def_dim(g, "component", PDF_COMP, &d[1]));
  CK(nc_def_dim(g, "pdf_bin", (size_t)p->cfg.bins, &d[2]));
  if ((rc = write_axes(p, g, (const int[4]){d[0], d[1], d[2], 0}, err, errlen)) != NC_NOERR ||
      (rc = write_results(p, g, d, err, errlen)) != NC_NOERR)
    goto done;
  CK(nc_def_dim(g, "window", rows, &d[2]));
  CK(nc_def_dim(g, "window_field", PW_LEN, &d[3]));
  CK(nc_def_dim(g, "power", PDF_POW, &d[4]));
  CK(nc_def_dim(g, "fine", p->nfine, &d[5]));
  rc = write_raw(p, g, d, err, errlen);
done:
  return rc;
}

/* The configuration of a stored group g (attributes and level coordinates). */
static int read_config(int g, struct pdf_config *c) {
  double cv[N_CFG_ATT];
  size_t nl = 0;
  int dl, vl, vy;
  for (int k = 0; k < N_CFG_ATT; k++)
    if (nc_get_att_double(g, NC_GLOBAL, cfg_att[k], cv + k) != NC_NOERR) return -1;
  if (nc_inq_dimid(g, "level", &dl) || nc_inq_dimlen(g, dl, &nl) || nl < 1 || nl > PDF_MAX_LEVELS ||
      nc_inq_varid(g, "level", &vl) || nc_inq_varid(g, "y_plus", &vy) ||
      nc_get_var_double(g, vl, c->y) || nc_get_var_double(g, vy, c->y_plus))
    return -1;
  c->n_levels = (int)nl, c->u_tau = cv[0], c->fine = cv[1], c->range = cv[2];
  c->bins = (int)cv[3], c->window = cv[4], c->half = cv[5], c->delta = cv[6];
  c->t_start = cv[7];
  return 0;
}

int pdf_nc_read(struct pdf *p, int ncid, char *err, size_t errlen) {
  struct pdf_config c;
  memset(&c, 0, sizeof c);
  int g, dw, vw, vp, vh, dfi, nwin = 0;
  size_t rows = 0, nfine = 0;
  memset(p, 0, sizeof *p);
  if (nc_inq_ncid(ncid, "pdfs", &g) != NC_NOERR || read_config(g, &c)) {
    snprintf(err, errlen, "no group 'pdfs' with its configuration (pdfs.y_plus was off?)");
    return -1;
  }
  pdf_init(p, &c);
  if (nc_inq_dimid(g, "window", &dw) || nc_inq_dimlen(g, dw, &rows) ||
      nc_inq_dimid(g, "fine", &dfi) || nc_inq_dimlen(g, dfi, &nfine) || nfine != p->nfine ||
      nc_get_att_int(g, NC_GLOBAL, "closed_windows", &nwin) || rows < 1 || (size_t)nwin > rows ||
      nc_inq_varid(g, "windows", &vw) || nc_inq_varid(g, "power_sums", &vp) ||
      nc_inq_varid(g, "fine_counts", &vh)) {
    snprintf(err, errlen, "the group 'pdfs' holds no raw windows of this layout");
    pdf_free(p);
    return -1;
  }
  pdf_reserve(p, rows + 1);
  p->nwin = (size_t)nwin;
  if (nc_get_var_double(g, vw, p->win) || nc_get_var_double(g, vp, p->pow) ||
      nc_get_var_double(g, vh, p->hist)) {
    snprintf(err, errlen, "cannot read the raw windows of group 'pdfs'");
    pdf_free(p);
    return -1;
  }
  return 0;
}

/* The engine's scene keys, section [pdfs] (docs/scenes.md is generated from them). */
static const struct scene_key_def key_y_plus = {
    .section = "pdfs",
    .name = "y_plus",
    .type = SCENE_LIST,
    .def = "",
    .lo = 0,
    .hi = SCENE_NO_BOUND,
    .flags = SCENE_Y_PLUS,
    .unit = "-",
    .help =
        "Comma-separated y+ levels (up to 8) of the one-point PDFs of u', v', w' (MKM "
        "1999 give them at y+ = 5, 10, 19, 30, 40, 59, 79, 98, 178): fluid particles in a slab at "
        "each level and its mirror (v -> -v), binned in units of the local rms about the mean of "
        "the averaged windows; stats.nc group pdfs (docs/stats-format.md). Empty = off."};
static const struct scene_key_def key_bins = {
    .section = "pdfs",
    .name = "bins",
    .type = SCENE_INT,
    .def = "40",
    .lo = 1,
    .hi = 1000,
    .unit = "-",
    .help = "Bins of each PDF over -range .. range local rms."};
static const struct scene_key_def key_range = {
    .section = "pdfs",
    .name = "range",
    .type = SCENE_DOUBLE,
    .def = "5",
    .lo = 0,
    .hi = 100,
    .flags = SCENE_LO_OPEN,
    .unit = "rms",
    .help =
        "Half-width of the PDFs in units of the local rms (samples beyond it are counted in "
        "outside)."};
static const struct scene_key_def key_fine = {
    .section = "pdfs",
    .name = "fine",
    .type = SCENE_DOUBLE,
    .def = "0.02",
    .lo = 0.001,
    .hi = 1,
    .unit = "u_tau",
    .help =
        "Width of the fine bins of the raw per-window counts of u_i / stats.u_tau_ref (over -10 .. "
        "35 for u, -10 .. 10 for v and w), rebinned in units of the rms at output: keep it well "
        "below a PDF bin, 2 range / bins times the smallest rms (v near the wall: 0.01); the log "
        "warns where it is above half of one."};
static const struct scene_key_def key_thickness = {
    .section = "pdfs",
    .name = "thickness",
    .type = SCENE_DOUBLE,
    .def = "1",
    .lo = 0,
    .hi = 100,
    .flags = SCENE_LO_OPEN,
    .unit = "dr",
    .help = "Thickness of the slab of particles sampled at each level, in units of dr."};
static const struct scene_key_def *const keys[] = {&key_y_plus, &key_bins, &key_range, &key_fine,
                                                   &key_thickness};

/* The engine's table of operations (engine.h). */
static int engine_init_scene(void *self, const struct stats_scene *sc) {
  struct pdf_config c;
  memset(&c, 0, sizeof c);
  c.n_levels = stats_scene_levels(sc, &key_y_plus, c.y_plus, c.y, PDF_MAX_LEVELS);
  c.half = 0.5 * stats_scene_double(sc, &key_thickness) * sc->dr;
  c.delta = sc->delta, c.t_start = sc->t_average_start, c.u_tau = sc->u_tau;
  c.window = sc->window;
  c.fine = stats_scene_double(sc, &key_fine);
  c.bins = stats_scene_int(sc, &key_bins);
  c.range = stats_scene_double(sc, &key_range);
  if (!(c.n_levels > 0)) return 0;
  pdf_init(self, &c);
  return 1;
}

STATS_ENGINE_ADAPTERS(pdf)

static void engine_close(void *self, double t) {
  pdf_close(self, t);
}

static size_t engine_bytes(const void *self) {
  const struct pdf *p = self;
  const size_t nl = (size_t)p->cfg.n_levels;
  return (p->cap * (PW_LEN + nl * (PDF_COMP * PDF_POW + p->nfine)) + p->ent_cap +
          p->all_cap * p->rec + p->cnt_cap) *
         sizeof(double);
}

static int engine_warnings(const void *self, char *buf, size_t len) {
  return pdf_warnings(self, buf, len);
}

static int engine_write(const void *self, double t_reached, int ncid, char *err, size_t errlen) {
  (void)t_reached;
  return pdf_nc_write(self, ncid, err, errlen);
}

const struct stats_engine pdf_engine = {.name = "one-point PDFs",
                                        .keys = keys,
                                        .n_keys = sizeof keys / sizeof keys[0],
                                        .size = sizeof(struct pdf),
                                        .init_scene = engine_init_scene,
                                        .init = engine_init,
                                        .free = engine_free,
                                        .sample = engine_sample,
                                        .close = engine_close,
                                        .state = engine_state,
                                        .bytes = engine_bytes,
                                        .write = engine_write,
                                        .warnings = engine_warnings,
                                        .log = NULL};
