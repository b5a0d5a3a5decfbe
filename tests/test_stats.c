/**
 * @file test_stats.c
 * @brief Unit tests of the Eulerian statistics engine (issue 5, acceptance 1-3):
 *        synthetic fields with known means, stresses and higher moments; merge invariance of
 *        the moment records; state round trip (serialise, restore, continue) bitwise.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "euler.h"
#include "expect.h"
#include "lagr.h"
#include "moments.h"
#include "state.h"
#include "stats.h"
#include "stats_setup.h"
#include "synthetic.h"

enum { NB = 8, NP = 4000, NSNAP = 400 };
static const double A = 0.3, B = -0.2, C = 0.25, SW = 0.15; /* u' = A g1, v' = B g1 + C g2 */

/* The mean velocity U(y) = 1 + S y, linear: its spread over a bin of width 0.25 adds
   S^2 0.25^2 / 12 to the variance of u about the bin mean, and nothing about U(y). */
static const double S_U = 1.0;
static double U_of_y(double y) {
  return 1.0 + S_U * y;
}
static double U_of_bin(int b) {
  return U_of_y(0.25 * (b + 0.5));
}

/* Snapshot s of the synthetic field: y uniform in (0, 2), bins of width 0.25. */
static void make_snapshot(long s, double *y, double *u, double *v, double *w, double *p,
                          double *rho) {
  for (size_t a = 0; a < NP; a++) {
    const uint64_t k = ((uint64_t)s * NP + a) * 8;
    y[a] = 2.0 * uniform(k);
    const double g1 = gauss(k + 1), g2 = gauss(k + 2), g3 = gauss(k + 3);
    u[a] = U_of_y(y[a]) + A * g1;
    v[a] = B * g1 + C * g2;
    w[a] = SW * g3;
    p[a] = 100.0 + gauss(k + 4), rho[a] = 1000.0;
  }
}

static struct euler_config config(void) {
  struct euler_config c = {.nb = NB,
                           .y0 = 0.0,
                           .y1 = 2.0,
                           .delta = 1.0,
                           .nu = 1e-3,
                           .rho0 = 1000.0,
                           .area = 1.0,
                           .t_start = 0.0,
                           .window = 1.0};
  return c;
}

/* Zero parts of the acceleration: every snapshot of feed() is a budget sample, which is what
   carries the wall stress (the solver's every stats.budget_every-th sample). */
static const double no_parts[NP * STATS_ACC];

static void feed(struct euler *e, long s0, long s1, double *buf) {
  double *y = buf, *u = y + NP, *v = u + NP, *w = v + NP, *p = w + NP, *rho = p + NP;
  for (long s = s0; s < s1; s++) {
    make_snapshot(s, y, u, v, w, p, rho);
    const struct stats_snapshot snap = {.n = NP,
                                        .y = y,
                                        .u = u,
                                        .v = v,
                                        .w = w,
                                        .p = p,
                                        .rho = rho,
                                        .t = 0.1 * s + 0.05,
                                        .fx = 2e-3,
                                        .sx = no_parts,
                                        .wall_fx = {-1.0, -1.0}};
    euler_sample(e, &snap);
  }
}

static void finalise(const struct euler *e, struct euler_result *r) {
  const size_t rows = euler_rows(e);
  int *complete = calloc(rows, sizeof *complete);
  for (size_t i = 0; i < rows; i++) complete[i] = i < e->nwin;
  euler_finalise(&e->cfg, e->win, e->mom, e->snp, e->pln, e->kin, e->rsb, e->tpl, e->tkn, complete,
                 0, rows, r);
  free(complete);
}

/* Acceptance 1: means and stresses of a field with known answers within 3 standard errors:
   the stresses about the local mean U(y) (issue 43: the default) are those of the
   fluctuations, those about the bin mean (uu_bin ...) hold the spread of U over the bin. */
static void test_known_field(double *buf) {
  const struct euler_config cfg = config();
  struct euler e;
  euler_init(&e, &cfg);
  feed(&e, 0, NSNAP, buf);
  struct euler_result r;
  finalise(&e, &r);
  const double exact[6] = {A * A, B * B + C * C, SW * SW, A * B, 0.0, 0.0};
  double worst = 0.0;
  for (int b = 0; b < NB; b++) {
    const double z_u = (r.prof[EP_U][b] - U_of_bin(b)) / r.prof[EP_SE_U][b];
    const double z_v = r.prof[EP_V][b] / r.prof[EP_SE_U + 1][b];
    EXPECT(fabs(z_u) < 3 && fabs(z_v) < 3, "bin %d: u_mean %.6f (exact %.6f, se %.2e)", b,
           r.prof[EP_U][b], U_of_bin(b), r.prof[EP_SE_U][b]);
    worst = fmax(worst, fmax(fabs(z_u), fabs(z_v)));
    EXPECT(r.prof[EP_LOCAL][b] == 1.0, "bin %d: stresses not about the local mean", b);
    for (int c = 0; c < 6; c++) {
      const double se = r.prof[EP_SE_U + 5 + c][b];
      const double z = (r.prof[EP_UU + c][b] - exact[c]) / se;
      /* the bin's spread of U: uniform y over the bin (the end bins reach no further) */
      const double spread = c == 0 ? S_U * S_U * 0.25 * 0.25 / 12.0 : 0.0;
      const double zb = (r.prof[EP_UU_BIN + c][b] - exact[c] - spread) / se;
      worst = fmax(worst, fmax(fabs(z), fabs(zb)));
      EXPECT(fabs(z) < 3, "bin %d stress %d: %.6f exact %.6f se %.2e", b, c, r.prof[EP_UU + c][b],
             exact[c], se);
      EXPECT(fabs(zb) < 3, "bin %d stress %d about the bin mean: %.6f exact %.6f se %.2e", b, c,
             r.prof[EP_UU_BIN + c][b], exact[c] + spread, se);
    }
    EXPECT(S_U * S_U * 0.25 * 0.25 / 12.0 > 3.0 * r.prof[EP_SE_U + 5][b],
           "bin %d: the spread of U is not resolved by the test (se %.2e)", b,
           r.prof[EP_SE_U + 5][b]);
    for (int i = 0; i < 3; i++) {
      EXPECT(fabs(r.prof[EP_SKEW_U + i][b]) < 0.05, "bin %d skewness %d = %.4f", b, i,
             r.prof[EP_SKEW_U + i][b]);
      EXPECT(fabs(r.prof[EP_FLAT_U + i][b] - 3.0) < 0.1, "bin %d flatness %d = %.4f", b, i,
             r.prof[EP_FLAT_U + i][b]);
    }
  }
  EXPECT(r.n_batches == NSNAP / 10 - 1, "batches %d", r.n_batches);
  EXPECT(fabs(r.u_tau_force - sqrt(2e-3)) < 1e-15, "u_tau_force %.17g", r.u_tau_force);
  EXPECT(fabs(r.u_tau_wall - sqrt(1e-3)) < 1e-15, "u_tau_wall %.17g", r.u_tau_wall);
  printf(
      "known field: %d bins x %d snapshots of %d particles, %d batches: largest deviation "
      "of means and stresses %.2f standard errors; correlation time %.3g s (snapshots 0.1 s "
      "apart, independent: expected about 0.05)\n",
      NB, NSNAP, NP, r.n_batches, worst, r.corr_time);
  EXPECT(r.corr_time < 0.1, "correlation time %.3g of independent snapshots", r.corr_time);
  euler_result_free(&r);
  euler_free(&e);
}

static double rel(double a, double b) {
  const double s = fmax(fabs(a), fabs(b));
  return s > 0 ? fabs(a - b) / s : 0.0;
}

