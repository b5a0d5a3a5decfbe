/**
 * @file term_damper.h
 * @brief The acoustic damper (Sun, Pilloton, Antuono & Colagrossi 2023): a bulk viscosity
 *        zeta = alpha rho0 c0 h (sph.acoustic_damper = alpha) acting on the dilatation.
 *
 * The momentum equation gains (zeta / rho) grad(div u). Applied as a change of the pressure,
 * p -> p - zeta div u, it goes through the symmetric pressure gradient and its wall term
 * unchanged: momentum is conserved pair by pair and the walls push with the damped pressure
 * too. div u_a = -(1/rho_a) D rho_a / Dt is taken from the density change of the last step
 * without the volume diffusion's share (sph_density), so it costs no neighbour loop; it is a
 * per-particle state (`density_rate`, checkpointed) so that a resumed run continues bitwise.
 * A solenoidal velocity field (the turbulence) has div u = 0 and feels nothing; the
 * particle-scale acoustic noise of the weakly compressible scheme, whose pressure times the
 * configurational error of the pressure gradient drains turbulent energy (the budgets'
 * pressure noise), is damped at the rate zeta k^2 / rho0 of its wavenumber k.
 * Hooks: damper_zeta_of (the model's constant), damper_rate (sph_density, after the density),
 * damper_pressure (the pressure the forces see). Its time-step limit is the viscous one with
 * nu + zeta / rho0 (sim.c time_step).
 */
#ifndef CHANSPH_TERM_DAMPER_H
#define CHANSPH_TERM_DAMPER_H

/** zeta = alpha rho0 c0 h [Pa s]; 0 when alpha = 0 (off). */
static inline double damper_zeta_of(double alpha, double rho0, double c0, double h) {
  return alpha * rho0 * c0 * h;
}

/** (1/rho) D rho / Dt of the last step, = -div u [1/s]: the density change from rho_old to
    rho_new in dt less the volume diffusion's part dt D / gamma_new (Eq. 3.64). */
static inline double damper_rate(double rho_old, double rho_new, double dt, double diff,
                                 double gam_new) {
  return (rho_new - rho_old - dt * diff / gam_new) / (dt * rho_new);
}

/** The pressure with the damper: p + zeta (1/rho) D rho / Dt = p - zeta div u [Pa]. */
static inline double damper_pressure(double p, double zeta, double rate) {
  return p + zeta * rate;
}

#endif
