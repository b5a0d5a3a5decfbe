/**
 * @file test_uncertainty.c
 * @brief Standard errors of the statistics engines against answers known in advance (issue 43,
 *        point 5): synthetic signals whose exact standard errors follow from their construction.
 *
 *  1. Lagrangian: every release tracks NP particles whose w is a stationary AR(1) chain started
 *     afresh at the release (so the releases are independent) and whose z is its integral; the
 *     structure function D_w(tau_k) = 2 s^2 (1 - phi^k), the dispersion sigma_z^2(tau_k) and the
 *     autocorrelation rho_L_w(tau_k) = phi^k have exact standard errors over R releases
 *     (Gaussian: var(dw^2) = 2 D^2, var(dz^2) = 2 sigma^4, var(r) = (1 - rho^2)^2 / N).
 *  2. Quadrants: u, v independent Gaussians at every sample, the fluctuations taken about the
 *     plane mean of the instant (as the engine does): the variance of each quadrant's share of
 *     the samples and of its part of u'v' follow from the bivariate normal orthant integrals
 *     with the correlation -1/(NP - 1) that the plane mean leaves between the particles (the
 *     binomial error, which ignores it, is 24% too large).
 *  3. Eulerian: the bin mean of u follows an AR(1) chain in time (phi = 0.9, correlation time
 *     9.5 samples) plus particle noise; the exact standard error of the mean over the run is
 *     known. Windows of 200 samples give batch means within 20% of it; windows of 5 samples,
 *     shorter than the correlation time, are flagged (short_windows), their batch means are
 *     more than 20% too small and the widened error sqrt(n / n_eff) se is within 20%.
 * Each check must be within 20% of the exact value (the scatter of a standard deviation from
 * 100-200 batches is 5-7%).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contract.h"
#include "euler.h"
#include "expect.h"
#include "lagr.h"
#include "moments.h"
#include "quad.h"
#include "synthetic.h"

static double welford_se(const double *W) {
  return W[SCAL_N] >= 2.0 ? sqrt(W[SCAL_M2] / (W[SCAL_N] - 1.0) / W[SCAL_N]) : NAN;
}

static void check(const char *what, double got, double exact) {
  const double rel = got / exact - 1.0;
  printf("  %-44s engine %.4e exact %.4e (%+.1f%%)\n", what, got, exact, 100.0 * rel);
  EXPECT(fabs(rel) < 0.2, "%s: %.4e against the exact %.4e", what, got, exact);
}

/* 1. Lagrangian: R releases of NP tracks, n_lags = 4 lags one sample apart. */
static void test_lagrangian(void) {
  enum { NP = 64, R = 200, PER = 8, NLAG = 4 };
  const double phi = 0.7, sw = 0.5, ds = 0.01;
  struct lagr_config c = {.n_levels = 1,
                          .y = {0.3},
                          .y_plus = {30},
                          .x0 = 0.5,
                          .half = 0.05,
                          .lx = 1.0,
                          .lz = 1.0,
                          .delta = 1.0,
                          .horizon = NLAG * ds,
                          .release_every = PER * ds,
                          .n_lags = NLAG,
                          .pdf_bins = 10};
  struct lagr g;
  lagr_init(&g, &c);
  double x[NP], y[NP], z[NP], u[NP], v[NP], w[NP], wn[NP];
  int64_t id[NP];
  for (long s = 0; s < (long)R * PER; s++) {
    const long j = s % PER;
    for (int a = 0; a < NP; a++) {
      const uint64_t key = ((uint64_t)s * NP + (uint64_t)a) * 4;
      if (j == 0) { /* a fresh stationary chain, the particle back at its release point */
        wn[a] = sw * gauss(key);
        z[a] = (a + 0.5) / NP;
      } else {
        z[a] += wn[a] * ds; /* the position integrates the previous sample's velocity */
        wn[a] = phi * wn[a] + sqrt(1.0 - phi * phi) * sw * gauss(key);
      }
      x[a] = 0.5, y[a] = 0.3, u[a] = 1.0, v[a] = 0.0, w[a] = wn[a], id[a] = a;
    }
    const struct stats_snapshot snap = {
        .n = NP, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .id = id, .t = s * ds + 1e-9};
    lagr_sample(&g, &snap);
  }
  printf("Lagrangian: %d releases of %d tracks, w an AR(1) chain (phi = %g per lag)\n",
         (int)g.releases, NP, phi);
  const size_t nlag = g.nlag;
  for (size_t k = 1; k <= NLAG; k++) {
    const double rho = pow(phi, (double)k), D = 2.0 * sw * sw * (1.0 - rho);
    double var = 0.0; /* var of z(k) - z(0) = ds sum_{i<k} w_i */
    for (size_t i = 0; i < k; i++)
      for (size_t m = 0; m < k; m++) var += ds * ds * sw * sw * pow(phi, fabs((double)i - m));
    const double *B = g.rb + (size_t)LF_D * nlag * SCAL_LEN; /* level 0 */
    char what[64];
    snprintf(what, sizeof what, "D_w_stderr, lag %zu", k);
    check(what, welford_se(B + (2 * nlag + k) * SCAL_LEN), sqrt(2.0 / (NP * R)) * D);
    B = g.rb + (size_t)LF_SIG2 * nlag * SCAL_LEN;
    snprintf(what, sizeof what, "sigma2_z_stderr, lag %zu", k);
    check(what, welford_se(B + (2 * nlag + k) * SCAL_LEN), sqrt(2.0 / (NP * R)) * var);
    B = g.rb + (size_t)LF_RHO_L * nlag * SCAL_LEN;
    snprintf(what, sizeof what, "rho_L_w_stderr, lag %zu", k);
    check(what, welford_se(B + (2 * nlag + k) * SCAL_LEN), (1.0 - rho * rho) / sqrt(NP * R));
    EXPECT(B[(2 * nlag + k) * SCAL_LEN + SCAL_N] == R, "lag %zu: %g batches, %d releases", k,
           B[(2 * nlag + k) * SCAL_LEN + SCAL_N], R);
  }
  lagr_free(&g);
}

