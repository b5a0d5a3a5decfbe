/**
 * @file test_pdf.c
 * @brief Unit tests of the one-point PDF engine (stats/pdf.c, issue 25): synthetic slabs with
 *        known distributions (Gaussian u', v', w' from a counter-based generator; an exponential
 *        w') whose mean, rms, skewness, flatness and PDF the engine must reproduce within the
 *        stated tolerances; the moments against a direct two-pass computation; the standard
 *        errors against the scatter they predict; the stats.nc group read back (the path of
 *        chansph extract --pdfs) giving the same numbers.
 */
#include <math.h>
#include <netcdf.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contract.h"
#include "expect.h"
#include "pdf.h"
#include "synthetic.h"

/* The synthetic slab: NP particles per snapshot, half at the level y = 0.3 (inside the slab),
   a quarter at the mirror 1.7 (v reversed), a quarter outside; u = U + SU g1, v = SV g2 (the
   mirror's sign flipped in the data, so the engine must flip it back), w = SW (E - 1) with E
   exponential (skewness 2, flatness 9). Velocities in units of u_tau = 0.5. */
enum { NP = 4000, NSNAP = 400, NWIN = 10 };
static const double UT = 0.5, U = 6.0, SU = 2.0, SV = 0.4, SW = 1.0;

static void make_snapshot(long s, double *x, double *y, double *u, double *v, double *w) {
  for (size_t a = 0; a < NP; a++) {
    const uint64_t k = ((uint64_t)s * NP + a) * 8;
    const int where = (int)(a % 4); /* 0, 1: level; 2: mirror; 3: outside */
    y[a] = where == 3 ? 1.0 : (where == 2 ? 1.7 : 0.3) + 0.04 * (uniform(k) - 0.5);
    x[a] = uniform(k + 1);
    u[a] = UT * (U + SU * gauss(k + 2));
    v[a] = UT * SV * gauss(k + 3) * (where == 2 ? -1.0 : 1.0);
    w[a] = UT * SW * (-log(uniform(k + 4)) - 1.0);
  }
}

static struct pdf_config config(void) {
  struct pdf_config c = {.n_levels = 1,
                         .y = {0.3},
                         .y_plus = {30},
                         .half = 0.05,
                         .delta = 1.0,
                         .t_start = 0.0,
                         .window = (double)NSNAP / NWIN,
                         .u_tau = UT,
                         .fine = 0.01,
                         .bins = 40,
                         .range = 5.0};
  return c;
}

static void feed(struct pdf *p, double *buf) {
  double *x = buf, *y = x + NP, *u = y + NP, *v = u + NP, *w = v + NP, *z = w + NP;
  memset(z, 0, NP * sizeof(double));
  for (long s = 0; s < NSNAP; s++) {
    make_snapshot(s, x, y, u, v, w);
    const struct stats_snapshot snap = {
        .n = NP, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .t = s + 0.5, .step = s};
    pdf_sample(p, &snap);
  }
}

/* Mean, rms, skewness and flatness of every sample the engine saw, computed directly in two
   passes (the reference for the engine's power sums). */
static void direct_moments(int comp, double *buf, double m[4]) {
  double *x = buf, *y = x + NP, *u = y + NP, *v = u + NP, *w = v + NP;
  const double *q = comp == 0 ? u : comp == 1 ? v : w;
  double s1 = 0, n = 0, c2 = 0, c3 = 0, c4 = 0;
  for (int pass = 0; pass < 2; pass++)
    for (long s = 0; s < NSNAP; s++) {
      make_snapshot(s, x, y, u, v, w);
      for (size_t a = 0; a < NP; a++) {
        if (a % 4 == 3) continue;
        const double val = comp == 1 && a % 4 == 2 ? -q[a] : q[a];
        if (pass == 0) {
          s1 += val, n += 1;
          continue;
        }
        const double d = val - s1 / n;
        c2 += d * d, c3 += d * d * d, c4 += d * d * d * d;
      }
    }
  c2 /= n, c3 /= n, c4 /= n;
  m[0] = s1 / n, m[1] = sqrt(c2), m[2] = c3 / pow(c2, 1.5), m[3] = c4 / (c2 * c2);
}