/* Acceptance 2: the same samples in 1, 2 or 3 accumulators, merged, agree to 1e-14. */
static void test_merge(void) {
  enum { N = 30000 };
  double ref[MOM_LEN] = {0}, parts[3][MOM_LEN], worst = 0.0;
  for (int i = 0; i < N; i++) {
    const double s[MOM_NQ] = {5.0 + gauss(10 * i),
                              -2.0 + 0.5 * gauss(10 * i + 1),
                              0.1 * uniform(10 * i + 2),
                              1e5 + gauss(10 * i + 3),
                              1000.0,
                              uniform(10 * i + 4)};
    mom_add(ref, s);
  }
  for (int split = 2; split <= 3; split++) {
    memset(parts, 0, sizeof parts);
    for (int i = 0; i < N; i++) {
      const double s[MOM_NQ] = {5.0 + gauss(10 * i),
                                -2.0 + 0.5 * gauss(10 * i + 1),
                                0.1 * uniform(10 * i + 2),
                                1e5 + gauss(10 * i + 3),
                                1000.0,
                                uniform(10 * i + 4)};
      mom_add(parts[(long)i * split / N], s);
    }
    double m[MOM_LEN] = {0}, m2[MOM_LEN] = {0};
    for (int k = 0; k < split; k++) mom_merge(m, parts[k]);
    for (int k = 0; k < split; k++) mom_merge(m2, parts[k]);
    EXPECT(!memcmp(m, m2, sizeof m), "merge in a fixed order is not bitwise reproducible");
    for (int k = 0; k < MOM_LEN; k++) {
      /* co-moments of nearly uncorrelated variables are sums of cancelling terms: compare
         them on the scale of the variances they are bounded by */
      double scale = fmax(fabs(ref[k]), fabs(m[k]));
      if (k >= MOM_C2 && k < MOM_C2 + MOM_NC) {
        const int i = mom_pair[k - MOM_C2][0], j = mom_pair[k - MOM_C2][1];
        scale = sqrt(ref[MOM_C2 + i] * ref[MOM_C2 + j]);
      }
      if (k >= MOM_M3 && k < MOM_M3 + 3) scale = pow(ref[MOM_C2 + k - MOM_M3], 1.5) / sqrt(N);
      if (k >= MOM_CY && k < MOM_CYY) scale = sqrt(ref[MOM_C2 + k - MOM_CY] * ref[MOM_CYY]);
      const double e = scale > 0 ? fabs(ref[k] - m[k]) / scale : 0.0;
      worst = fmax(worst, e);
      /* the co-moments with y (issue 43) are new slots, not a loosened one: measured 1.01e-14
         for C2_yy of a uniform y (the same formula as C2_uu, whose samples give less) */
      EXPECT(e < (k >= MOM_CY ? 2e-14 : 1e-14), "split %d slot %d: %.17g vs %.17g", split, k,
             ref[k], m[k]);
    }
  }
  printf(
      "merge invariance: %d samples in 1, 2, 3 accumulators, largest relative difference "
      "%.2e\n",
      N, worst);
  (void)rel;
}

/* A copy of a state list's arrays (what a checkpoint would write). */
struct saved {
  int n;
  char name[48][96];
  int rank[48];
  size_t dims[48][STATE_MAX_RANK];
  double *data[48];
};

static void save(struct state_list *L, struct saved *sv) {
  sv->n = L->n;
  if (L->n > 48) {
    printf("FAIL: more than 48 state fields\n");
    exit(1);
  }
  for (int i = 0; i < L->n; i++) {
    const struct state_field *f = &L->f[i];
    snprintf(sv->name[i], sizeof sv->name[i], "%s", f->name);
    sv->rank[i] = f->rank;
    memcpy(sv->dims[i], f->dims, sizeof f->dims);
    const size_t n = state_count(f);
    sv->data[i] = malloc(n * sizeof(double));
    memcpy(sv->data[i], f->data, n * sizeof(double));
  }
}

static void restore(struct state_list *L, const struct saved *sv) {
  EXPECT(L->n == sv->n, "state lists differ in length");
  for (int i = 0; i < L->n && i < sv->n; i++) {
    struct state_field *f = state_find(L, sv->name[i]);
    EXPECT(f != NULL, "field %s missing", sv->name[i]);
    if (!f) continue;
    void *dst = f->reserve ? f->reserve(f->owner, sv->rank[i], sv->dims[i]) : f->data;
    EXPECT(dst != NULL, "reserve refused %s", sv->name[i]);
    size_t n = 1;
    for (int k = 0; k < sv->rank[i]; k++) n *= sv->dims[i][k];
    if (dst) memcpy(dst, sv->data[i], n * sizeof(double));
  }
}

/* Feed snapshots s0..s1-1 of the synthetic field to a whole engine (positions in x, z and ids
   too, so that all three engines see data). */
static void feed_all(struct stats *st, long s0, long s1, double *buf) {
  double *y = buf, *u = y + NP, *v = u + NP, *w = v + NP, *p = w + NP, *rho = p + NP;
  static double x[NP], z[NP];
  static int64_t id[NP];
  for (long s = s0; s < s1; s++) {
    make_snapshot(s, y, u, v, w, p, rho);
    for (size_t a = 0; a < NP; a++)
      id[a] = (int64_t)a, x[a] = uniform(((uint64_t)s * NP + a) * 8 + 5),
      z[a] = uniform(((uint64_t)s * NP + a) * 8 + 6);
    const struct stats_snapshot snap = {.n = NP,
                                        .x = x,
                                        .y = y,
                                        .z = z,
                                        .u = u,
                                        .v = v,
                                        .w = w,
                                        .p = p,
                                        .rho = rho,
                                        .ax = u,
                                        .ay = v,
                                        .az = w,
                                        .id = id,
                                        .t = 0.1 * s + 0.05,
                                        .fx = 2e-3,
                                        .wall_fx = {-1.0, -1.0}};
    stats_sample(st, &snap);
  }
}

static struct test_stats_config all_engines(void) {
  struct test_stats_config c = {.eulerian = 1, .eul = config()};
  c.corr = (struct corr_config){.n_levels = 2,
                                .y = {0.5, 0.25},
                                .nx = 8,
                                .nz = 4,
                                .lx = 1.0,
                                .lz = 1.0,
                                .half = 0.05,
                                .delta = 1.0,
                                .window = 1.0};
  c.lagr = (struct lagr_config){.n_levels = 2,
                                .y = {0.5, 0.3},
                                .x0 = 0.5,
                                .half = 0.05,
                                .lx = 1.0,
                                .lz = 1.0,
                                .delta = 1.0,
                                .horizon = 1.0,
                                .release_every = 0.5,
                                .n_lags = 10,
                                .n_stations = 1,
                                .station = {0.1},
                                .pdf_bins = 10};
  c.pdf = (struct pdf_config){.n_levels = 2,
                              .y = {0.3, 0.6},
                              .half = 0.05,
                              .delta = 1.0,
                              .window = 1.0,
                              .u_tau = 0.1,
                              .fine = 0.05,
                              .bins = 20,
                              .range = 4.0};
  return c;
}

/* Acceptance 3 (engine side): serialise -> restore in a fresh engine -> continue gives the
   same state, field by field and bit for bit, as never stopping (all three engines). */
static void test_round_trip(double *buf) {
  const struct test_stats_config cfg = all_engines();
  struct stats a, b, c;
  test_stats_init(&a, &cfg);
  feed_all(&a, 0, 137, buf);
  test_stats_init(&b, &cfg);
  feed_all(&b, 0, 61, buf);
  struct state_list L = {0};
  stats_state(&b, &L);
  struct saved sv;
  save(&L, &sv);
  state_free(&L);
  stats_free(&b);
  test_stats_init(&c, &cfg);
  stats_state(&c, &L);
  restore(&L, &sv);
  state_free(&L);
  feed_all(&c, 61, 137, buf);
  struct state_list La = {0}, Lc = {0};
  stats_state(&a, &La);
  stats_state(&c, &Lc);
  int same = La.n == Lc.n;
  for (int i = 0; i < La.n && same; i++) {
    const struct state_field *fa = &La.f[i], *fc = state_find(&Lc, fa->name);
    same = fc && state_count(fa) == state_count(fc) &&
           !memcmp(fa->data, fc->data, state_count(fa) * sizeof(double));
    if (!same) printf("field %s differs\n", fa->name);
  }
  EXPECT(same, "state after a round trip differs from the uninterrupted run");
  const struct lagr *la = test_la(&a);
  EXPECT(la->releases > 2 && la->ntracks > 0, "Lagrangian engine idle in the round trip");
  const struct pdf *pd = test_pdf(&a);
  EXPECT(pd->nwin >= 2 && pd->pow[0] > 0, "PDF engine idle in the round trip");
  printf(
      "state round trip after 61 of 137 snapshots (%d fields, Eulerian, correlations, "
      "Lagrangian with %g releases done and %zu tracks active): %s\n",
      La.n, la->releases, la->ntracks, same ? "bitwise identical" : "DIFFERENT");
  for (int i = 0; i < sv.n; i++) free(sv.data[i]);
  state_free(&La), state_free(&Lc);
  stats_free(&c);
  stats_free(&a);
}

/* One level at y = 0.3 (y+ 10) of an nx x nz grid over lx x lz, slab half 0.05, windows of
   the given length (0: one window). */
static struct corr_config one_level(int nx, int nz, double lx, double lz, double window) {
  return (struct corr_config){.n_levels = 1,
                              .y = {0.3},
                              .y_plus = {10},
                              .nx = nx,
                              .nz = nz,
                              .lx = lx,
                              .lz = lz,
                              .half = 0.05,
                              .delta = 1.0,
                              .window = window};
}