/* 2. Quadrants: NWIN windows of NS samples of NP particles in the slab. */
static void test_quadrants(void) {
  enum { NP = 400, NS = 10, NWIN = 100 };
  const double s = 0.3, ds = 0.01;
  struct quad_config c = {
      .n_levels = 1, .y = {0.3}, .y_plus = {30}, .half = 0.05, .delta = 1.0, .window = NS * ds};
  struct quad q;
  quad_init(&q, &c);
  double y[NP], u[NP], v[NP];
  for (long k = 0; k < (long)NS * NWIN + 1; k++) { /* + 1: the sample that closes the last */
    for (int a = 0; a < NP; a++) {
      const uint64_t key = ((uint64_t)k * NP + (uint64_t)a) * 4 + 7;
      y[a] = 0.3, u[a] = 2.0 + s * gauss(key), v[a] = s * gauss(key + 1);
    }
    const struct stats_snapshot snap = {.n = NP, .y = y, .u = u, .v = v, .t = (k + 0.5) * ds};
    quad_sample(&q, &snap);
  }
  /* the fluctuations are about the plane mean of each instant: e_a = u_a - mean has variance
     s^2 (1 - 1/NP) and correlation r = -1/(NP - 1) between particles, so the quadrant
     indicators and the u'v' of a quadrant are correlated within a plane (bivariate normal:
     P(e_a > 0, e_b > 0) = 1/4 + asin(r) / (2 pi); E[e_a e_b; e_a > 0, e_b > 0] = var g(r),
     g(r) = r / 4 + (r asin(r) + sqrt(1 - r^2)) / (2 pi)); the planes are independent */
  const double pi = acos(-1.0), r = -1.0 / (NP - 1), cr = asin(r) / (2.0 * pi);
  const double ve = s * s * (1.0 - 1.0 / NP),
               g = r / 4 + (r * asin(r) + sqrt(1 - r * r)) / (2 * pi);
  const double m = ve / (2.0 * pi), planes = (double)NS * NWIN;
  const double var_t = (0.25 * 0.75 + (NP - 1) * (0.5 * cr + cr * cr)) / NP;
  const double var_uv = (ve * ve / 4.0 - m * m + (NP - 1) * (ve * ve * g * g - m * m)) / NP;
  printf(
      "quadrants: %g complete windows of %d samples of %d particles, u', v' independent "
      "about the plane mean\n",
      q.batch[SCAL_N], NS, NP);
  EXPECT(q.batch[SCAL_N] == NWIN, "%g windows, %d expected", q.batch[SCAL_N], NWIN);
  for (int k = 0; k < 4; k++) {
    char what[64];
    snprintf(what, sizeof what, "time_fraction_stderr, Q%d", k + 1);
    check(what, welford_se(q.batch + (size_t)(QB_TIME + k) * SCAL_LEN), sqrt(var_t / planes));
    snprintf(what, sizeof what, "uv_stderr, Q%d", k + 1);
    check(what, welford_se(q.batch + (size_t)(QB_UV + k) * SCAL_LEN), sqrt(var_uv / planes));
  }
  quad_free(&q);
}

