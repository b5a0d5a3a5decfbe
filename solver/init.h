/**
 * @file init.h
 * @brief Initial velocity field of a run: mean profile (rest, laminar, Reichardt),
 *        divergence-free streaks and sinusoidal modes, counter-based random noise, or the
 *        state of an earlier run (thesis Sec. 6.1.1; docs/theory.md, "Start-up").
 */
#ifndef CHANSPH_INIT_H
#define CHANSPH_INIT_H

#include "part.h"
#include "scene.h"

/**
 * @brief Set the velocities (and, from an earlier run of the same resolution, positions and
 *        densities) of the fluid particles of a freshly created lattice.
 * @param[in] sc scene
 * @param[in,out] P particles as created by part_create
 * @return CHANSPH_OK, or CHANSPH_ERR after a message naming the file (init.from)
 */
int init_fields(const struct scene *sc, struct particles *P);

/**
 * @brief The friction velocity of the Reichardt initial profile: (force delta)^(1/2) in force
 *        mode, or the u_tau whose Reichardt profile has the target bulk velocity (flux mode).
 */
double init_reichardt_utau(const struct scene *sc);

/**
 * @brief Uniform random number in [-1, 1) from the Philox-4x64 generator (Random123) with
 *        key (seed) and counter (id, stream): the same for a particle whatever the thread or rank.
 * @param seed key
 * @param id particle id
 * @param stream which number of this particle (0, 1, 2 for u, v, w)
 */
double init_noise(long seed, long long id, int stream);

#endif