/* Acceptance 1: a field with a known sinusoidal correlation gives R(l) to 1e-6. */
static void test_corr(void) {
  enum { NX = 16, NZ = 8, M = 3, NM = 1 };
  const double lx = 1.6, lz = 0.8, amp_a = 0.7, amp_b = 0.4, amp_c = 0.3, amp_d = 0.2;
  const double phi = 0.4, tp = 6.283185307179586;
  const struct corr_config cfg = one_level(NX, NZ, lx, lz, 0.0);
  struct corr c;
  corr_init(&c, &cfg);
  double x[NX * NZ], y[NX * NZ], z[NX * NZ], u[NX * NZ], v[NX * NZ], w[NX * NZ];
  for (int i = 0; i < NX; i++)
    for (int k = 0; k < NZ; k++) {
      const int a = i * NZ + k;
      x[a] = (i + 0.5) * lx / NX, z[a] = (k + 0.5) * lz / NZ, y[a] = 0.3;
      u[a] = amp_a * cos(tp * M * x[a] / lx) + amp_b * cos(tp * NM * z[a] / lz);
      v[a] = amp_c * cos(tp * M * x[a] / lx + phi);
      w[a] = amp_d * sin(tp * NM * z[a] / lz);
    }
  const struct stats_snapshot snap = {
      .n = NX * NZ, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .t = 1.0};
  corr_sample(&c, &snap);
  corr_sample(&c, &snap);
  double rx[4 * NX], rz[4 * NZ], ex[3 * (NX / 2 + 1)], ez[3 * (NZ / 2 + 1)], worst = 0.0;
  corr_results(&c, rx, rz, ex, ez);
  for (int i = 0; i < NX; i++) {
    const double l = i * lx / NX;
    const double want[4] = {0.5 * amp_a * amp_a * cos(tp * M * l / lx) + 0.5 * amp_b * amp_b,
                            0.5 * amp_c * amp_c * cos(tp * M * l / lx), 0.5 * amp_d * amp_d,
                            0.5 * amp_a * amp_c * cos(tp * M * l / lx + phi)};
    for (int q = 0; q < 4; q++) worst = fmax(worst, fabs(rx[q * NX + i] - want[q]));
  }
  for (int k = 0; k < NZ; k++) {
    const double l = k * lz / NZ;
    const double want[4] = {0.5 * amp_a * amp_a + 0.5 * amp_b * amp_b * cos(tp * NM * l / lz),
                            0.5 * amp_c * amp_c, 0.5 * amp_d * amp_d * cos(tp * NM * l / lz),
                            0.5 * amp_a * amp_c * cos(phi)};
    for (int q = 0; q < 4; q++) worst = fmax(worst, fabs(rz[q * NZ + k] - want[q]));
  }
  EXPECT(worst < 1e-6, "two-point correlation off by %.3e", worst);
  /* spectra: Parseval and the energy at the forced wavenumbers */
  double sx = 0, sz = 0;
  for (int m = 0; m <= NX / 2; m++) sx += ex[m] * tp / lx;
  for (int m = 0; m <= NZ / 2; m++) sz += ez[m] * tp / lz;
  const double uu0 = 0.5 * (amp_a * amp_a + amp_b * amp_b);
  const double e_m = ex[M] * tp / lx, e_n = ez[NM] * tp / lz;
  const double werr = fmax(fmax(fabs(sx - uu0), fabs(sz - uu0)),
                           fmax(fabs(e_m - 0.5 * amp_a * amp_a), fabs(e_n - 0.5 * amp_b * amp_b)));
  EXPECT(werr < 1e-6, "spectra off by %.3e", werr);
  printf(
      "correlations: sinusoidal field on a %d x %d plane, largest error of R_ij(l) %.2e, of "
      "the spectra (Parseval, forced modes) %.2e\n",
      NX, NZ, worst, werr);
  corr_free(&c);
}

/* Gaps (corr.h): the field of x alone, u = A cos(M k x), v = C sin(N k x), w = D cos(k x),
   k = 2 pi / lx, sampled at the cell centres of every z row but the empty rows 1, 4 and 5 of
   8. Over the filled pairs the field's correlation along x is exactly the full grid's
   (A^2/2 cos(M k l), ...) and along z constant, R(0): the gap-corrected results must give them
   to round-off, where the zero-filled ones are lower by P(l) (5/8 along x) and have a white
   floor in the spectra. The same through the window records (corr_range_values). */
static void test_corr_gaps(void) {
  enum { NX = 16, NZ = 8, M = 3, N = 5, NXH = NX / 2 + 1, NZH = NZ / 2 + 1 };
  const double lx = 1.6, lz = 0.8, A = 0.7, C = 0.4, D = 0.2, tp = 6.283185307179586;
  const struct corr_config cfg = one_level(NX, NZ, lx, lz, 0.5);
  struct corr c;
  corr_init(&c, &cfg);
  double x[NX * NZ], y[NX * NZ], z[NX * NZ], u[NX * NZ], v[NX * NZ], w[NX * NZ];
  int n = 0;
  for (int i = 0; i < NX; i++)
    for (int k = 0; k < NZ; k++) {
      if (k == 1 || k == 4 || k == 5) continue; /* the empty rows */
      x[n] = (i + 0.5) * lx / NX, z[n] = (k + 0.5) * lz / NZ, y[n] = 0.3;
      u[n] = A * cos(tp * M * x[n] / lx), v[n] = C * sin(tp * N * x[n] / lx);
      w[n] = D * cos(tp * x[n] / lx), n++;
    }
  for (int j = 0; j < 4; j++) { /* two windows of two snapshots */
    const struct stats_snapshot snap = {
        .n = (size_t)n, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .t = 0.3 * j};
    corr_sample(&c, &snap);
  }
  corr_win_close(&c, 1.0);
  double rx[4 * NX], rz[4 * NZ], ex[3 * NXH], ez[3 * NZH], px[NX], pz[NZ], worst = 0.0;
  int corrected = 0;
  corr_results(&c, rx, rz, ex, ez);
  corr_pair_fraction(&c, px, pz, &corrected);
  EXPECT(corrected == 1, "level not gap-corrected with 3 of 8 rows empty");
  const double amp[3] = {A, C, D};
  const int mode[3] = {M, N, 1};
  for (int i = 0; i < NX; i++) {
    const double l = i * lx / NX;
    for (int q = 0; q < 3; q++)
      worst =
          fmax(worst, fabs(rx[q * NX + i] - 0.5 * amp[q] * amp[q] * cos(tp * mode[q] * l / lx)));
    worst = fmax(worst, fabs(rx[3 * NX + i])); /* <u(x) v(x + l)> = 0: other modes */
    worst = fmax(worst, fabs(px[i] - 5.0 / 8.0));
  }
  for (int k = 0; k < NZ; k++)
    for (int q = 0; q < 3; q++) worst = fmax(worst, fabs(rz[q * NZ + k] - 0.5 * amp[q] * amp[q]));
  /* the spectra: all of the energy in the forced mode, none in the white floor */
  double floor_x = 0.0, werr = 0.0;
  for (int q = 0; q < 3; q++)
    for (int m = 0; m < NXH; m++) {
      const double e = ex[q * NXH + m] * tp / lx;
      if (m == mode[q])
        werr = fmax(werr, fabs(e - 0.5 * amp[q] * amp[q]));
      else
        floor_x = fmax(floor_x, fabs(e));
    }
  EXPECT(worst < 1e-12, "gap-corrected R off by %.3e", worst);
  EXPECT(werr < 1e-12 && floor_x < 1e-12,
         "gap-corrected spectra: forced mode off by %.3e, "
         "floor %.3e",
         werr, floor_x);
  /* the window records give the same (2 closed windows pooled), each window too */
  const size_t nv = corr_nv(&c);
  double *val = malloc(nv * sizeof(double)), wworst = 0.0;
  for (size_t r0 = 0; r0 < 2; r0++) {
    corr_range_values(&c, r0, r0 == 0 ? 2 : r0 + 1, val);
    for (int i = 0; i < 4 * NX; i++) wworst = fmax(wworst, fabs(val[i] - rx[i]));
    for (int i = 0; i < 4 * NZ; i++) wworst = fmax(wworst, fabs(val[4 * NX + i] - rz[i]));
    for (int i = 0; i < 3 * NXH; i++) wworst = fmax(wworst, fabs(val[4 * NX + 4 * NZ + i] - ex[i]));
  }
  int wcorr = 0;
  double wpx[NX], wpz[NZ];
  corr_range_pair_fraction(&c, 0, 2, wpx, wpz, &wcorr);
  EXPECT(wcorr == 1 && wworst < 1e-12, "window records: corrected %d, off by %.3e", wcorr, wworst);
  /* the zero-filled sums alone: R(0) lowered by the filled share, P = 5/8 */
  const double raw0 = rx[0] * px[0];
  EXPECT(fabs(raw0 - 0.5 * A * A * 5.0 / 8.0) < 1e-12, "zero-filled R_uu(0) %.6f", raw0);
  printf(
      "correlations with gaps: 3 of 8 rows empty, gap-corrected R_ij(l) within %.2e of the "
      "full field's (zero-filled: R_uu(0) %.4f against %.4f), spectra's floor %.2e, forced "
      "modes %.2e; through the window records %.2e\n",
      worst, raw0, 0.5 * A * A, floor_x, werr, wworst);
  free(val);
  corr_free(&c);
}