/* Exact bin averages of the standard normal density and of the unit exponential shifted to
   mean 0, over [a, b]. */
static double normal_bin(double a, double b) {
  return 0.5 * (erf(b / sqrt(2.0)) - erf(a / sqrt(2.0))) / (b - a);
}
static double expo_bin(double a, double b) {
  const double lo = fmax(a, -1.0), hi = fmax(b, -1.0);
  return (exp(-(lo + 1.0)) - exp(-(hi + 1.0))) / (b - a);
}

/* Largest |pdf - exact| over the bins within +-3 rms (w: from -0.75, clear of the edge of its
   density at -1, which the sample mean shifts) and the largest |pdf - exact| /
   stderr (the standard errors must match the scatter). */
static void pdf_error(const struct pdf_result *r, int comp, int bins, double range, double *abs_err,
                      double *z_max) {
  const double db = 2.0 * range / bins;
  *abs_err = 0.0, *z_max = 0.0;
  for (int j = 0; j < bins; j++) {
    const double a = -range + j * db, b = a + db;
    if (a < (comp == 2 ? -0.75 : -3.0) || b > 3.0) continue; /* w: not at its edge -1 */
    const double exact = comp == 2 ? expo_bin(a, b) : normal_bin(a, b);
    const double e = fabs(r->p[(size_t)comp * bins + j] - exact);
    *abs_err = fmax(*abs_err, e);
    *z_max = fmax(*z_max, e / r->p_err[(size_t)comp * bins + j]);
  }
}

/* The known distributions: moments (against the exact values within the tolerances below, and
   against a direct two-pass computation within 1e-9), the PDF within 0.006 of the exact bin
   averages inside +-3 rms, normalisation, and the standard errors. */
static void test_known(double *buf) {
  const struct pdf_config cfg = config();
  struct pdf p;
  pdf_init(&p, &cfg);
  feed(&p, buf);
  EXPECT(p.nwin == NWIN - 1 && pdf_rows(&p) == NWIN, "windows: %zu closed, %zu rows", p.nwin,
         pdf_rows(&p));
  struct pdf_result r;
  pdf_finalise(&p, 0, pdf_rows(&p), &r);
  const double n = NSNAP * 0.75 * NP;
  EXPECT(r.n[0] == n, "samples %g, expected %g", r.n[0], n);
  static const char *const name[3] = {"u (Gaussian)", "v (Gaussian, mirrored)", "w (exponential)"};
  const double exact[3][4] = {{U * UT, SU * UT, 0, 3}, {0, SV * UT, 0, 3}, {0, SW * UT, 2, 9}};
  const double tol[3][4] = {
      {0.01, 0.005, 0.02, 0.04}, {0.01, 0.005, 0.02, 0.04}, {0.01, 0.01, 0.1, 1.0}};
  for (int c = 0; c < 3; c++) {
    double d[4], sum = 0.0, err, z;
    direct_moments(c, buf, d);
    const double *m = r.mom + 4 * c, *me = r.mom_err + 4 * c;
    for (int k = 0; k < 4; k++) {
      const double scale = k < 2 ? SU * UT : 1.0; /* mean and rms relative to the u rms */
      EXPECT(fabs(m[k] - exact[c][k]) <= tol[c][k] * scale, "%s moment %d: %.6g vs exact %.6g",
             name[c], k, m[k], exact[c][k]);
      EXPECT(fabs(m[k] - d[k]) <= 1e-9 * fmax(1.0, fabs(d[k])),
             "%s moment %d: %.15g vs direct %.15g", name[c], k, m[k], d[k]);
      EXPECT(me[k] > 0.0 && fabs(m[k] - exact[c][k]) <= 5.0 * me[k] + 1e-12 * scale,
             "%s moment %d: error %.3g beyond 5 standard errors %.3g", name[c], k,
             fabs(m[k] - exact[c][k]), me[k]);
    }
    for (int j = 0; j < cfg.bins; j++) sum += r.p[c * cfg.bins + j] * 2.0 * cfg.range / cfg.bins;
    pdf_error(&r, c, cfg.bins, cfg.range, &err, &z);
    printf(
        "%s: mean %.5f rms %.5f skewness %.4f (+- %.4f) flatness %.4f (+- %.4f); pdf max error "
        "%.2e within 3 rms, at most %.2f standard errors; integral %.12f + outside %.2e\n",
        name[c], m[0], m[1], m[2], me[2], m[3], me[3], err, z, sum, r.outside[c]);
    EXPECT(fabs(sum + r.outside[c] - 1.0) < 1e-12, "%s: pdf integral %.15g + outside %.3g", name[c],
           sum, r.outside[c]);
    EXPECT(err < 0.006, "%s: pdf error %.3g", name[c], err); /* 4-5 binomial sd */
    EXPECT(z < 5.0, "%s: pdf error %.2f standard errors", name[c], z);
    /* the fine grid of w ends at 10 u_tau: P(E - 1 >= 9.99) = 1.7e-5 of w lands in its end bin */
    EXPECT(c == 2 ? r.clipped[c] > 0.0 && r.clipped[c] < 5e-5 : r.clipped[c] == 0.0,
           "%s: %.3g clipped", name[c], r.clipped[c]);
  }
  pdf_result_free(&r);
  pdf_free(&p);
}

