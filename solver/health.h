/**
 * @file health.h
 * @brief Health checks of the particle state: NaN/Inf in any per-particle array that is written
 *        or sampled (position, velocity, density, pressure, mass, gamma, kernel sum,
 *        acceleration, nu_r, k_r), particles through a wall, supersonic particles. A failure
 *        names the step, the particle id and its position. The run checks every health.every
 *        steps and, whatever that interval, every state before it is written or sampled
 *        (checkpoint, snapshot, stats.nc, statistics sample, time-series row, particles.nc).
 */
#ifndef CHANSPH_HEALTH_H
#define CHANSPH_HEALTH_H

#include "part.h"
#include "sph.h"

/** What went wrong, and where. */
struct health_report {
  char what[400];
};

/**
 * @brief Check every fluid particle. If several fail, the one with the smallest id is
 *        reported, so the message does not depend on threads.
 * @param[in] M model (walls at y = 0 and ly, c0)
 * @param[in] P particles
 * @param[in] step,t current step and time
 * @param[out] rep message on failure
 * @return 0 if healthy, nonzero otherwise
 */
int health_check(const struct model *M, const struct particles *P, long step, double t,
                 struct health_report *rep);

#endif