/* Snapshot j of window w for test_corr_windows: one particle per cell at y = 0.3 and at the
   mirror 1.7; modes whose amplitudes and phases change from window to window, plus
   pseudo-random values (all wavenumbers, uv with a phase). */
enum { CW_NX = 16, CW_NZ = 8, CW_NP = 2 * CW_NX * CW_NZ };
static void corr_window_snapshot(int w, int j, double *x, double *y, double *z, double *u,
                                 double *v, double *wv) {
  const double lx = 1.6, lz = 0.8, tp = 6.283185307179586, a = 0.5 + 0.2 * w, ph = 0.3 * w + j;
  for (int n = 0; n < CW_NP; n++) {
    const int c = n % (CW_NX * CW_NZ), i = c / CW_NZ, k = c % CW_NZ;
    const uint64_t key = ((uint64_t)(w * 2 + j) * CW_NP + (uint64_t)n) * 4;
    x[n] = (i + 0.5) * lx / CW_NX, z[n] = (k + 0.5) * lz / CW_NZ, y[n] = n < CW_NP / 2 ? 0.3 : 1.7;
    u[n] = a * cos(tp * 3 * x[n] / lx + ph) + 0.3 * cos(tp * z[n] / lz) + 0.2 * gauss(key);
    v[n] = 0.4 * a * cos(tp * 3 * x[n] / lx + ph + 0.7) + 0.1 * w * gauss(key + 1);
    wv[n] = a * sin(tp * 2 * z[n] / lz + ph) + 0.1 * gauss(key + 2);
  }
}

/* Issue 25: the batch-means standard errors of R(l_x), R(l_z), E(k_x), E(k_z) from the 1-D
   window sums equal those of a direct computation (one engine per window, corr_results on
   its 2-D spectra); the whole-run sums are bitwise those of an engine without windows; a
   resume without window records makes the window of the resume partial (not a batch). */
static void test_corr_windows(void) {
  enum { NW = 4, NXH = CW_NX / 2 + 1, NZH = CW_NZ / 2 + 1, NV = 4 * CW_NX + 4 * CW_NZ };
  struct corr_config cfg = {.n_levels = 1,
                            .y = {0.3},
                            .y_plus = {10},
                            .nx = CW_NX,
                            .nz = CW_NZ,
                            .lx = 1.6,
                            .lz = 0.8,
                            .half = 0.05,
                            .delta = 1.0,
                            .window = 1.0};
  struct corr c, whole, one[NW];
  corr_init(&c, &cfg);
  struct corr_config cw = cfg;
  cw.window = 0.0;
  corr_init(&whole, &cw);
  static double x[CW_NP], y[CW_NP], z[CW_NP], u[CW_NP], v[CW_NP], w[CW_NP];
  /* sums of the direct per-window results: R x, R z, E x, E z */
  double s1[NV + 3 * NXH + 3 * NZH] = {0}, s2[NV + 3 * NXH + 3 * NZH] = {0};
  for (int win = 0; win <= NW; win++) { /* window NW stays open: not a batch */
    if (win < NW) corr_init(&one[win], &cw);
    for (int j = 0; j < 2; j++) {
      corr_window_snapshot(win, j, x, y, z, u, v, w);
      const struct stats_snapshot snap = {
          .n = CW_NP, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .t = win + 0.25 + 0.5 * j};
      corr_sample(&c, &snap);
      corr_sample(&whole, &snap);
      if (win < NW) corr_sample(&one[win], &snap);
    }
    if (win == NW) break;
    double r[NV + 3 * NXH + 3 * NZH];
    corr_results(&one[win], r, r + 4 * CW_NX, r + NV, r + NV + 3 * NXH);
    for (int k = 0; k < NV + 3 * NXH + 3 * NZH; k++) s1[k] += r[k], s2[k] += r[k] * r[k];
    corr_free(&one[win]);
  }
  EXPECT(memcmp(c.spec, whole.spec, (size_t)CW_NX * NZH * CS_LEN * sizeof(double)) == 0 &&
             c.samples[0] == whole.samples[0] && c.samples[0] == 2.0 * 2 * (NW + 1),
         "the whole-run spectra with windows differ from those without");
  double e[NV + 3 * NXH + 3 * NZH], worst = 0.0, scale = 0.0;
  int nb = 0;
  corr_stderr(&c, e, e + 4 * CW_NX, e + NV, e + NV + 3 * NXH, &nb);
  for (int k = 0; k < NV + 3 * NXH + 3 * NZH; k++) {
    const double want = sqrt(fmax(s2[k] - s1[k] * s1[k] / NW, 0.0) / (NW - 1) / NW);
    worst = fmax(worst, fabs(e[k] - want)), scale = fmax(scale, want);
  }
  EXPECT(nb == NW && c.nwin == NW, "batches %d, closed windows %zu (expected %d)", nb, c.nwin, NW);
  EXPECT(scale > 1e-3 && worst < 1e-9 * scale,
         "window standard errors off by %.3e (largest %.3e) from the direct computation", worst,
         scale);
  /* a checkpoint of format 1.7: the whole-run sums, no window records */
  struct corr old;
  corr_init(&old, &cfg);
  memcpy(old.spec, c.spec, (size_t)CW_NX * NZH * CS_LEN * sizeof(double));
  old.samples[0] = c.samples[0];
  for (int win = NW; win < NW + 4; win++) {
    corr_window_snapshot(win, 1, x, y, z, u, v, w);
    const struct stats_snapshot snap = {
        .n = CW_NP, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .t = win + 0.75};
    corr_sample(&old, &snap);
  }
  corr_stderr(&old, e, e + 4 * CW_NX, e + NV, e + NV + 3 * NXH, &nb);
  EXPECT(old.nwin == 3 && old.win[CW_PARTIAL] == 1.0 && nb == 2 && old.win[CW_T0] == NW,
         "resume without window records: %zu closed windows, %d batches (expected 3, 2)", old.nwin,
         nb);
  printf(
      "correlation windows: %d batches, standard errors within %.2e of the direct "
      "computation (largest %.3e); whole-run sums bitwise unchanged\n",
      NW, worst, scale);
  corr_free(&old), corr_free(&c), corr_free(&whole);
}

/* Acceptance 1: tracks from Ornstein-Uhlenbeck processes of known time scale give
   rho^L(tau) = exp(-tau/T), D(tau) = 2 var (1 - exp(-tau/T)) and T_L within 3 standard
   errors of Eq. 5.61 applied to exp(-tau/T) (T (1 - e^-4), times the trapezoid factor). */
