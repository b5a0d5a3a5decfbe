/** @file walllaw.c @brief Implementation of walllaw.h. */
#include "walllaw.h"

#include <math.h>

/** Reichardt's law without the "+ 1" of thesis Eq. 5.53, which would give U+ = 1 at the wall
    and an outer intercept of 6.6 instead of 5.6 (docs/theory.md). */
static double reichardt(double k, double yp) {
  return log1p(k * yp) / k + 7.8 * (1.0 - exp(-yp / 11.0) - yp / 11.0 * exp(-yp / 3.0));
}

static double reichardt_d(double k, double yp) {
  return 1.0 / (1.0 + k * yp) +
         7.8 * (exp(-yp / 11.0) / 11.0 - exp(-yp / 3.0) / 11.0 + yp / 33.0 * exp(-yp / 3.0));
}

struct wall_law_def wall_law_make(int law, double kappa, double b) {
  struct wall_law_def L = {law, kappa, b, 0.0};
  /* crossing of the linear and log laws: y = ln(y)/kappa + B, the root above 1 */
  double y = 11.0;
  for (int i = 0; i < 100; i++) {
    const double g = y - log(y) / kappa - b, dg = 1.0 - 1.0 / (kappa * y);
    const double dy = g / dg;
    y -= dy;
    if (y < 1.0) y = 1.0 + 1e-9;
    if (fabs(dy) < 1e-15 * y) break;
  }
  L.y_c = y;
  return L;
}

double wall_law_uplus(const struct wall_law_def *L, double yp) {
  switch (L->law) {
    case WALL_LAW_LOG:
      return yp < L->y_c ? yp : log(yp) / L->kappa + L->b;
    case WALL_LAW_REICHARDT:
      return reichardt(L->kappa, yp);
    default:
      return yp;
  }
}

/** d f / d y+ */
static double uplus_d(const struct wall_law_def *L, double yp) {
  switch (L->law) {
    case WALL_LAW_LOG:
      return yp < L->y_c ? 1.0 : 1.0 / (L->kappa * yp);
    case WALL_LAW_REICHARDT:
      return reichardt_d(L->kappa, yp);
    default:
      return 1.0;
  }
}

double wall_law_utau(const struct wall_law_def *L, double U, double y, double nu) {
  if (!(U > 0.0)) return 0.0;
  const double R = U * y / nu; /* = y+ U+ */
  const double lo0 = sqrt(R);  /* laminar root: f(y+) <= y+ */
  if (L->law == WALL_LAW_LAMINAR) return lo0 * nu / y;
  /* bracket [lo, hi] of the root of phi(Y) = Y f(Y) - R: f(Y) <= Y and f increasing give
     [sqrt(R), R / f(sqrt(R))]; widened if rounding (or a law with f > y+ somewhere) breaks it */
  double lo = lo0, hi = lo0 * 2.0;
  const double flo = wall_law_uplus(L, lo0);
  if (flo > 0.0 && R / flo > hi) hi = R / flo;
  while (lo * wall_law_uplus(L, lo) - R > 0.0) lo *= 0.5;
  while (hi * wall_law_uplus(L, hi) - R < 0.0) hi *= 2.0;
  double Y;
  /* Newton from the upper end (phi is concave there for the log part), kept in the bracket */
  Y = hi;
  for (int it = 0; it < 200; it++) {
    const double f = wall_law_uplus(L, Y), phi = Y * f - R;
    if (phi == 0.0) break;
    if (phi > 0.0)
      hi = Y;
    else
      lo = Y;
    const double dphi = f + Y * uplus_d(L, Y);
    double Yn = Y - phi / dphi;
    if (!(Yn > lo && Yn < hi)) Yn = 0.5 * (lo + hi); /* bisection fallback */
    if (fabs(Yn - Y) <= 1e-15 * Y || hi - lo <= 2e-16 * hi) {
      Y = Yn;
      break;
    }
    Y = Yn;
  }
  return Y * nu / y;
}