/* 3. Eulerian: windows of nw samples over ns samples; returns the result (bin 0). */
static void euler_ar1(long ns, long nw, struct euler_result *r, double *exact) {
  enum { NP = 50 };
  const double phi = 0.9, sa = 0.1, sn = 0.2, ds = 0.01;
  struct euler_config c = {.nb = 2,
                           .y0 = 0.0,
                           .y1 = 2.0,
                           .delta = 1.0,
                           .nu = 1e-3,
                           .rho0 = 1000.0,
                           .area = 1.0,
                           .window = nw * ds};
  struct euler e;
  euler_init(&e, &c);
  double y[NP], u[NP], v[NP], w[NP], p[NP], rho[NP], A = sa * gauss(99);
  for (long s = 0; s < ns + 1; s++) { /* + 1: the sample that closes the last window */
    for (int a = 0; a < NP; a++) {
      const uint64_t key = ((uint64_t)s * NP + (uint64_t)a) * 4 + 11;
      y[a] = 0.5 + (a % 2), u[a] = 1.0 + A + sn * gauss(key), v[a] = w[a] = 0.0;
      p[a] = 0.0, rho[a] = 1000.0;
    }
    const struct stats_snapshot snap = {
        .n = NP, .y = y, .u = u, .v = v, .w = w, .p = p, .rho = rho, .t = (s + 0.5) * ds};
    euler_sample(&e, &snap);
    A = phi * A + sqrt(1.0 - phi * phi) * sa * gauss(1000003 + (uint64_t)s);
  }
  euler_running_result(&e, r);
  /* the exact variance of the mean over the complete windows' samples of bin 0 (NP / 2 each) */
  const double n = (double)r->n_batches * nw;
  double sum = n;
  for (long k = 1; k < (long)n; k++) sum += 2.0 * (n - k) * pow(phi, (double)k);
  *exact = sqrt(sa * sa * sum / (n * n) + sn * sn / (n * NP / 2));
  euler_free(&e);
}

static void test_eulerian(void) {
  struct euler_result r;
  double exact;
  euler_ar1(20000, 200, &r, &exact);
  printf(
      "Eulerian: bin mean an AR(1) chain (phi 0.9: correlation time 9.5 samples), %d windows "
      "of 200 samples: correlation time %.3g samples, n_eff %.1f, short_windows %g\n",
      r.n_batches, r.prof[EP_CORR_TIME][0] / 0.01, r.prof[EP_NEFF][0], r.prof[EP_SHORT][0]);
  check("u_mean_stderr, windows of 200 samples", r.prof[EP_SE_U][0], exact);
  EXPECT(r.prof[EP_SHORT][0] == 0.0, "windows of 200 samples flagged short");
  euler_result_free(&r);
  euler_ar1(1000, 5, &r, &exact);
  const double se = r.prof[EP_SE_U][0], wide = se * sqrt(r.n_batches / r.prof[EP_NEFF][0]);
  printf(
      "Eulerian: %d windows of 5 samples: correlation time %.3g samples, n_eff %.1f, "
      "short_windows %g\n",
      r.n_batches, r.prof[EP_CORR_TIME][0] / 0.01, r.prof[EP_NEFF][0], r.prof[EP_SHORT][0]);
  printf("  batch means %.4e, widened %.4e, exact %.4e\n", se, wide, exact);
  EXPECT(r.prof[EP_SHORT][0] == 1.0, "windows of 5 samples not flagged short");
  EXPECT(se < 0.8 * exact, "batch means %.4e of short windows not too small (exact %.4e)", se,
         exact);
  check("u_mean_stderr widened, windows of 5 samples", wide, exact);
  euler_result_free(&r);
}

int main(void) {
  test_lagrangian();
  test_quadrants();
  test_eulerian();
  if (failures) printf("FAILED (%d)\n", failures);
  return failures != 0;
}
