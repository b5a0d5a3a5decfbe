/*
 * test_init: the synthetic-eddy start-up (init.profile = synthetic, solver/init.c; Jarrin et
 * al. 2006) at Re_tau = 180 in a 6.4 x 2 x 3.2 delta box (dr+ = 9, 319 488 particles, 6 144
 * eddies of size 0.2 delta): statistics over the particles binned in y (both halves, u'v'
 * mirrored) against the Lee & Moser table it was built from.
 *   - mean U within 3% of the DNS in the log layer (30 < y+ < 100);
 *   - u'u', v'v', w'w', -u'v' averaged over 20 < y+ < 100 (ratio to the DNS) within 4 standard
 *     errors + 1% of 1; the standard error is from the spread over 64 blocks (8 along x, two
 *     halves, 4 independent eddy sets, init.seed = 7-10): the sample is a finite number of
 *     eddies, not of particles; the expectation is the table exactly (the reference is the
 *     same interpolation at the same y), the 1% is for the estimate of the standard error;
 *   - -u'v' / (u_rms v_rms) in 20 < y+ < 100 between 0.35 and 0.55 (DNS about 0.45);
 *   - the cell search of the eddies equals a sum over all eddies (3000 points, default count
 *     and 40 eddies);
 *   - exactly zero velocity at the walls (y = 0, y = 2 delta);
 *   - bitwise identical velocities with 1 and 2 threads.
 */
#include <math.h>
#include <mpi.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "init.h"
#include "part.h"