static void test_lagr_ou(void) {
  enum { NPART = 2000, RELEASES = 40, NLAG = 40 };
  const double T = 1.0, Ta = 0.25, dt = 0.125, horizon = 5.0;
  const struct lagr_config cfg = {.n_levels = 1,
                                  .y = {0.5},
                                  .y_plus = {50},
                                  .x0 = 0.0,
                                  .half = 0.05,
                                  .lx = 10.0,
                                  .lz = 0.0,
                                  .delta = 1.0,
                                  .horizon = horizon,
                                  .release_every = horizon,
                                  .n_lags = NLAG,
                                  .pdf_bins = 10};
  struct lagr g;
  lagr_init(&g, &cfg);
  static double x[NPART], y[NPART], z[NPART], u[NPART], v[NPART], w[NPART], ax[NPART];
  static double zero[NPART];
  static int64_t id[NPART];
  const double f = exp(-dt / T), fa = exp(-dt / Ta);
  for (int p = 0; p < NPART; p++) {
    id[p] = p, x[p] = 0.0, y[p] = 0.5, z[p] = 0.0;
    u[p] = 3.0 + gauss(7000000 + 3 * p), v[p] = gauss(7000001 + 3 * p), w[p] = 0.0;
    ax[p] = gauss(7000002 + 3 * p);
  }
  const long steps = (long)(RELEASES * horizon / dt) + 1;
  for (long n = 0; n < steps; n++) {
    const struct stats_snapshot snap = {.n = NPART,
                                        .x = x,
                                        .y = y,
                                        .z = z,
                                        .u = u,
                                        .v = v,
                                        .w = w,
                                        .ax = ax,
                                        .ay = zero,
                                        .az = zero,
                                        .id = id,
                                        .t = n * dt};
    lagr_sample(&g, &snap);
    for (int p = 0; p < NPART; p++) {
      const uint64_t k = 100000000ULL + ((uint64_t)n * NPART + (uint64_t)p) * 4;
      u[p] = 3.0 + f * (u[p] - 3.0) + sqrt(1 - f * f) * gauss(k);
      v[p] = f * v[p] + sqrt(1 - f * f) * gauss(k + 1);
      w[p] = 0.1 * gauss(k + 2); /* uncorrelated */
      ax[p] = fa * ax[p] + sqrt(1 - fa * fa) * gauss(k + 3);
    }
  }
  const size_t nlag = NLAG + 1;
  double fn[LF_LEN * (NLAG + 1)], tl[3];
  lagr_functions(&g, 0, fn, tl);
  double dr = 0, da = 0, dd = 0;
  for (size_t k = 0; k < nlag; k++) {
    const double tau = k * horizon / NLAG;
    dr = fmax(dr, fabs(fn[LF_RHO_L * nlag + k] - exp(-tau / T)));
    dr = fmax(dr, fabs(fn[(LF_RHO_L + 1) * nlag + k] - exp(-tau / T)));
    da = fmax(da, fabs(fn[LF_RHO_A * nlag + k] - exp(-tau / Ta)));
    dd = fmax(dd, fabs(fn[LF_D * nlag + k] - 2.0 * (1.0 - exp(-tau / T))));
  }
  const double q = dt / (2 * T), expect = T * (1 - exp(-4.0)) * q / tanh(q);
  const double *W = g.tl; /* u: [n, mean, M2] over the releases */
  const double se = sqrt(W[SCAL_M2] / (W[SCAL_N] - 1) / W[SCAL_N]);
  printf(
      "Lagrangian OU tracks (%d particles x %.0f releases, T = %g): max |rho_L - exp(-tau/T)| "
      "%.4f, max |rho_a - exp(-tau/T_a)| %.4f, max |D_u - 2(1 - exp)| %.4f; T_L merged %.4f, "
      "release mean %.4f +- %.4f, expected %.4f (%.2f standard errors)\n",
      NPART, g.releases, T, dr, da, dd, tl[0], W[SCAL_MEAN], se, expect,
      (W[SCAL_MEAN] - expect) / se);
  EXPECT(g.releases >= RELEASES - 1, "releases %g", g.releases);
  EXPECT(dr < 0.02 && da < 0.02 && dd < 0.04, "Lagrangian correlations off");
  EXPECT(fabs(W[SCAL_MEAN] - expect) < 3 * se, "T_L of the releases not within 3 se");
  EXPECT(fabs(tl[0] - expect) < 3 * se, "merged T_L not within 3 se");
  lagr_free(&g);
}

/* Variance of dt (u_0 + ... + u_{k-1}) for a stationary AR(1) of unit variance and lag-one
   correlation f: dt^2 (k + 2 sum_{m=1}^{k-1} (k - m) f^m). */
static double ar1_sum_var(int k, double f, double dt) {
  double s = k, fm = 1.0;
  for (int m = 1; m < k; m++) fm *= f, s += 2.0 * (k - m) * fm;
  return dt * dt * s;
}

/* The largest |value - expected| / standard error over the lags 1.. of one row. */
static double worst_z(const double *row, const double *n, size_t nlag, double (*want)(int, int),
                      double (*se)(int, int, double), int comp) {
  double z = 0.0;
  for (size_t k = 1; k < nlag; k++)
    z = fmax(z, fabs(row[k] - want((int)k, comp)) / se((int)k, comp, n[k]));
  return z;
}

/* The drift test's process: u = U + OU (T = 1), v = V + OU, w white (sd 0.1); dt = dtau. */
static const double DRIFT_U[3] = {3.0, -0.2, 0.0}, DRIFT_DT = 0.125;
static double drift_f(void) {
  return exp(-DRIFT_DT / 1.0);
}
static double dvar(int k, int c) {
  return c < 2 ? ar1_sum_var(k, drift_f(), DRIFT_DT) : 0.01 * DRIFT_DT * DRIFT_DT * k;
}
static double want_mean(int k, int c) {
  return DRIFT_U[c] * k * DRIFT_DT;
}
static double se_mean(int k, int c, double n) {
  return sqrt(dvar(k, c) / n);
}
static double se_var(int k, int c, double n) {
  return dvar(k, c) * sqrt(2.0 / (n - 1));
}

/* Write one sums field of g as a checkpoint of an older format stores it (records of w sums:
   LG_LEN_1_6 up to format 1.6, LG_LEN_1_8 in 1.7-1.8) into the memory its reserve() gives,
   widen it with after_read(); 1 if the old sums came back bitwise and the sums after them (of
   dr, of the actual lags) are NaN exactly in the records with samples. */
static int widen_one(struct state_field *f, size_t rows, size_t w) {
  double *ref = malloc(rows * LG_LEN * sizeof(double)), *old = malloc(rows * w * 8);
  memcpy(ref, f->data, rows * LG_LEN * sizeof(double));
  for (size_t r = 0; r < rows; r++) memcpy(old + r * w, ref + r * LG_LEN, w * sizeof(double));
  const size_t dims[3] = {f->dims[0], f->dims[1], w}, bad[3] = {f->dims[0], 7, 44};
  const size_t bad_w[3] = {f->dims[0], f->dims[1], LG_LEN_1_6 + 1};
  int ok = f->reserve(f->owner, 3, bad) == NULL && f->reserve(f->owner, 3, bad_w) == NULL;
  double *dst = f->reserve(f->owner, 3, dims);
  ok = ok && dst == f->data;
  if (ok) {
    memcpy(dst, old, rows * w * sizeof(double));
    f->after_read(f->owner, 3, dims);
    for (size_t r = 0; r < rows; r++) {
      const double *R = dst + r * LG_LEN, *W = ref + r * LG_LEN;
      ok = ok && !memcmp(R, W, w * sizeof(double));
      for (size_t i = w; i < LG_LEN; i++) ok = ok && (R[LG_N] > 0 ? isnan(R[i]) : R[i] == 0.0);
    }
  }
  free(ref), free(old);
  return ok;
}

/* The engine's sums read from a checkpoint of format 1.8 (records without the sums of the
   actual lags) or 1.6 (also without the sums of dr): every other sum as stored, the mean lag
   time NaN, and for 1.6 the mean displacement and its variance NaN (not recoverable), sigma2
   and the mean velocities as before (and for 1.8 the mean displacement too). */
static void lagr_widen_check(struct lagr *g, size_t w, const char *version) {
  const size_t nlag = g->nlag;
  double *before = malloc(LF_LEN * nlag * sizeof(double)), *after = malloc(LF_LEN * nlag * 8);
  double tl[3];
  lagr_functions(g, 0, before, tl);
  struct state_list L = {0};
  lagr_state(g, &L);
  struct state_field *fs = state_find(&L, "stats/lagrangian/sums");
  struct state_field *fl = state_find(&L, "stats/lagrangian/slot_sums");
  const int ok_s = fs && widen_one(fs, nlag, w);
  const int ok_l = fl && widen_one(fl, (size_t)g->n_slots * nlag, w);
  lagr_functions(g, 0, after, tl);
  int kept = 1, nan = 1;
  for (size_t k = 0; k < nlag; k++) {
    nan = nan && isnan(after[LF_TAU * nlag + k]);
    for (int c = 0; c < 3; c++) {
      const int rows[] = {LF_SIG2 + c, LF_U0 + c, LF_UT + c, LF_DR + c, LF_DVAR + c};
      for (int j = 0; j < (w == LG_LEN_1_6 ? 3 : 5); j++)
        kept = kept && after[rows[j] * nlag + k] == before[rows[j] * nlag + k];
      if (w == LG_LEN_1_6)
        nan = nan && isnan(after[(LF_DR + c) * nlag + k]) && isnan(after[(LF_DVAR + c) * nlag + k]);
    }
  }
  printf(
      "Lagrangian sums of checkpoint format %s: widened (sums %s, slot sums %s), the stored "
      "functions %s, the missing ones (lag time%s) %s\n",
      version, ok_s ? "ok" : "WRONG", ok_l ? "ok" : "WRONG", kept ? "kept" : "CHANGED",
      w == LG_LEN_1_6 ? ", mean displacement" : "", nan ? "NaN" : "NOT NaN");
  EXPECT(ok_s && ok_l && kept && nan, "reading the sums of format %s", version);
  state_free(&L);
  free(before), free(after);
}