/* stats.nc round trip: the group pdfs written, read back (as chansph extract --pdfs does) and
   finalised over a range of windows gives bitwise the results of the engine itself. */
static void test_nc(double *buf) {
  const struct pdf_config cfg = config();
  struct pdf p, q;
  pdf_init(&p, &cfg);
  feed(&p, buf);
  char err[256] = "";
  int ncid, rc = nc_create("test_pdf.nc", NC_NETCDF4 | NC_CLOBBER, &ncid);
  if (rc == NC_NOERR) rc = pdf_nc_write(&p, ncid, err, sizeof err);
  if (rc == NC_NOERR) rc = nc_close(ncid);
  EXPECT(rc == NC_NOERR, "writing the group pdfs: %s", err);
  rc = nc_open("test_pdf.nc", NC_NOWRITE, &ncid);
  const int rd = rc == NC_NOERR ? pdf_nc_read(&q, ncid, err, sizeof err) : -1;
  EXPECT(rd == 0, "reading the group pdfs: %s", err);
  if (rc == NC_NOERR) nc_close(ncid);
  remove("test_pdf.nc");
  if (rd != 0) {
    pdf_free(&p);
    return;
  }
  struct pdf_result a, b;
  pdf_finalise(&p, 2, 7, &a);
  pdf_finalise(&q, 2, 7, &b);
  const size_t nc = 3 * (size_t)cfg.bins;
  const int same = q.nwin == p.nwin && a.n_batches == 5 && b.n_batches == 5 &&
                   !memcmp(a.mom, b.mom, 12 * sizeof(double)) &&
                   !memcmp(a.mom_err, b.mom_err, 12 * sizeof(double)) &&
                   !memcmp(a.p, b.p, nc * sizeof(double)) &&
                   !memcmp(a.p_err, b.p_err, nc * sizeof(double));
  EXPECT(same, "windows 2..6 from the file differ from the engine's");
  printf("stats.nc group pdfs read back, windows 2..6 (t = %g .. %g s): %s\n", b.t0, b.t1,
         same ? "bitwise identical" : "DIFFERENT");
  pdf_result_free(&a), pdf_result_free(&b);
  pdf_free(&p), pdf_free(&q);
}

int main(void) {
  double *buf = malloc(6 * NP * sizeof(double));
  test_known(buf);
  test_nc(buf);
  free(buf);
  printf(failures ? "FAILED (%d)\n" : "all passed\n", failures);
  return failures ? 1 : 0;
}