enum { NS = 4, NB = 16 * NS, NL = 20 }; /* eddy sets (seeds), blocks, layers per half */

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  char *set[] = {"domain.dimension=3",     "domain.delta=1", "domain.lx=6.4",
                 "domain.lz=3.2",          "domain.dr=0.05", "fluid.nu=0.005555555555555556",
                 "fluid.c0=200",           "drive.force=1",  "time.t_end=1",
                 "init.profile=synthetic", "init.seed=7"};
  struct scene sc;
  if (scene_load(&sc, NULL, (int)(sizeof set / sizeof *set), set)) return 1;
  struct particles P;
  struct walls W;
  part_create(&P, &W, &sc);
  const size_t n = P.n_fluid;
  int fail = 0;

  /* threads: 1 and 2, bitwise */
  omp_set_num_threads(1);
  if (init_fields(&sc, &P, NULL)) return 1;
  double *ref = malloc(3 * n * sizeof(double));
  memcpy(ref, P.u, n * sizeof(double)), memcpy(ref + n, P.v, n * sizeof(double));
  memcpy(ref + 2 * n, P.w, n * sizeof(double));
  omp_set_num_threads(2);
  if (init_fields(&sc, &P, NULL)) return 1;
  const int same = !memcmp(ref, P.u, n * sizeof(double)) &&
                   !memcmp(ref + n, P.v, n * sizeof(double)) &&
                   !memcmp(ref + 2 * n, P.w, n * sizeof(double));
  printf("threads: 1 and 2 threads %s\n", same ? "bitwise identical" : "DIFFER");
  fail |= !same;

  const double ut = sqrt(sc.force * sc.delta), nu = sc.nu, dr = sc.dr;
  /* per eddy set: layer means (both halves), then moments about them per block (8 along x,
     2 halves); the NS eddy sets (seeds 7 ..) are independent samples */
  static double sum[NS][NL][4], cnt[NL], mom[NL][NB][5], bcnt[NL][NB];
  for (int e = 0; e < NS; e++) {
    sc.init_seed = 7 + e;
    if (e > 0 && init_fields(&sc, &P, NULL)) return 1;
    for (size_t a = 0; a < n; a++) {
      const int up = P.y[a] > sc.delta;
      const int l = (int)lround((up ? 2.0 * sc.delta - P.y[a] : P.y[a]) / dr) - 1;
      const double vel[3] = {P.u[a], P.v[a], P.w[a]};
      for (int c = 0; c < 3; c++) sum[e][l][c] += vel[c];
      if (e == 0) cnt[l] += 1.0;
    }
    for (size_t a = 0; a < n; a++) {
      const int up = P.y[a] > sc.delta;
      const int l = (int)lround((up ? 2.0 * sc.delta - P.y[a] : P.y[a]) / dr) - 1;
      const int b = 16 * e + up * 8 + (int)fmin(7, floor(P.x[a] / sc.lx * 8));
      const double du = P.u[a] - sum[e][l][0] / cnt[l], dv = P.v[a] - sum[e][l][1] / cnt[l];
      const double dw = P.w[a] - sum[e][l][2] / cnt[l];
      mom[l][b][0] += du * du, mom[l][b][1] += dv * dv, mom[l][b][2] += dw * dw;
      mom[l][b][3] += (up ? -1.0 : 1.0) * du * dv; /* mirrored: u'v' of the lower half */
      bcnt[l][b] += 1.0;
    }
  }
  printf("%zu particles, %d eddy sets (seeds 7-%d), eddies: count %ld (0 = auto), size %g delta\n",
         n, NS, 6 + NS, sc.init_eddies, sc.init_eddy_size);
  printf("  y+     U+ (DNS)        u_rms+ (DNS)   v_rms+ (DNS)   w_rms+ (DNS)   -u'v'+ (DNS)\n");
  double band[NB][4] = {{0}}, rho_sum = 0.0, rho_dns = 0.0, umax = 0.0;
  int nband = 0;
  for (int l = 0; l < NL; l++) {
    const double yp = (l + 1) * dr * ut / nu; /* layers at y = dr, 2 dr, ... */
    double d[5], s[4] = {0};
    init_dns180(yp, d);
    for (int b = 0; b < NB; b++)
      for (int c = 0; c < 4; c++) s[c] += mom[l][b][c];
    for (int c = 0; c < 4; c++) s[c] /= NS * cnt[l] * ut * ut;
    double U = 0.0;
    for (int e = 0; e < NS; e++) U += sum[e][l][0] / (NS * cnt[l] * ut);
    printf("%6.1f %6.2f (%6.2f)  %5.3f (%5.3f)  %5.3f (%5.3f)  %5.3f (%5.3f)  %6.3f (%6.3f)\n", yp,
           U, d[0], sqrt(s[0]), sqrt(d[1]), sqrt(s[1]), sqrt(d[2]), sqrt(s[2]), sqrt(d[3]), -s[3],
           -d[4]);
    if (yp > 30.0 && yp < 100.0) umax = fmax(umax, fabs(U / d[0] - 1.0));
    if (yp > 20.0 && yp < 100.0) {
      nband++;
      rho_sum += -s[3] / sqrt(s[0] * s[1]);
      rho_dns += -d[4] / sqrt(d[1] * d[2]);
      const double want[4] = {d[1], d[2], d[3], d[4]};
      for (int b = 0; b < NB; b++)
        for (int c = 0; c < 4; c++) band[b][c] += mom[l][b][c] / (bcnt[l][b] * ut * ut) / want[c];
    }
  }
  printf("mean U in 30 < y+ < 100: largest deviation from the DNS %.2f%% (tol 3%%)\n", 100 * umax);
  fail |= !(umax < 0.03);
  static const char *const nm[4] = {"u'u'", "v'v'", "w'w'", "-u'v'"};
  printf("20 < y+ < 100 (%d layers per half, %d blocks):\n", nband, NB);
  for (int c = 0; c < 4; c++) {
    double m = 0.0, q = 0.0;
    for (int b = 0; b < NB; b++) m += band[b][c] / nband;
    m /= NB;
    for (int b = 0; b < NB; b++) q += pow(band[b][c] / nband - m, 2);
    const double se = sqrt(q / (NB - 1) / NB), tol = 4.0 * se + 0.01;
    const int ok = fabs(m - 1.0) <= tol;
    printf("  %-5s / DNS = %.4f +- %.4f (standard error), |ratio - 1| tol %.4f: %s\n", nm[c], m, se,
           tol, ok ? "ok" : "FAIL");
    fail |= !ok;
  }
  const double rho = rho_sum / nband;
  printf("  -u'v'/(u_rms v_rms) = %.3f (DNS %.3f), want 0.35-0.55\n", rho, rho_dns / nband);
  fail |= !(rho > 0.35 && rho < 0.55);

  /* the cell search against a sum over all eddies, at the default count (cells of width
     sigma) and at 40 eddies (wider cells) */
  double brute = 0.0;
  for (int pass = 0; pass < 2; pass++) {
    sc.init_eddies = pass ? 40 : 0;
    struct init_sem B;
    init_sem_make(&B, &sc);
    for (int k = 0; k < 3000; k++) {
      const double x = sc.lx * (init_noise(5, k, 0) + 1) / 2 - 1.0, y = (init_noise(5, k, 1) + 1);
      const double z = sc.lz * (init_noise(5, k, 2) + 1) / 2 + 2.0, f = 1.5 * sqrt(1.5);
      double xi[3], want[3] = {0, 0, 0};
      init_sem_xi(&B, x, y, z, xi);
      for (size_t e = 0; e < B.n; e++) {
        double dx = x - B.pos[3 * e], dz = z - B.pos[3 * e + 2];
        dx -= sc.lx * floor(dx / sc.lx + 0.5), dz -= sc.lz * floor(dz / sc.lz + 0.5);
        const double ax = fabs(dx) / B.sigma, ay = fabs(y - B.pos[3 * e + 1]) / B.sigma;
        const double az = fabs(dz) / B.sigma;
        if (ax < 1 && ay < 1 && az < 1)
          for (int c = 0; c < 3; c++)
            want[c] += B.eps[3 * e + c] * f * (1 - ax) * (1 - ay) * (1 - az) * B.scale;
      }
      for (int c = 0; c < 3; c++) brute = fmax(brute, fabs(xi[c] - want[c]));
    }
    printf(
        "cell search (%zu eddies, %d x %d x %d cells) against all eddies: max |difference| "
        "%.2e (tol 1e-12)\n",
        B.n, B.nx, B.ny, B.nz, brute);
    init_sem_free(&B);
  }
  fail |= !(brute < 1e-12);
  sc.init_eddies = 0;

  /* walls: exactly zero */
  struct init_sem E;
  init_sem_make(&E, &sc);
  double wmax = 0.0;
  for (int k = 0; k < 2000; k++) {
    const double x = sc.lx * (init_noise(3, k, 0) + 1) / 2,
                 z = sc.lz * (init_noise(3, k, 1) + 1) / 2;
    double v0[3], v1[3];
    init_sem_velocity(&E, &sc, ut, x, 0.0, z, v0);
    init_sem_velocity(&E, &sc, ut, x, 2.0 * sc.delta, z, v1);
    for (int c = 0; c < 3; c++) wmax = fmax(wmax, fmax(fabs(v0[c]), fabs(v1[c])));
  }
  printf("walls: %zu eddies, largest |velocity| at y = 0 and 2 delta over 2000 points: %g\n", E.n,
         wmax);
  fail |= !(wmax == 0.0);
  init_sem_free(&E);
  free(ref);
  part_destroy(&P, &W);
  printf("%s\n", fail ? "FAIL" : "ok");
  MPI_Finalize();
  return fail;
}