/* Issue 25: tracks moving with a known mean velocity (U, V, 0) plus OU fluctuations give the
   Lagrangian mean velocities (U, V, 0) at release and at every lag, the mean displacement
   <dr_i>(tau) = U_i tau and the displacement variance of the fluctuations alone,
   dt^2 sum_{m,n} f^|m-n| (the mean drift removed from sigma_i^2), each within 4 standard
   errors; sigma_i^2 = variance + mean^2. Then the sums as a checkpoint of format 1.8 holds
   them (records without the sums of the actual lags), and then as one of format 1.6 (also
   without the sums of dr), are widened by the state list's callbacks: the other sums bitwise,
   the mean lag time NaN, for 1.6 the mean displacement NaN. */
static void test_lagr_drift(void) {
  enum { NPART = 2000, RELEASES = 24, NLAG = 40 };
  const double horizon = NLAG * DRIFT_DT, f = drift_f();
  const struct lagr_config cfg = {.n_levels = 1,
                                  .y = {0.5},
                                  .y_plus = {50},
                                  .half = 0.05,
                                  .lx = 10.0,
                                  .delta = 1.0,
                                  .horizon = horizon,
                                  .release_every = horizon + DRIFT_DT,
                                  .n_lags = NLAG,
                                  .pdf_bins = 10};
  struct lagr g;
  lagr_init(&g, &cfg);
  static double x[NPART], y[NPART], z[NPART], u[NPART], v[NPART], w[NPART];
  static int64_t id[NPART];
  for (int p = 0; p < NPART; p++) {
    id[p] = p, u[p] = DRIFT_U[0] + gauss(8000000 + 3 * p);
    v[p] = DRIFT_U[1] + gauss(8000001 + 3 * p), w[p] = 0.1 * gauss(8000002 + 3 * p);
  }
  const long steps = (long)(RELEASES * (horizon + DRIFT_DT) / DRIFT_DT) + 1;
  for (long n = 0; n < steps; n++) {
    const double t = n * DRIFT_DT;
    if (t >= g.next_release) /* nothing tracked: all particles back on the release line */
      for (int p = 0; p < NPART; p++) x[p] = 0.0, y[p] = 0.5, z[p] = 0.0;
    const struct stats_snapshot snap = {
        .n = NPART, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .id = id, .t = t};
    lagr_sample(&g, &snap);
    for (int p = 0; p < NPART; p++) {
      const uint64_t k = 300000000ULL + ((uint64_t)n * NPART + (uint64_t)p) * 3;
      x[p] += u[p] * DRIFT_DT, y[p] += v[p] * DRIFT_DT, z[p] += w[p] * DRIFT_DT;
      u[p] = DRIFT_U[0] + f * (u[p] - DRIFT_U[0]) + sqrt(1 - f * f) * gauss(k);
      v[p] = DRIFT_U[1] + f * (v[p] - DRIFT_U[1]) + sqrt(1 - f * f) * gauss(k + 1);
      w[p] = 0.1 * gauss(k + 2);
    }
  }
  const size_t nlag = NLAG + 1;
  static double fn[LF_LEN * (NLAG + 1)];
  double tl[3], zm = 0, zv = 0, zu = 0, ident = 0;
  lagr_functions(&g, 0, fn, tl);
  const double *n = fn + LF_N * nlag;
  for (int c = 0; c < 3; c++) {
    zm = fmax(zm, worst_z(fn + (LF_DR + c) * nlag, n, nlag, want_mean, se_mean, c));
    zv = fmax(zv, worst_z(fn + (LF_DVAR + c) * nlag, n, nlag, dvar, se_var, c));
    const double sd = c < 2 ? 1.0 : 0.1;
    for (size_t k = 0; k < nlag; k++) {
      zu = fmax(zu, fabs(fn[(LF_U0 + c) * nlag + k] - DRIFT_U[c]) / (sd / sqrt(n[k])));
      zu = fmax(zu, fabs(fn[(LF_UT + c) * nlag + k] - DRIFT_U[c]) / (sd / sqrt(n[k])));
      const double m = fn[(LF_DR + c) * nlag + k];
      ident =
          fmax(ident, fabs(fn[(LF_SIG2 + c) * nlag + k] - fn[(LF_DVAR + c) * nlag + k] - m * m));
    }
  }
  printf(
      "Lagrangian drift tracks (%d particles x %.0f releases, U = %g, V = %g): <dx>(5 s) = %.4f "
      "(exact %g), var dx(5 s) = %.4f (exact %.4f, sigma2_x %.3f); worst over the lags in "
      "standard errors: mean displacement %.2f, its variance %.2f, mean velocities %.2f\n",
      NPART, g.releases, DRIFT_U[0], DRIFT_U[1], fn[LF_DR * nlag + NLAG], want_mean(NLAG, 0),
      fn[LF_DVAR * nlag + NLAG], dvar(NLAG, 0), fn[LF_SIG2 * nlag + NLAG], zm, zv, zu);
  EXPECT(g.releases >= RELEASES - 1 && n[NLAG] >= NPART * (RELEASES - 1), "releases %g, n %g",
         g.releases, n[NLAG]);
  EXPECT(zm < 4.0 && zv < 4.0 && zu < 4.0, "Lagrangian means or displacement variance off");
  EXPECT(ident < 1e-9 * (1.0 + fn[LF_SIG2 * nlag + NLAG]), "sigma2 != variance + mean^2 (%g)",
         ident);
  lagr_widen_check(&g, LG_LEN_1_8, "1.8");
  lagr_widen_check(&g, LG_LEN_1_6, "1.6");
  lagr_free(&g);
}

/* Issue 25: with a varying sampling interval the samples of lag k fall at the first
   statistics sample at or after t0 + k dtau, not on the nominal lag. lag_time_mean (LF_TAU)
   is the mean over the samples of (sample time - release time), computed here from the sample
   times alone, to 1e-12; it lies in [k dtau, k dtau + the largest sampling interval]. The
   particles move along x at fixed speeds u_p = 0.01 p: each sample's interval-mean velocity
   dx / tau is u_p whatever its actual lag, so rate_var_x (LF_RVAR) is the variance of the u_p
   at every lag > 0, to 1e-12, while disp_var_x / lag_time_mean^2 is not (the releases' lags
   differ, and the mean drift turns that into displacement variance). */
static void test_lagr_lag_times(void) {
  enum { NPART = 50, RELEASES = 12, NLAG = 8 };
  /* sampling intervals: with the irrational 1e-3 sqrt(2) no sum of them is a multiple of dtau */
  const double e = 1e-3 * sqrt(2.0), DT[5] = {0.07 + e, 0.11 + e, 0.13 + e, 0.05 + e, 0.09 + e};
  const double horizon = 2.0, dtau = horizon / NLAG, every = 2.5, dtmax = 0.13 + 1e-3 * sqrt(2.0);
  const struct lagr_config cfg = {.n_levels = 1,
                                  .y = {0.5},
                                  .half = 0.05,
                                  .lx = 10.0,
                                  .delta = 1.0,
                                  .horizon = horizon,
                                  .release_every = every,
                                  .n_lags = NLAG,
                                  .pdf_bins = 10};
  struct lagr g;
  lagr_init(&g, &cfg);
  static double x[NPART], y[NPART], z[NPART], u[NPART];
  static int64_t id[NPART];
  for (int p = 0; p < NPART; p++) id[p] = p, y[p] = 0.5, u[p] = 0.01 * p;
  double want[NLAG + 1] = {0}, t = 0.0, t0 = 0.0;
  int r = 0, k = NLAG + 1; /* releases so far, next lag of the current one */
  for (long n = 0; t < RELEASES * every; t += DT[n % 5], n++) {
    if (t >= r * every) { /* a release: the first sample at or after r every, from x = 0 */
      t0 = t, r++, k = 0;
      for (int p = 0; p < NPART; p++) x[p] = 0.0;
    }
    if (k <= NLAG && t >= t0 + k * dtau) want[k++] += (t - t0) / RELEASES;
    const struct stats_snapshot snap = {
        .n = NPART, .x = x, .y = y, .z = z, .u = u, .v = u, .w = u, .id = id, .t = t};
    lagr_sample(&g, &snap);
    for (int p = 0; p < NPART; p++) x[p] += u[p] * DT[n % 5];
  }
  const size_t nlag = NLAG + 1;
  const double var_u = 1e-4 * (NPART * NPART - 1) / 12.0; /* of 0.01 p, p = 0 .. NPART - 1 */
  double fn[LF_LEN * (NLAG + 1)], tl[3], err = 0.0, off = 0.0, rerr = 0.0, naive = 0.0;
  int inside = 1;
  lagr_functions(&g, 0, fn, tl);
  for (size_t j = 0; j < nlag; j++) {
    const double m = fn[LF_TAU * nlag + j], nominal = (double)j * dtau;
    err = fmax(err, fabs(m - want[j]));
    if (j > 0) {
      rerr = fmax(rerr, fabs(fn[LF_RVAR * nlag + j] - var_u));
      naive = fmax(naive, fabs(fn[LF_DVAR * nlag + j] / (m * m) - var_u));
    }
    off = fmax(off, m - nominal);
    inside =
        inside && m >= nominal && m <= nominal + dtmax && fn[LF_N * nlag + j] == NPART * RELEASES;
  }
  printf(
      "Lagrangian lag times (%d releases, sampling intervals 0.05-0.13 s, dtau %g s): "
      "lag_time_mean - mean(t - t0) at most %.3g, largest lag_time_mean - nominal %.4f s\n",
      (int)g.releases, dtau, err, off);
  EXPECT(g.releases == RELEASES && k == NLAG + 1, "releases %g", g.releases);
  EXPECT(err <= 1e-12, "lag_time_mean is not the mean actual lag (%g)", err);
  printf(
      "  rate_var_x - var(u_p) at most %.3g (var %.5g); disp_var_x / lag_time_mean^2 off by up "
      "to %.3g\n",
      rerr, var_u, naive);
  EXPECT(rerr <= 1e-12 && naive > 1e-4, "rate_var_x is not var(dx / tau) (%g, naive %g)", rerr,
         naive);
  EXPECT(inside && off > 0.01, "lag_time_mean outside [nominal, nominal + dt] or on nominal");
  lagr_free(&g);
}

