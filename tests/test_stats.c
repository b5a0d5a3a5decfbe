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
#include "moments.h"
#include "state.h"
#include "stats.h"

static int failures = 0;

#define EXPECT(cond, ...)           \
  do {                              \
    if (!(cond)) {                  \
      printf("FAIL: " __VA_ARGS__); \
      printf("\n");                 \
      failures++;                   \
    }                               \
  } while (0)

/* Counter-based generator (splitmix64 of a key): reproducible, no hidden state. */
static uint64_t mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
static double uniform(uint64_t key) {
  return ((double)(mix(key) >> 11) + 0.5) / 9007199254740992.0;
}
static double gauss(uint64_t key) { /* Box-Muller */
  return sqrt(-2.0 * log(uniform(2 * key))) * cos(6.283185307179586 * uniform(2 * key + 1));
}

enum { NB = 8, NP = 4000, NSNAP = 400 };
static const double A = 0.3, B = -0.2, C = 0.25, SW = 0.15; /* u' = A g1, v' = B g1 + C g2 */

static double U_of_bin(int b) {
  return 1.0 + 0.1 * b;
}

/* Snapshot s of the synthetic field: y uniform in (0, 2), bins of width 0.25. */
static void make_snapshot(long s, double *y, double *u, double *v, double *w, double *p,
                          double *rho) {
  for (size_t a = 0; a < NP; a++) {
    const uint64_t k = ((uint64_t)s * NP + a) * 8;
    y[a] = 2.0 * uniform(k);
    const int b = (int)floor(y[a] / 0.25);
    const double g1 = gauss(k + 1), g2 = gauss(k + 2), g3 = gauss(k + 3);
    u[a] = U_of_bin(b) + A * g1;
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
                                        .wall_fx = {-1.0, -1.0}};
    euler_sample(e, &snap);
  }
}

static void finalise(const struct euler *e, struct euler_result *r) {
  const size_t rows = euler_rows(e);
  int *complete = calloc(rows, sizeof *complete);
  for (size_t i = 0; i < rows; i++) complete[i] = i < e->nwin;
  euler_finalise(&e->cfg, e->win, e->mom, e->snp, complete, 0, rows, r);
  free(complete);
}

/* Acceptance 1: means and stresses of a field with known answers within 3 standard errors. */
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
    for (int c = 0; c < 6; c++) {
      const double z = (r.prof[EP_UU + c][b] - exact[c]) / r.prof[EP_SE_U + 5 + c][b];
      worst = fmax(worst, fabs(z));
      EXPECT(fabs(z) < 3, "bin %d stress %d: %.6f exact %.6f se %.2e", b, c, r.prof[EP_UU + c][b],
             exact[c], r.prof[EP_SE_U + 5 + c][b]);
    }
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
      const double e = scale > 0 ? fabs(ref[k] - m[k]) / scale : 0.0;
      worst = fmax(worst, e);
      EXPECT(e < 1e-14, "split %d slot %d: %.17g vs %.17g", split, k, ref[k], m[k]);
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
  char name[32][96];
  int rank[32];
  size_t dims[32][STATE_MAX_RANK];
  double *data[32];
};

static void save(struct state_list *L, struct saved *sv) {
  sv->n = L->n;
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

/* Acceptance 3 (engine side): serialise -> restore in a fresh engine -> continue gives the
   same raw state and results bit for bit as never stopping. */
static void test_round_trip(double *buf) {
  const struct euler_config cfg = config();
  struct euler a, b, c;
  euler_init(&a, &cfg);
  feed(&a, 0, 137, buf);
  euler_init(&b, &cfg);
  feed(&b, 0, 61, buf);
  struct state_list L = {0};
  struct stats sb = {.cfg = {.eulerian = 1}, .eu = b};
  stats_state(&sb, &L);
  struct saved sv;
  save(&L, &sv);
  state_free(&L);
  euler_free(&sb.eu);
  euler_init(&c, &cfg);
  struct stats sc = {.cfg = {.eulerian = 1}, .eu = c};
  stats_state(&sc, &L);
  restore(&L, &sv);
  state_free(&L);
  feed(&sc.eu, 61, 137, buf);
  const size_t nb = NB;
  EXPECT(sc.eu.nwin == a.nwin, "windows %zu vs %zu", sc.eu.nwin, a.nwin);
  const size_t rows = a.nwin + 1;
  const int same = sc.eu.nwin == a.nwin &&
                   !memcmp(sc.eu.win, a.win, rows * WIN_LEN * sizeof(double)) &&
                   !memcmp(sc.eu.mom, a.mom, rows * nb * MOM_LEN * sizeof(double)) &&
                   !memcmp(sc.eu.snp, a.snp, rows * nb * SCAL_LEN * sizeof(double));
  EXPECT(same, "state after a round trip differs from the uninterrupted run");
  printf("state round trip after 61 of 137 snapshots (%d fields): %s\n", sv.n,
         same ? "bitwise identical" : "DIFFERENT");
  for (int i = 0; i < sv.n; i++) free(sv.data[i]);
  euler_free(&sc.eu);
  euler_free(&a);
}

/* Acceptance 1: a field with a known sinusoidal correlation gives R(l) to 1e-6. */
static void test_corr(void) {
  enum { NX = 16, NZ = 8, M = 3, NM = 1 };
  const double lx = 1.6, lz = 0.8, amp_a = 0.7, amp_b = 0.4, amp_c = 0.3, amp_d = 0.2;
  const double phi = 0.4, tp = 6.283185307179586;
  const struct corr_config cfg = {.n_levels = 1,
                                  .y = {0.3},
                                  .y_plus = {10},
                                  .nx = NX,
                                  .nz = NZ,
                                  .lx = lx,
                                  .lz = lz,
                                  .half = 0.05,
                                  .delta = 1.0};
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

int main(void) {
  double *buf = malloc(6 * NP * sizeof(double));
  test_known_field(buf);
  test_merge();
  test_round_trip(buf);
  test_corr();
  free(buf);
  printf(failures ? "FAILED (%d)\n" : "all passed\n", failures);
  return failures ? 1 : 0;
}
