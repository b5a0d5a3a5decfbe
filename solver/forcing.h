/**
 * @file forcing.h
 * @brief Driving the channel: constant body force (thesis Eq. 5.14) or a controlled volume
 *        flux (thesis Eq. 3.43, generalised to a variable time step by Eq. 3.42; or Eq. 3.38).
 */
#ifndef CHANSPH_FORCING_H
#define CHANSPH_FORCING_H

#include "scene.h"

/** State of the driver; everything the next force depends on. */
struct drive {
  int mode;       /*!< enum drive_mode */
  int controller; /*!< enum flux_controller */
  double target;  /*!< target bulk velocity v [m/s] (flux mode) */
  double force;   /*!< force of the last step, F^(n-1) [m/s^2] */
  double ub_prev; /*!< bulk velocity one step earlier, v~^(n-2) [m/s] */
  double dt_prev; /*!< previous time step dt^(n-1) [s] */
  int started;    /*!< 0 until the first step has been taken */
};

/** @brief Initialise the driver from the scene (force = drive.force). */
void drive_init(struct drive *d, const struct scene *s);

/**
 * @brief Streamwise body acceleration for the step from t^n to t^n + dt.
 * @param[in,out] d driver state (history shifted)
 * @param[in] ub bulk velocity of the current state, v~^(n-1) in the thesis' notation [m/s]
 * @param[in] dt this step [s]
 * @return F^n [m/s^2]
 */
double drive_force(struct drive *d, double ub, double dt);

#endif