/* Acceptance 1: tracks with a known y-distribution at a station give its PDF and moments. */
static void test_lagr_pdf(void) {
  enum { NPART = 20000, BINS = 50 };
  const double sy = 0.1, dt = 0.0625, X = 0.5;
  const struct lagr_config cfg = {.n_levels = 1,
                                  .y = {0.5},
                                  .x0 = 0.0,
                                  .half = 0.05,
                                  .lx = 10.0,
                                  .delta = 1.0,
                                  .horizon = 1.0,
                                  .release_every = 100.0,
                                  .n_lags = 16,
                                  .n_stations = 1,
                                  .station = {X},
                                  .pdf_bins = BINS};
  struct lagr g;
  lagr_init(&g, &cfg);
  static double x[NPART], y[NPART], z[NPART], u[NPART], g0[NPART];
  static int64_t id[NPART];
  for (int p = 0; p < NPART; p++) id[p] = p, g0[p] = gauss(9000000 + p), u[p] = 1.0;
  for (int n = 0; n <= 16; n++) {
    const double t = n * dt;
    for (int p = 0; p < NPART; p++) /* x = U t, y drifts linearly: N(0.5, sy^2) at x = X */
      x[p] = t, y[p] = 0.5 + sy * g0[p] * t / X, z[p] = 0.0;
    const struct stats_snapshot snap = {
        .n = NPART, .x = x, .y = y, .z = z, .u = u, .v = u, .w = u, .id = id, .t = t};
    lagr_sample(&g, &snap);
  }
  const double *P = g.pdf, n = P[BINS], mu = P[BINS + 1] / n, var = P[BINS + 2] / n - mu * mu;
  const double se_mu = sy / sqrt(n), se_var = sy * sy * sqrt(2.0 / n), width = 2.0 / BINS;
  double worst = 0.0; /* per-bin deviation from the Gaussian in units of its Poisson error */
  for (int b = 0; b < BINS; b++) {
    const double lo = b * width, hi = lo + width;
    const double pexp =
        0.5 * (erf((hi - 0.5) / (sy * sqrt(2.0))) - erf((lo - 0.5) / (sy * sqrt(2.0))));
    if (pexp * n < 5) continue;
    worst = fmax(worst, fabs(P[b] - pexp * n) / sqrt(pexp * n));
  }
  printf(
      "Lagrangian PDF at x - x0 = %g: %.0f tracks, mu_y = %.5f (exact 0.5, %.2f se), "
      "variance %.6f (exact %.6f, %.2f se), largest bin deviation %.2f Poisson errors\n",
      X, n, mu, (mu - 0.5) / se_mu, var, sy * sy, (var - sy * sy) / se_var, worst);
  EXPECT(n == NPART, "tracks crossing the station: %g", n);
  EXPECT(fabs(mu - 0.5) < 3 * se_mu && fabs(var - sy * sy) < 3 * se_var, "PDF moments off");
  EXPECT(worst < 4.5, "PDF histogram off");
  lagr_free(&g);
}

/* SPH interpolation (Eq. 5.56): on a lattice of particle layers, a linear profile is
   reproduced exactly at the profile points at least 2h from the walls (the plane-averaged
   kernel is symmetric), and a constant everywhere. */
static void test_sph_profiles(void) {
  enum { NL = 39, NCOL = 3 };
  const double dr = 0.05, h = 1.3 * dr;
  struct euler_config cfg = config();
  cfg.nb = NL, cfg.y0 = 0.5 * dr, cfg.y1 = 2.0 - 0.5 * dr, cfg.method = EULER_SPH, cfg.h = h;
  cfg.dim = 3;
  struct euler e;
  euler_init(&e, &cfg);
  static double y[NL * NCOL], u[NL * NCOL], v[NL * NCOL], w[NL * NCOL], p[NL * NCOL];
  static double rho[NL * NCOL], m[NL * NCOL];
  for (int j = 0; j < NL; j++)
    for (int k = 0; k < NCOL; k++) {
      const int a = j * NCOL + k;
      y[a] = (j + 1) * dr, u[a] = 0.3 + 2.0 * y[a], v[a] = 0.7, w[a] = 0.0, p[a] = 5.0;
      rho[a] = 1000.0, m[a] = 1000.0 * dr * dr * dr;
    }
  const struct stats_snapshot snap = {.n = NL * NCOL,
                                      .y = y,
                                      .u = u,
                                      .v = v,
                                      .w = w,
                                      .p = p,
                                      .rho = rho,
                                      .m = m,
                                      .t = 0.5,
                                      .wall_fx = {0, 0}};
  euler_sample(&e, &snap);
  struct euler_result r;
  finalise(&e, &r);
  double lin = 0.0, con = 0.0;
  for (int b = 0; b < NL; b++) {
    con = fmax(con, fabs(r.prof[EP_V][b] - 0.7));
    if (r.prof[EP_Y][b] > 2 * h + dr && r.prof[EP_Y][b] < 2.0 - 2 * h - dr)
      lin = fmax(lin, fabs(r.prof[EP_U][b] - (0.3 + 2.0 * r.prof[EP_Y][b])));
  }
  printf(
      "SPH interpolation profiles: linear field error %.2e away from the walls, constant "
      "field error %.2e everywhere\n",
      lin, con);
  EXPECT(lin < 1e-12 && con < 1e-12, "SPH interpolation profiles off");
  euler_result_free(&r);
  euler_free(&e);
}

/* Quadrant analysis: four particles per plane with known fluctuations about the plane mean
   (u' = 1, -2, -0.5, 1.5; v' = 0.5, 1, -0.25, -1.25 about U = 2, V = 0.3), the same set on the
   mirror level (v -> -v), one particle outside the slabs and one skipped: the sums of u'v' and
   the counts of Q1..Q4 over both planes are exact. */
static void test_quad(void) {
  const struct quad_config cfg = {
      .n_levels = 1, .y = {0.3}, .y_plus = {10}, .half = 0.05, .delta = 1.0};
  struct quad q;
  quad_init(&q, &cfg);
  const double up[4] = {1, -2, -0.5, 1.5}, vp[4] = {0.5, 1, -0.25, -1.25};
  double x[10], y[10], z[10], u[10], v[10], w[10];
  uint8_t skip[10] = {0};
  for (int a = 0; a < 8; a++) {
    const int k = a % 4, upper = a >= 4;
    x[a] = 0.1 * a, z[a] = 0.05 * a, w[a] = 0.0, y[a] = upper ? 1.7 : 0.3;
    u[a] = 2.0 + up[k], v[a] = upper ? -(0.3 + vp[k]) : 0.3 + vp[k];
  }
  x[8] = x[9] = z[8] = z[9] = w[8] = w[9] = 0.0, y[8] = 0.5, y[9] = 0.31; /* outside; skipped */
  u[8] = u[9] = v[8] = v[9] = 100.0, skip[9] = 1;
  const struct stats_snapshot snap = {
      .n = 10, .x = x, .y = y, .z = z, .u = u, .v = v, .w = w, .skip = skip, .t = 1.0};
  quad_sample(&q, &snap);
  double worst = fabs(q.samples[0] - 2.0);
  for (int k = 0; k < 4; k++) {
    worst = fmax(worst, fabs(q.acc[QS_UV + k] - 2.0 * up[k] * vp[k]));
    worst = fmax(worst, fabs(q.acc[QS_N + k] - 2.0));
  }
  printf("quadrants: u'v' sums and counts of Q1..Q4 over a level and its mirror: max error %.2e\n",
         worst);
  if (worst > 1e-12) failures++;
  quad_free(&q);
}

