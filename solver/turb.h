/**
 * @file turb.h
 * @brief The turbulence model terms: wall-law stresses on the wall vertices, and the
 *        Smagorinsky eddy viscosity with van Driest damping and Yoshizawa's residual kinetic
 *        energy (thesis Sec. 5.2.2). Quasi-DNS with the laminar wall law never calls it.
 *
 * Order within a step (sim.c, model_update, which also refreshes the ghosts between the
 * passes: as for sph.h, the passes never exchange halos themselves): after the density and
 * the wall values of the new positions,
 *  1. the wall-law stress rho u_tau^2 e_t of every fluid particle within 2h of a wall (walllaw.h),
 *  2. the wall stress rho_s u_tau u_tau of the vertices by Shepard interpolation (Ferrand
 *     Eq. 38),
 *  3. with LES: the rate of strain S, the local y+ from the wall stress at the foot of the
 *     nearest wall, nu_r = l_S^2 S and k_r; with les.strain_lag (the default) the force loop
 *     of the previous step formed them from the strain of its state (turb_model_chunk,
 *     turb_advance), one time step of lag, and this step only takes their maximum;
 *     les.model = profile instead sets nu_r = nu g(d / delta) from the table of les.profile
 *     (turb_profile_value) and no k_r,
 *  4. with C_Y > 0, sph_kr_pressure (sph.h, which sets every pressure the forces read): k_r
 *     of the vertices (Shepard), and the pressure of fluid and vertex particles as seen by the
 *     forces becomes p + 2/3 rho k_r (Eq. 5.42: pr2 and the wall pressure; P->p stays the
 *     equation-of-state pressure).
 * Everything is a gather over the neighbour list: bitwise independent of the thread count.
 * The model terms change no pressure here: turb.c computes tau_w, nu_r and k_r only.
 * Phases: steps 1-2 are timed as `wall_law`, steps 3-4 as `les`.
 */
#ifndef CHANSPH_TURB_H
#define CHANSPH_TURB_H

#include "dd.h"
#include "nbr.h"
#include "part.h"
#include "sph.h"

/**
 * @brief Steps 1-2: the wall-law stress of the near-wall fluid particles (ghosts included: they
 *        compute their own) and its Shepard interpolation to the vertices (W->tx, W->tz); the
 *        caller then refreshes the vertex ghosts' wall values.
 */
void turb_wall_law(const struct model *M, struct particles *P, const struct nbr *nb,
                   struct walls *W);

/**
 * @brief Step 3 (LES): nu_r and k_r of the owned particles at the current state, or, with
 *        les.strain_lag after the first step, those the last force pass formed; the caller
 *        then refreshes them at the ghosts.
 * @return the largest nu + nu_r over this rank's fluid particles [m^2/s] (M->nu is the
 *         viscosity of the schedule; the caller takes the maximum over the ranks)
 */
double turb_eddy_viscosity(const struct model *M, struct particles *P, const struct nbr *nb,
                           const struct walls *W);

/** les.model = profile: the table's nu_r / nu at y (wall distance over delta), linear between
    its points and constant beyond the first and the last. Exposed for the unit tests. */
double turb_profile_value(const struct nu_profile *t, double y);

/** Particles per call of turb_model_chunk (the force loop's chunk). */
enum { TURB_CHUNK = 128 };

/**
 * @brief nu_r and k_r of the particles a0 .. a0+n-1 (n <= TURB_CHUNK) from their corrected
 *        velocity-gradient sums (as turb_strain_gradient takes them: A in ab[0..5][i], B in
 *        ab[6..14][i] for particle a0 + i), with the damping of the current wall stresses: what
 *        the force loop computes for the next step under les.strain_lag. Particles that are not
 *        fluid get 0. Vectorised over the chunk, and the same bits for a particle wherever it
 *        sits in a chunk.
 * @param[out] nur nu_r of the n particles (nur[i] for particle a0 + i) [m^2/s]
 * @param[out] kr k_r [m^2/s^2]
 */
void turb_model_chunk(const struct model *M, const struct particles *P, const struct walls *W,
                      size_t a0, int n, const double ab[][TURB_CHUNK], double *nur, double *kr);

/**
 * @brief les.strain_lag, after the force pass: the nu_r and k_r it formed (P->nur_next,
 *        P->kr_next) become those of the next step (P->nur_live = 1), which model_update (sim.c)
 *        then only refreshes at the ghosts and adds to the pressure.
 */
void turb_advance(struct particles *P);

/**
 * @brief Rate of strain from the first-order corrected velocity gradient of one particle
 *        (thesis Eq. 2.88-2.90 with k = 0): G = [sum_b V_b (v_b - v_a) (x) grad w_ab] L_a^T,
 *        S = (2 S:S)^(1/2), S = (G + G^T)/2. Exposed for the unit tests.
 * @param dim 2 or 3
 * @param A -sum_b V_b F_ab r_ab (x) r_ab, as {xx, xy, xz, yy, yz, zz}
 * @param B sum_b V_b (v_b - v_a)_i F_ab (r_ab)_j, row-major 3x3
 * @return S [1/s]
 */
double turb_strain_gradient(int dim, const double A[6], const double B[9]);

/**
 * @brief The Q criterion (|Omega|^2 - |S|^2)/2 = -G_ij G_ji / 2 of the corrected velocity
 *        gradient G = B L from the sums of turb_strain_gradient. Exposed for the unit tests.
 * @return Q [1/s^2]
 */
double turb_q_gradient(int dim, const double A[6], const double B[9]);

/**
 * @brief Q (turb_q_gradient) of every owned fluid particle at the current state into q (0 for
 *        vertices), from the neighbour list and the ghosts' current velocities; for
 *        particles.nc (output.q_criterion).
 */
void turb_q_criterion(const struct model *M, const struct particles *P, const struct nbr *nb,
                      double *q);

/**
 * @brief van Driest damping 1 - exp(-y+/A+) (thesis Eq. 5.50, sign corrected).
 */
double turb_van_driest(double yplus, double a_plus);

#endif
