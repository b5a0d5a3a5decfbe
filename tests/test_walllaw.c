/*
 * test_walllaw.c: unit test of the wall-law solver of solver/walllaw.h (thesis Eq. 2.146,
 * 5.51, 5.53).
 *
 * For the laminar, log and Reichardt laws, over a grid spanning y+ from 1e-6 to 1e6, speeds
 * from 1e-8 to 1e8 m/s and viscosities from 1e-8 to 10 m^2/s (U is chosen to give the target
 * y+, so every grid point is a genuine case):
 *  - the relative residual |U / u_tau - f(y+)| / f(y+) is at most 1e-12 and u_tau is finite;
 *  - u_tau recovers the u_tau the case was built from to 1e-12 relative;
 *  - U = 0 gives u_tau = 0 exactly.
 * Also: Reichardt's law has U+ = y+ to first order at the wall and tends to
 * ln(y+)/kappa + ln(kappa)/kappa + 7.8 far from it; the log law is continuous at its crossing
 * point (y+ about 11 for kappa = 0.41, B = 5.2). Reichardt's law rises up to 1.5% above y+ in
 * the buffer layer, so the solver's first bracket [sqrt(R), R/f(sqrt(R))] can miss the root;
 * the grid above covers that range and proves the widened bracket.
 */
#include <math.h>
#include <stdio.h>

#include "walllaw.h"

int main(void) {
  int fail = 0;
  static const char *const names[3] = {"laminar", "log", "reichardt"};
  for (int law = 0; law < 3; law++) {
    const struct wall_law_def L = wall_law_make(law, 0.41, 5.2);
    double worst_res = 0.0, worst_ut = 0.0;
    long cases = 0;
    for (double yp = 1e-6; yp <= 1e6 * 1.0001; yp *= pow(10.0, 0.125))
      for (double nu = 1e-8; nu <= 10.0 * 1.0001; nu *= 10.0)
        for (double ut = 1e-6; ut <= 1e6 * 1.0001; ut *= 100.0) {
          const double y = yp * nu / ut;                /* distance giving this y+ */
          const double U = ut * wall_law_uplus(&L, yp); /* speed of this u_tau */
          if (!(y > 0.0) || !isfinite(y) || !(U > 0.0) || !isfinite(U)) continue;
          const double got = wall_law_utau(&L, U, y, nu);
          cases++;
          if (!isfinite(got) || !(got > 0.0)) {
            printf("FAIL %s: u_tau = %g for U = %g y = %g nu = %g\n", names[law], got, U, y, nu);
            fail = 1;
            continue;
          }
          const double f = wall_law_uplus(&L, y * got / nu);
          const double res = fabs(U / got - f) / f;
          const double eut = fabs(got - ut) / ut;
          if (res > worst_res) worst_res = res;
          if (eut > worst_ut) worst_ut = eut;
        }
    const double zero = wall_law_utau(&L, 0.0, 0.01, 1e-3);
    printf("%-9s: %ld cases, max relative residual %.2e, max u_tau error %.2e, U=0 -> %g\n",
           names[law], cases, worst_res, worst_ut, zero);
    if (worst_res > 1e-12 || worst_ut > 1e-12 || zero != 0.0) fail = 1;
  }
  const struct wall_law_def R = wall_law_make(WALL_LAW_REICHARDT, 0.41, 5.2);
  double above = 0.0;
  for (double yp = 1e-8; yp < 1e8; yp *= 1.01) {
    const double d = wall_law_uplus(&R, yp) - yp;
    if (d > above * yp) above = d / yp;
  }
  const double slope0 = wall_law_uplus(&R, 1e-7) / 1e-7;
  const double far = wall_law_uplus(&R, 1e7) - log(1e7) / 0.41;
  printf("reichardt: slope at the wall %.9f, outer intercept %.4f, max (f - y+)/y+ %.2e\n", slope0,
         far, above);
  if (fabs(slope0 - 1.0) > 1e-6 || fabs(far - (log(0.41) / 0.41 + 7.8)) > 1e-3) fail = 1;
  const struct wall_law_def G = wall_law_make(WALL_LAW_LOG, 0.41, 5.2);
  const double jump = fabs(log(G.y_c) / 0.41 + 5.2 - G.y_c);
  printf("log: crossing y+ = %.6f, mismatch %.1e\n", G.y_c, jump);
  if (jump > 1e-12 || G.y_c < 10.0 || G.y_c > 12.0) fail = 1;
  printf(fail ? "FAILED\n" : "PASSED\n");
  return fail;
}