/* The momentum budget as an identity (docs/stats-format.md, "The momentum budget"): particles
   that oscillate in y about fixed levels, some within a bin (a layer) and some across its
   edges, with u' correlated with v and the x-force m du/dt put in the pressure part. Without a
   body force, total_stress + momentum_change must vanish in every bin up to the quadrature of
   the sampled times (dt 2e-4, O(dt)); folded, with the last bin holding the centre, and
   unfolded (no particle crossing the centre, through which the unfolded budget takes no
   flux). The edge mean alone, without the bins' first moments and the advective part, misses
   it by 0.21 and 0.036 (largest terms 0.30 and 0.07; measured when this test was written). */
static void test_budget_identity(void) {
  enum { NPB = 600, NBB = 8 };
  const double dt = 2e-4, T = 0.8;
  for (int fold = 0; fold <= 1; fold++) {
    struct euler_config cfg = config();
    cfg.nb = NBB, cfg.fold = fold, cfg.window = T / 4;
    cfg.y1 = fold ? 1.0 + 0.5 / (NBB - 0.5) : 2.0; /* folded: the last bin is centred on delta */
    struct euler e;
    euler_init(&e, &cfg);
    static double y[NPB], u[NPB], v[NPB], w[NPB], p[NPB], rho[NPB], m[NPB], sx[NPB * STATS_ACC];
    for (long s = 0; s * dt <= T + 1e-12; s++) {
      const double t = s * dt;
      for (int a = 0; a < NPB; a++) {
        /* unfolded, no particle crosses the centre: the budget takes no flux through it */
        double y0 = 0.02 + 1.96 * uniform(10 * a + 1);
        if (!fold && fabs(y0 - 1.0) < 0.07) y0 += y0 < 1.0 ? -0.07 : 0.07;
        const double amp = 0.005 + 0.06 * uniform(10 * a + 2);
        const double om = 20.0 + 30.0 * uniform(10 * a + 3), ph = 6.283 * uniform(10 * a + 4);
        const double ub = 1.0 + 2.0 * y0, du = 0.5 + uniform(10 * a + 5), lag = 0.4;
        y[a] = y0 + amp * sin(om * t + ph), v[a] = amp * om * cos(om * t + ph);
        u[a] = ub - du * sin(om * t + ph - lag); /* u' anti-correlated with v */
        for (int k = 0; k < STATS_ACC; k++) sx[a * STATS_ACC + k] = 0.0;
        sx[a * STATS_ACC] = -du * om * cos(om * t + ph - lag);
        w[a] = 0.0, p[a] = 0.0, rho[a] = 1000.0, m[a] = 2.0;
      }
      const struct stats_snapshot snap = {.n = NPB,
                                          .y = y,
                                          .u = u,
                                          .v = v,
                                          .w = w,
                                          .p = p,
                                          .rho = rho,
                                          .m = m,
                                          .sx = sx,
                                          .t = t,
                                          .fx = 0.0,
                                          .wall_fx = {0.0, 0.0}};
      euler_sample(&e, &snap);
    }
    struct euler_result r;
    finalise(&e, &r);
    double worst = 0.0, scale = 0.0, edge = 0.0;
    for (int b = 0; b < NBB; b++) {
      const double close =
          r.prof[EP_TOTAL][b] + r.prof[EP_TAU_INERTIA][b] - r.prof[EP_TOTAL_EXPECTED][b];
      worst = fmax(worst, fabs(close));
      for (int k = EP_TAU_REYNOLDS; k <= EP_TAU_INERTIA; k++)
        scale = fmax(scale, fabs(r.prof[k][b]));
      edge = fmax(edge, fabs(r.prof[EP_TAU_ADVECT][b]));
    }
    printf(
        "budget identity (%s): max |total + momentum_change - expected| %.2e, largest "
        "term %.3f, advective %.3f\n",
        fold ? "folded" : "unfolded", worst, scale, edge);
    EXPECT(scale > 0.05 && worst <= 5e-3 * scale, "budget identity (fold %d): closure %.3g", fold,
           worst);
    euler_result_free(&r);
    euler_free(&e);
  }
}

/* The Reynolds-stress budget on a hand-computed case (docs/theory.md, "Reynolds-stress
   budgets"): two particles of mass 1 at rest in y in bin 0, u = (1, 3) at t = 1, then after a
   step dt = 0.1 with pressure accelerations (2, -1) u = (1.2, 2.9) at t = 1.1. U = the mean of
   the four samples, 2.025; the range leaves out the first sample, so the pressure term of uu
   is (2 sum (ub - U) A) / M with ub = u - dt A / 2 = (1.1, 2.95): (2 (-0.75) - 2 U) / 2 =
   -2.775, and the rate is ((1.2 - U)^2 + (2.9 - U)^2 - (1 - U)^2 - (3 - U)^2) / 0.1 / 2 =
   -2.775: the closure is zero, nothing else acts. */
static void test_rs_budget_known(void) {
  struct euler_config cfg = config();
  cfg.nb = 2, cfg.fold = 0, cfg.window = 10.0, cfg.y0 = 0.0, cfg.y1 = 2.0;
  struct euler e;
  euler_init(&e, &cfg);
  double y[2] = {0.5, 0.5}, v[2] = {0, 0}, w[2] = {0, 0}, p[2] = {0, 0}, rho[2] = {1, 1};
  double m[2] = {1, 1}, sx[2 * STATS_ACC] = {0};
  double u1[2] = {1.0, 3.0}, u2[2] = {1.2, 2.9};
  struct stats_snapshot snap = {.n = 2,
                                .y = y,
                                .u = u1,
                                .v = v,
                                .w = w,
                                .p = p,
                                .rho = rho,
                                .m = m,
                                .sx = sx,
                                .t = 1.0,
                                .dt = 0.1,
                                .wall_fx = {0.0, 0.0}};
  euler_sample(&e, &snap);
  sx[0] = 2.0, sx[STATS_ACC] = -1.0; /* x pressure parts */
  snap.u = u2, snap.t = 1.1;
  euler_sample(&e, &snap);
  struct euler_result r;
  finalise(&e, &r);
  const double *pr = r.prof[EP_RSB + RS_UU * RS_NTERM + RT_PRESSURE];
  const double *rate = r.prof[EP_RSB + RS_UU * RS_NTERM + RT_RATE];
  const double *cl = r.prof[EP_RSB + RS_UU * RS_NTERM + RT_CLOSURE];
  const double *vv = r.prof[EP_RSB + RS_VV * RS_NTERM + RT_PRESSURE];
  const double *k = r.prof[EP_RSB + RS_K * RS_NTERM + RT_PRESSURE];
  printf(
      "Reynolds-stress budget, known case: uu pressure %.12g rate %.12g closure %.3g "
      "(expected -2.775, -2.775, 0); vv %.3g, k %.12g\n",
      pr[0], rate[0], cl[0], vv[0], k[0]);
  EXPECT(r.rs_budget && fabs(pr[0] + 2.775) < 1e-12 && fabs(rate[0] + 2.775) < 1e-12 &&
             fabs(cl[0]) < 1e-12 && vv[0] == 0.0 && fabs(k[0] + 1.3875) < 1e-12,
         "Reynolds-stress budget of the known case");
  EXPECT(isnan(pr[1]), "an empty bin has no budget");
  euler_result_free(&r);
  euler_free(&e);
}

int main(void) {
  double *buf = malloc(6 * NP * sizeof(double));
  test_known_field(buf);
  test_merge();
  test_round_trip(buf);
  test_corr();
  test_corr_gaps();
  test_corr_windows();
  test_quad();
  test_budget_identity();
  test_rs_budget_known();
  test_sph_profiles();
  test_lagr_ou();
  test_lagr_drift();
  test_lagr_lag_times();
  test_lagr_pdf();
  free(buf);
  printf(failures ? "FAILED (%d)\n" : "all passed\n", failures);
  return failures ? 1 : 0;
}
