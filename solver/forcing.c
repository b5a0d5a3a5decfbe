/** @file forcing.c @brief Implementation of forcing.h. */
#include "forcing.h"

void drive_init(struct drive *d, const struct scene *s) {
  d->mode = s->drive_mode;
  d->controller = s->controller;
  d->target = s->u_bulk;
  d->force = s->force;
  d->ub_prev = 0.0;
  d->dt_prev = 0.0;
  d->started = 0;
}

double drive_force(struct drive *d, double ub, double dt) {
  if (d->mode == DRIVE_FORCE) return d->force;
  if (!d->started) d->ub_prev = ub, d->dt_prev = dt, d->started = 1;
  double f;
  if (d->controller == CONTROLLER_EQ338)
    f = (d->target - 2.0 * ub + d->ub_prev) / (2.0 * dt); /* Eq. 3.38 */
  else
    f = (d->target - ub) / dt - (ub - d->ub_prev) / d->dt_prev + d->force; /* Eq. 3.42/3.43 */
  d->ub_prev = ub, d->dt_prev = dt, d->force = f;
  return f;
}
