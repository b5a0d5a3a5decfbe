/**
 * @file walllaw.h
 * @brief Wall laws for the wall shear term: the friction velocity u_tau of a particle at
 *        distance y from a wall, moving parallel to it with speed U.
 *
 * Every law is written as U+ = f(y+), U+ = U / u_tau, y+ = y u_tau / nu, and solved in the
 * single variable y+ from  y+ f(y+) = R,  R = U y / nu  (docs/theory.md, "Wall laws"):
 * y+ f(y+) grows monotonically from 0 to infinity, so the root is unique. Where f(y+) <= y+
 * (laminar, log) it lies in [sqrt(R), R / f(sqrt(R))]; Reichardt's law exceeds y+ by up to
 * 1.5% in the buffer layer, so the bracket is widened by halving/doubling until it holds. A
 * Newton iteration safeguarded by bisection on the bracket always converges. U = 0 gives
 * u_tau = 0.
 */
#ifndef CHANSPH_WALLLAW_H
#define CHANSPH_WALLLAW_H

enum wall_law {
  WALL_LAW_LAMINAR = 0,  /*!< U+ = y+ (thesis Eq. 2.146, Ferrand Eq. 37) */
  WALL_LAW_LOG = 1,      /*!< U+ = ln(y+)/kappa + B above the crossing with U+ = y+ (Eq. 5.51),
                              U+ = y+ below it */
  WALL_LAW_REICHARDT = 2 /*!< Reichardt's law (Eq. 5.53 without the misprinted "+ 1") */
};

/** A wall law and its constants. */
struct wall_law_def {
  int law;      /*!< enum wall_law */
  double kappa; /*!< von Karman constant [-] (thesis Eq. 5.33: 0.41) */
  double b;     /*!< log-law intercept B [-] (5.2) */
  double y_c;   /*!< log law: the y+ where ln(y+)/kappa + B = y+ (set by wall_law_make) */
};

/** @brief A wall law with its crossing point computed. */
struct wall_law_def wall_law_make(int law, double kappa, double b);

/** @brief U+ = f(y+) of the law. */
double wall_law_uplus(const struct wall_law_def *L, double yplus);

/**
 * @brief Friction velocity from the law.
 * @param L law
 * @param U speed parallel to the wall [m/s], >= 0
 * @param y distance to the wall [m], > 0
 * @param nu kinematic viscosity [m^2/s], > 0
 * @return u_tau [m/s] >= 0; finite for any finite inputs
 */
double wall_law_utau(const struct wall_law_def *L, double U, double y, double nu);

#endif
