/**
 * @file eos.h
 * @brief Tait equation of state and the local speed of sound.
 */
#ifndef CHANSPH_EOS_H
#define CHANSPH_EOS_H

#include <math.h>

/** Equation-of-state constants. */
struct eos {
  double rho0; /*!< reference density [kg/m^3] */
  double c0;   /*!< numerical speed of sound [m/s] */
  double zeta; /*!< Tait exponent [-] (7) */
  double pb;   /*!< background pressure [Pa] */
};

/** Integer power for the common exponents, exact and fast; pow() otherwise. */
static inline double eos_ipow(const double x, const double e) {
  if (e == 7.0) {
    const double x2 = x * x;
    return x2 * x2 * x2 * x;
  }
  if (e == 3.0) return x * x * x;
  return pow(x, e);
}

/**
 * @brief Pressure p = rho0 c0^2 / zeta ((rho/rho0)^zeta - 1) + p_b.
 * @param[in] e constants
 * @param[in] rho density [kg/m^3]
 * @return pressure [Pa]. Implements: thesis Eq. 2.11.
 */
static inline double eos_pressure(const struct eos *e, const double rho) {
  return e->rho0 * e->c0 * e->c0 / e->zeta * (eos_ipow(rho / e->rho0, e->zeta) - 1.0) + e->pb;
}

/**
 * @brief Local speed of sound c = c0 (rho/rho0)^((zeta-1)/2).
 * @param[in] e constants
 * @param[in] rho density [kg/m^3]
 * @return c [m/s]. Implements: thesis Eq. 3.31/3.33.
 */
static inline double eos_sound(const struct eos *e, const double rho) {
  return e->c0 * eos_ipow(rho / e->rho0, 0.5 * (e->zeta - 1.0));
}

#endif
