/**
 * @file shift.h
 * @brief Particle shifting (`sph.shifting = fickian`, issue 12): after the position update each
 *        fluid particle moves by
 *
 *          delta r_a = -C h^2 grad C_a,
 *          grad C_a = sum_b V_b [1 + R (w_ab / w(dr))^n] grad_a w_ab - sum_walls W_as n_s,
 *
 *        the Fickian shift of Lind et al. (2012, J. Comput. Phys. 231, Eq. 21-24) with the
 *        anti-clustering term of Skillen et al. (2013, Comput. Methods Appl. Mech. Engrg. 265)
 *        and Sun et al. (2017, Comput. Methods Appl. Mech. Engrg. 315), R = 0.2, n = 4. The
 *        sum runs over fluid and vertex neighbours; the walls' part uses |grad gamma_as| with
 *        the weight W_as of the pressure wall term (`sph.wall_pressure_weight`), so that the
 *        shift and a uniform pressure see the same equilibrium. |delta r_a| <= 0.1 dr, and a
 *        shift never carries a particle more than half-way to a wall. Velocities, masses and
 *        densities are not changed (docs/theory.md, "Particle shifting").
 *
 * Determinism: each particle's shift is a gather over its own neighbour list at the positions
 * of the start of the step (the list is valid there), so it is the same on any number of
 * threads and ranks, and it depends only on checkpointed state (positions, densities, masses).
 */
#ifndef CHANSPH_SHIFT_H
#define CHANSPH_SHIFT_H

#include "nbr.h"
#include "part.h"
#include "sph.h"

/**
 * @brief The shift of every owned fluid particle at the current positions (the ones the
 *        neighbour list was built for); zero for vertex particles.
 * @param[in] M model (shift_ch2, shift_iwdr, shift_max, lat_s, wall_pressure)
 * @param[in] P particles (x, y, z, vol of owned particles and ghosts)
 * @param[in] nb neighbour list of the current positions
 * @param[out] sx, sy, sz shift per owned slot [m]
 */
void shift_compute(const struct model *M, const struct particles *P, const struct nbr *nb,
                   double *sx, double *sy, double *sz);

/**
 * @brief Move the owned particles by the shift (after the position update of the step).
 * @param[in,out] P particles (x, y, z)
 * @param[in] sx, sy, sz shift per owned slot [m] (vertex particles hold zeros)
 */
void shift_apply(struct particles *P, const double *sx, const double *sy, const double *sz);

/**
 * @brief The Taylor correction of the velocities for a shift (sph.shift_velocity = taylor):
 *        du_a = (delta r_a . grad) u_a, grad u_a the first-order corrected gradient (thesis Eq.
 *        2.88-2.90) of the velocities at the current positions over fluid and vertex
 *        neighbours (Lind et al. 2012, Eq. 24); zero for vertex particles.
 * @param[in] M model
 * @param[in] P particles (positions, velocities, volumes of owned particles and ghosts)
 * @param[in] nb neighbour list of the current positions
 * @param[in] sx, sy, sz the shifts (shift_compute) [m]
 * @param[out] du, dv, dw the velocity change per owned slot [m/s]
 */
void shift_velocity(const struct model *M, const struct particles *P, const struct nbr *nb,
                    const double *sx, const double *sy, const double *sz, double *du, double *dv,
                    double *dw);

/**
 * @brief The conservative momentum transport of a shift (sph.shift_velocity = conservative):
 *
 *          du_a = u_a dr_a . G_a + sum_{b fluid} m_b phi_ab u_b (dr_b . grad_a w_ab) / rho_b,
 *          G_a = sum_b m_b phi_ab grad_a w_ab / rho_a - sum_walls W_as n_s,
 *
 *        the symmetric SPH divergence dt (1/rho) div(rho u (u~ - u)) of the A term of the
 *        transport-velocity formulation (Adami, Hu & Adams 2013, J. Comput. Phys. 241, Eq. 9)
 *        with the shift dr = dt (u~ - u) as the transport velocity's displacement and the
 *        kernel gradient weighted by the shift's phi_ab = 1 + R (w_ab / w(dr))^n; G_a is the
 *        shift's grad C_a (its walls' part counting the region behind a wall as filled), so
 *        the first term vanishes on the initial lattice, walls included. In the interior it
 *        is (dr . grad) u + u div dr. Each fluid pair's share is antisymmetric; the walls'
 *        part and the vertex neighbours of the first term act on u_a alone (the wall takes
 *        m_a u_a dr_a . (their part), zero where u_a = 0). Zero for vertex particles.
 * @param[in] M model
 * @param[in] P particles (positions, velocities, masses, densities and the shifts shift_dx,
 *              shift_dy, shift_dz of owned particles and ghosts: dd_refresh PR_SHIFT)
 * @param[in] nb neighbour list of the current positions
 * @param[out] du, dv, dw the velocity change per owned slot [m/s]
 */
void shift_velocity_conservative(const struct model *M, const struct particles *P,
                                 const struct nbr *nb, double *du, double *dv, double *dw);

#endif
