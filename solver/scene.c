/**
 * @file scene.c
 * @brief Table-driven scene parsing (inih), validation and documentation (STYLE items 9-11).
 */
#define _XOPEN_SOURCE 700 /* realpath */
#include "scene.h"
#include "alloc.h"
#include "kernel.h"

#include <ctype.h>
#include <ini.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "engine.h"
#include "error.h"
#include "euler.h"
#include "walllaw.h"

/* Short names of the key types and flags of stats/contract.h, for the tables below. */
#define T_INT SCENE_INT
#define T_LONG SCENE_LONG
#define T_DOUBLE SCENE_DOUBLE
#define T_CHOICE SCENE_CHOICE
#define T_STRING SCENE_STRING
#define T_LIST SCENE_LIST
enum { REQUIRED = SCENE_REQUIRED, LO_OPEN = SCENE_LO_OPEN };
#define BIG SCENE_NO_BOUND

/** One of the solver's own keys: its definition and the field of struct scene it sets. */
struct key {
  struct scene_key_def d;
  size_t offset;
};

#define OFF(f) offsetof(struct scene, f)
/* The bounds of the physical keys where the physics is finite (SI units): a body acceleration,
   a speed and a kinematic viscosity beyond these are no channel flow, and would take the time
   step to zero (a run that never advances) */
#define ACCEL_MAX 1e12
#define SPEED_MAX 1e8
#define NU_MAX 1e6

/* The names of the choice keys, in the order of their enums (scene.h): the value stored is
   the index. */
static const char *const names_sph_viscous[] = {"morris", "violeau", NULL};
static const char *const names_sph_kernel[] = {"wendland_c2", "wendland_c4", NULL};
static const char *const names_sph_laplacian_norm[] = {"wall_normal", "trace", "none", NULL};
static const char *const names_sph_wall_shear_weight[] = {"discrete", "analytic", NULL};
static const char *const names_sph_wall_pressure_weight[] = {"lattice", "consistent", "analytic",
                                                             NULL};
static const char *const names_sph_pressure_gradient[] = {"standard", "corrected", "kgc", NULL};
static const char *const names_sph_shifting[] = {"none", "fickian", NULL};
static const char *const names_sph_shift_velocity[] = {"keep", "taylor", "conservative", NULL};
static const char *const names_sph_wall_collision[] = {"stop", "reflect", NULL};
static const char *const names_les_model[] = {"none", "smagorinsky", "profile", NULL};
static const char *const names_les_strain[] = {"gradient", "violeau_issa", NULL};
static const char *const names_wall_law[] = {"laminar", "log", "reichardt", NULL};
static const char *const names_drive_mode[] = {"force", "flux", NULL};
static const char *const names_drive_controller[] = {"eq3.43", "eq3.38", NULL};
static const char *const names_init_profile[] = {"rest", "laminar",   "reichardt",
                                                 "wave", "synthetic", NULL};
static const char *const names_init_density[] = {"keep", "rho0", NULL};
static const char *const names_sph_diffusion[] = {"ferrand", "delta_sph", NULL};

/* The solver's keys before the engines': the domain, the scheme, the fluid, the drive, time,
   initial state and output. */
static const struct key keys_head[] = {
    {{"domain", "dimension", T_INT, NULL, 2, 3, REQUIRED, NULL, "-",
      "Spatial dimension: 2 (x-y plane) or 3."},
     OFF(dim)},
    {{"domain", "delta", T_DOUBLE, "0.5", 0, BIG, LO_OPEN, NULL, "m",
      "Channel half-width; the walls are at y = 0 and y = 2 delta."},
     OFF(delta)},
    {{"domain", "lx", T_DOUBLE, NULL, 0, BIG, REQUIRED | LO_OPEN, NULL, "m",
      "Periodic length in the streamwise direction x; a multiple of dr, at least 6h."},
     OFF(lx)},
    {{"domain", "lz", T_DOUBLE, "0", 0, BIG, 0, NULL, "m",
      "Periodic length in the spanwise direction z (3-D only; required there)."},
     OFF(lz)},
    {{"domain", "dr", T_DOUBLE, NULL, 0, BIG, REQUIRED | LO_OPEN, NULL, "m",
      "Initial particle spacing; 2 delta, lx and lz must be multiples of it."},
     OFF(dr)},
    {{"sph", "h_over_dr", T_DOUBLE, "1.3", 1.0, 2.5, 0, NULL, "-",
      "Smoothing length over particle spacing (kernel support radius is 2h). The neighbour "
      "number grows as its cube, and with it the cost of a step and the accuracy on a "
      "disordered arrangement: in the turbulent channel with wendland_c4 the numerical pair "
      "stress falls about as N^-0.8 (h = 2.5 dr halves it against 2 dr at 1.9 times the "
      "step's cost; refining dr+ from 6 to 4.5 at h = 2 dr lowers it by a quarter near the "
      "wall at 3.2 times the cost a turnover; docs/validation/scheme_ab.md)."},
     OFF(h_over_dr)},
    {{"sph", "kernel", T_CHOICE, "wendland_c2", 0, 0, 0, names_sph_kernel, "-",
      "Kernel, support 2h: the Wendland C2 (thesis Eq. 2.63) or the Wendland C4 of Dehnen & Aly "
      "(2012), smoother (its gradient vanishes as (1 - q/2)^5 at the edge), with smaller "
      "zeroth-order errors than C2 at larger h/dr; C4 is 3-D only (its closed-form wall integrals "
      "are, "
      "solver/wall.h; docs/theory.md \"Kernels\")."},
     OFF(kernel)},
    {{"sph", "xi", T_DOUBLE, "0", 0, BIG, 0, NULL, "-",
      "Volume-diffusion constant xi of thesis Eq. 3.34; 0 selects the mixing-length value "
      "1000 dr / (2 delta) (thesis Sec. 3.2, 6.1.1)."},
     OFF(xi)},
    {{"sph", "diffusion", T_CHOICE, "ferrand", 0, 0, 0, names_sph_diffusion, "-",
      "Pair form of the volume diffusion of the continuity equation: ferrand (thesis Eq. 3.34, "
      "strength 1/xi, the pair weight grows with the pair distance r_ab) or delta_sph (the "
      "delta-SPH strength of Antuono et al. (2010): 2 delta h in place of r_ab / xi, with the "
      "same hydrostatic density difference as Fourtakas et al. (2019); docs/theory.md, "
      "\"Continuity\")."},
     OFF(diffusion)},
    {{"sph", "delta", T_DOUBLE, "0.1", 0, 1, 0, NULL, "-",
      "delta of sph.diffusion = delta_sph (0.1 is the delta-SPH literature's value)."},
     OFF(diff_delta)},
    {{"sph", "diffusion_substeps", T_INT, "1", 1, 16, 0, NULL, "-",
      "Sub-steps of the volume diffusion in each time step: n > 1 applies the diffusion's rate "
      "n times at dt / n, the last n - 1 at the new positions in a pass of their own, so that "
      "time.c_diffusion limits dt / n instead of dt: a stronger sph.delta at the acoustic "
      "step for one density pass per extra sub-step (docs/theory.md, \"Continuity\"). Not "
      "with sph.acoustic_damper. An experiment, not for production: with delta = 0.4 and "
      "n = 2 in the turbulent channel the pressure noise feeds particle-scale v and w "
      "(docs/validation/scheme_ab.md); use time.c_diffusion's smaller step instead."},
     OFF(diff_substeps)},
    {{"sph", "acoustic_damper", T_DOUBLE, "0", 0, 2, 0, NULL, "-",
      "Acoustic damper alpha (Sun, Pilloton, Antuono & Colagrossi 2023): a bulk viscosity "
      "zeta = alpha rho0 c0 h, applied as the pressure p - zeta div u with div u = -(1/rho) "
      "D rho/Dt from the density change of the last step (without the volume diffusion's part); "
      "it damps the particle-scale acoustic (dilatational) motion and leaves solenoidal motion "
      "alone; the viscous time-step limit takes nu + zeta / rho0. 0 = off (docs/theory.md, "
      "\"The acoustic damper\")."},
     OFF(damper)},
    {{"sph", "viscous", T_CHOICE, "morris", 0, 0, 0, names_sph_viscous, "-",
      "Viscous operator: Morris (thesis Eq. 2.147) or Violeau (Eq. 2.100), both with the wall "
      "shear term."},
     OFF(viscous)},
    {{"sph", "laplacian_norm", T_CHOICE, "wall_normal", 0, 0, 0, names_sph_laplacian_norm, "-",
      "Normalisation of the viscous particle sum by its discrete second moment (plus the "
      "analytic part behind the walls): wall_normal uses the y-y moment, exact for the mean "
      "flow of a channel; trace uses the isotropic part; none is the plain operator of the "
      "thesis (2.6% lattice error at h/dr = 1.3, docs/theory.md)."},
     OFF(lap_norm)},
    {{"sph", "wall_shear_weight", T_CHOICE, "discrete", 0, 0, 0, names_sph_wall_shear_weight, "-",
      "Weight of the viscous wall shear term: |grad gamma_as| (analytic, thesis Eq. 2.147) or "
      "the discrete first moment sum_b V_b (r_ab . n) F_ab (Morris; Violeau: half that of its "
      "pair weight G_ab, per component), which makes the operator exact for a linear velocity "
      "profile (docs/theory.md)."},
     OFF(wall_weight)},
    {{"sph", "wall_pressure_weight", T_CHOICE, "lattice", 0, 0, 0, names_sph_wall_pressure_weight,
      "-",
      "Weight of the pressure wall term: |grad gamma_as| (analytic, thesis Eq. 3.17); "
      "max(|grad gamma_as|, sum_b V_b (r_ab . n) F_ab) of the current particles (consistent), "
      "which keeps the first particle layer in place under a uniform pressure; or "
      "|grad gamma_as| plus the excess of that discrete moment over it on the initial particle "
      "lattice, as a function of the wall distance (lattice): the same equilibrium, but a "
      "uniform pressure still resists wall-normal disorder (docs/theory.md)."},
     OFF(wall_pressure)},
    {{"sph", "pressure_gradient", T_CHOICE, "standard", 0, 0, 0, names_sph_pressure_gradient, "-",
      "Pressure gradient: the symmetric Grad^{gamma,1} with its wall term (thesis Eq. 3.17), or "
      "the first-order corrected difference form Eq. 2.90 (k = 0) with the matrix L of Eq. "
      "2.88 built from fluid and vertex neighbours, exact for linear pressure fields and without "
      "a wall term (Sec. 6.2.2-6.2.3), or the conservative kernel-gradient-corrected form kgc, "
      "-(1/(gamma_a rho_a)) sum_b V_b (p_a B_b + p_b B_a) grad w_ab with its wall term, B the "
      "inverse of the moment matrix (walls included) blended towards the identity where it is "
      "ill-conditioned: antisymmetric in a and b and exact for the first-order part of a linear "
      "pressure field (docs/theory.md)."},
     OFF(pgrad)},
    {{"sph", "shifting", T_CHOICE, "none", 0, 0, 0, names_sph_shifting, "-",
      "Particle shifting after each position update: none, or the Fickian shift "
      "delta r_a = -C h^2 grad C_a of Lind et al. (2012) with the anti-clustering term of "
      "Skillen et al. (2013) / Sun et al. (2017, 2018) and the walls' part of grad C_a taken "
      "from grad gamma with the pressure wall weight; at most 0.1 dr per step; velocities are "
      "not changed (docs/theory.md, \"Particle shifting\")."},
     OFF(shifting)},
    {{"sph", "shift_coefficient", T_DOUBLE, "0.05", 0, 0.3, LO_OPEN, NULL, "-",
      "Shifting coefficient C of delta r_a = -C h^2 grad C_a per step (sph.shifting = fickian). "
      "0.05 relaxes a displaced particle per step as much as Sun et al. (2018)'s CFL Ma (2h)^2 "
      "with h = 2 dr at CFL Ma = 0.08 (this code's cfl 0.8 at Mach 0.1) does; 0.5 is unstable "
      "in 2-D (docs/theory.md)."},
     OFF(shift_coef)},
    {{"sph", "shift_velocity", T_CHOICE, "keep", 0, 0, 0, names_sph_shift_velocity, "-",
      "What a shift does to the velocity of the shifted particle: keep it, carry it to the "
      "new position by the Taylor correction u_a += (delta r_a . grad) u_a (Lind et al. 2012, "
      "Eq. 24) with the first-order corrected velocity gradient of the start of the step "
      "(thesis Eq. 2.88-2.90). Kept, a shift across the mean shear adds dU/dy delta y to u "
      "each step; corrected, the budgets' closure holds the correction's share (it is not a "
      "force; docs/theory.md, \"Particle shifting\"). conservative: the momentum transport "
      "of the transport-velocity formulation (Adami, Hu & Adams 2013, the divergence of "
      "A = rho u (u~ - u) with dr = dt (u~ - u)), du_a = sum_b m_b [u_a (dr_a . grad w_ab) / "
      "rho_a + u_b (dr_b . grad w_ab) / rho_b] over fluid pairs, which conserves momentum."},
     OFF(shift_velocity)},
    {{"sph", "wall_collision", T_CHOICE, "stop", 0, 0, 0, names_sph_wall_collision, "-",
      "What a fluid particle that reaches a wall in a step does: stop the run (exit 3, the "
      "particle named), or reflect it specularly (y -> -y at y = 0, 2 delta - y at the upper "
      "wall; its wall-normal velocity turned into the fluid, u and w kept) and go on, each "
      "reflection named on stderr and counted in the log line. The wall's pressure term holds "
      "particles off the wall only while their pressure is positive; with fluid.p_background = 0 "
      "the acoustic noise can pull one onto it, about once in 10^10 particle-steps at dr+ = 6 "
      "(docs/theory.md, \"A particle at the wall\")."},
     OFF(wall_collision)},
    {{"sph", "wall_dmin", T_DOUBLE, "1", 0, BIG, LO_OPEN, NULL, "dr",
      "Lower bound delta r of the wall distance in the wall shear term (thesis Eq. 2.148), in "
      "units of dr."},
     OFF(wall_dmin)},
    {{"sph", "eta2", T_DOUBLE, "1e-4", 0, 1, 0, NULL, "h^2",
      "Regularisation added to r^2 in the viscous term (thesis Sec. 2.3.3), in units of h^2."},
     OFF(eta2)},
    {{"les", "model", T_CHOICE, "none", 0, 0, 0, names_les_model, "-",
      "Sub-grid model: none (quasi-DNS: no model term is computed), the Smagorinsky eddy "
      "viscosity nu_r = l_S^2 S (thesis Eq. 5.45-5.47), or profile: a prescribed nu_r(y) read "
      "from les.profile (a diagnostic: e.g. nu_r = -nu_num(y) takes a measured numerical "
      "viscosity out of the mean flow; no k_r); needs sph.viscous = violeau (Eq. 2.100 with "
      "variable viscosity)."},
     OFF(les)},
    {{"les", "cs", T_DOUBLE, "0.065", 0, 1, LO_OPEN, NULL, "-",
      "Smagorinsky constant C_S: 0.065 (Moin & Kim 1982, used in the thesis) or 0.158 (Lilly's "
      "analysis for the Wendland kernel, thesis App. B)."},
     OFF(cs)},
    {{"les", "filter_width", T_DOUBLE, "2", 0, 10, LO_OPEN, NULL, "h",
      "Filter width Delta_G in units of h (thesis Sec. 5.2.2.1: 2h for the Wendland kernel)."},
     OFF(filter_h)},
    {{"les", "strain", T_CHOICE, "gradient", 0, 0, 0, names_les_strain, "-",
      "Rate of strain S = (2 S:S)^(1/2) from the full velocity gradient (first-order corrected, "
      "thesis Eq. 2.88-2.90) or from the Violeau-Issa estimate with its wall term (Eq. 5.48; "
      "docs/theory.md)."},
     OFF(strain)},
    {{"les", "strain_lag", T_INT, "1", 0, 1, 0, NULL, "-",
      "With strain = gradient: 1 forms the strain sums of the eddy viscosity and k_r inside the "
      "force loop, from the neighbours and pair geometry it has already gathered, and applies "
      "them at the next step (one time step of lag, as in codes that update nu_r from the "
      "previous velocity field; the LES step then costs about as much as the quasi-DNS step; "
      "docs/performance.md); the first step of a run, and of a resumed run whose checkpoint "
      "lacks the values, computes them at the current state. 0: a separate pass at the current "
      "state every step."},
     OFF(strain_lag)},
    {{"les", "van_driest", T_INT, "1", 0, 1, 0, NULL, "-",
      "van Driest damping l_S = C_S Delta_G (1 - exp(-y+/A+)) (thesis Eq. 5.50 with the sign "
      "corrected), y+ from the local friction velocity of the nearest wall; also damps k_r."},
     OFF(van_driest)},
    {{"les", "a_plus", T_DOUBLE, "25", 0, BIG, LO_OPEN, NULL, "-", "A+ of the van Driest damping."},
     OFF(a_plus)},
    {{"les", "cy", T_DOUBLE, "0.044", 0, 1, 0, NULL, "-",
      "Yoshizawa constant C_Y of the residual kinetic energy k_r = 2 C_Y (Delta_G S)^2 (thesis "
      "Eq. 5.49), added to the pressure as 2/3 rho k_r (Eq. 5.42); 0 leaves it out."},
     OFF(cy)},
    {{"les", "profile", T_STRING, "", 0, 0, 0, NULL, "-",
      "With model = profile: a text file of lines 'y nu_r/nu' (whitespace or comma between, '#' "
      "comments and a header line allowed): the eddy viscosity over nu at the wall distance y "
      "in units of delta, y increasing from 0, nu_r/nu > -1 (so that nu + nu_r > 0) and 0 at "
      "y = 0 (the wall shear term takes the molecular viscosity), linear in between and "
      "constant beyond the last point; at most 256 points. Read at every start and resume. A "
      "relative path in a scene file is relative to the scene file's directory."},
     OFF(les_profile)},
    {{"wall", "law", T_CHOICE, "laminar", 0, 0, 0, names_wall_law, "-",
      "Wall law of the wall shear term: laminar (thesis Eq. 2.146-2.148, the particle's own "
      "velocity), log law (Eq. 5.51, linear below y+ = 11.06) or Reichardt (Eq. 5.53); the "
      "turbulent laws are solved for u_tau per near-wall particle and carried to the wall "
      "vertices (Ferrand Eq. 38)."},
     OFF(wall_law)},
    {{"wall", "kappa", T_DOUBLE, "0.41", 0, 1, LO_OPEN, NULL, "-",
      "von Karman constant of the wall laws (thesis Eq. 5.33)."},
     OFF(kappa)},
    {{"wall", "b", T_DOUBLE, "5.2", -BIG, BIG, 0, NULL, "-",
      "Intercept B of the log law (thesis Eq. 5.33)."},
     OFF(log_b)},
    {{"fluid", "nu", T_DOUBLE, NULL, 0, NU_MAX, REQUIRED, NULL, "m^2/s",
      "Kinematic viscosity (0: inviscid, e.g. the energy experiment of thesis Sec. 3.1.2)."},
     OFF(nu)},
    {{"fluid", "rho0", T_DOUBLE, "1000", 0, BIG, LO_OPEN, NULL, "kg/m^3", "Reference density."},
     OFF(rho0)},
    {{"fluid", "c0", T_DOUBLE, NULL, 0, SPEED_MAX, REQUIRED | LO_OPEN, NULL, "m/s",
      "Numerical speed of sound (about 10 times the largest velocity)."},
     OFF(c0)},
    {{"fluid", "zeta", T_DOUBLE, "7", 1, 10, 0, NULL, "-",
      "Exponent of the Tait equation of state (thesis Eq. 2.11)."},
     OFF(zeta)},
    {{"fluid", "p_background", T_DOUBLE, "0.01", -0.01, 10, 0, NULL, "rho0 c0^2",
      "Background pressure added to the Tait equation of state, in units of rho0 c0^2; it "
      "gives the particle arrangement a restoring force and, with the lattice pressure wall "
      "weight, stops the transverse instability of the sheared lattice (docs/theory.md). "
      "For turbulence use 0: its pair stress destroys resolved turbulence within 0.15 "
      "delta/u_tau (docs/validation/turbulent_channel.md). Negative values, for experiments, "
      "lower the pressure of every density; a developed turbulent channel raises its mean "
      "density back to the same mean pressure within 0.1 turnovers "
      "(docs/validation/scheme_ab.md)."},
     OFF(p_background)},
    {{"fluid", "gravity_y", T_DOUBLE, "0", -ACCEL_MAX, ACCEL_MAX, 0, NULL, "m/s^2",
      "Wall-normal body acceleration; enters the momentum equation, the wall pressure "
      "(thesis Eq. 2.143, 3.63) and the volume diffusion (Eq. 3.61)."},
     OFF(gravity_y)},
    {{"fluid", "nu_start", T_DOUBLE, "0", 0, NU_MAX, 0, NULL, "m^2/s",
      "Viscosity schedule (Jimenez & Moin 1991, thesis Sec. 6.1.1): nu_start until "
      "nu_ramp_begin, then linear in time to nu at nu_ramp_end; 0 = constant nu."},
     OFF(nu_start)},
    {{"fluid", "nu_ramp_begin", T_DOUBLE, "0", 0, BIG, 0, NULL, "s",
      "Start of the viscosity ramp."},
     OFF(nu_ramp_begin)},
    {{"fluid", "nu_ramp_end", T_DOUBLE, "0", 0, BIG, 0, NULL, "s",
      "End of the viscosity ramp (at least nu_ramp_begin)."},
     OFF(nu_ramp_end)},
    {{"drive", "mode", T_CHOICE, "force", 0, 0, 0, names_drive_mode, "-",
      "Drive the flow by a constant body force or by a controlled volume flux."},
     OFF(drive_mode)},
    {{"drive", "force", T_DOUBLE, "0", -ACCEL_MAX, ACCEL_MAX, 0, NULL, "m/s^2",
      "Streamwise body acceleration in force mode (tau_w = rho delta force, thesis Eq. 5.14); "
      "initial value in flux mode."},
     OFF(force)},
    {{"drive", "u_bulk", T_DOUBLE, "0", -SPEED_MAX, SPEED_MAX, 0, NULL, "m/s",
      "Target bulk velocity in flux mode."},
     OFF(u_bulk)},
    {{"drive", "controller", T_CHOICE, "eq3.43", 0, 0, 0, names_drive_controller, "-",
      "Flux controller: thesis Eq. 3.43 (new, generalised to variable dt by Eq. 3.42) or the "
      "older Eq. 3.38."},
     OFF(controller)},
    {{"time", "t_end", T_DOUBLE, NULL, 0, BIG, REQUIRED | LO_OPEN, NULL, "s", "End time."},
     OFF(t_end)},
    {{"time", "dt", T_DOUBLE, "0", 0, BIG, 0, NULL, "s",
      "Fixed time step; 0 selects the adaptive step of thesis Eq. 2.160-2.164."},
     OFF(dt_fixed)},
    {{"time", "cfl", T_DOUBLE, "0.8", 0, 2, LO_OPEN, NULL, "-",
      "Factor of the acoustic limit dt <= cfl h / c0 (thesis Eq. 2.160; 0.8 after Violeau & "
      "Leroy 2014)."},
     OFF(cfl)},
    {{"time", "c_visc", T_DOUBLE, "0.125", 0, 1, LO_OPEN, NULL, "-",
      "Factor of the viscous limit dt <= c_visc h^2 / nu (thesis Eq. 2.161)."},
     OFF(c_visc)},
    {{"time", "c_force", T_DOUBLE, "0.25", 0, 1, LO_OPEN, NULL, "-",
      "Factor of the force limit dt <= c_force sqrt(h / |a|) (thesis Eq. 2.162)."},
     OFF(c_force)},
    {{"time", "c_gamma", T_DOUBLE, "0.005", 0, 1, 0, NULL, "-",
      "Factor of the wall limit dt <= c_gamma / max|grad gamma . v| (thesis Eq. 2.163); 0 "
      "disables it."},
     OFF(c_gamma)},
    {{"time", "c_diffusion", T_DOUBLE, "0.18", 0, 1, 0, NULL, "-",
      "Factor of the volume diffusion's limit dt <= c_diffusion h^2 / D, D = delta h c0 for "
      "sph.diffusion = delta_sph (c0 h / xi, its bound, for ferrand): the explicit diffusion's "
      "stability; it binds only above delta = 0.18 / cfl (0.225 at cfl 0.8: delta = 0.3 blew up "
      "without it; docs/theory.md, \"Time integration\"); 0 disables it."},
     OFF(c_diffusion)},
    {{"time", "max_steps", T_LONG, "0", 0, 1e18, 0, NULL, "-",
      "Stop after this many steps even if t_end is not reached (0 = no limit)."},
     OFF(max_steps)},
    {{"init", "profile", T_CHOICE, "rest", 0, 0, 0, names_init_profile, "-",
      "Initial mean velocity: at rest; the laminar Poiseuille profile of the force (force mode) "
      "or of the target bulk velocity (flux mode); or Reichardt's turbulent profile (thesis Eq. "
      "5.53) with u_tau = (force delta)^(1/2) (force mode) or the u_tau whose profile has the "
      "target bulk velocity (flux mode); or the wall-normal wave v = init.wave sin(4 pi y / "
      "(2 delta)) of the energy experiment of thesis Sec. 3.1.2; or synthetic: a synthetic-eddy "
      "field (Jarrin et al. 2006) carrying the Lee & Moser Re_tau = 180 DNS mean profile U+(y+) "
      "and Reynolds-stress tensor (u'u', v'v', w'w', u'v'), scaled with the u_tau above and "
      "this scene's nu (3-D only; not divergence-free; docs/theory.md, \"Synthetic-eddy "
      "start-up\")."},
     OFF(init_profile)},
    {{"init", "wave", T_DOUBLE, "0", -SPEED_MAX, SPEED_MAX, 0, NULL, "m/s",
      "Amplitude of the wall-normal wave of profile = wave (the thesis uses c0/10)."},
     OFF(init_wave)},
    {{"init", "streaks", T_DOUBLE, "0", 0, BIG, 0, NULL, "m/s",
      "Amplitude of streamwise streaks u' = A 4 (y/2delta)(1 - y/2delta) cos(2 pi k z / lz) "
      "(3-D; divergence-free)."},
     OFF(init_streaks)},
    {{"init", "streak_kz", T_INT, "2", 1, 1e6, 0, NULL, "-", "Streak pairs across lz."},
     OFF(init_streak_kz)},
    {{"init", "modes", T_DOUBLE, "0", 0, BIG, 0, NULL, "m/s",
      "Amplitude of divergence-free sinusoidal modes: spanwise rolls from the stream function "
      "psi(x, y) and, in 3-D, streamwise rolls from psi(y, z), both vanishing with their "
      "normal derivative at the walls (thesis Sec. 6.1.1; docs/theory.md)."},
     OFF(init_modes)},
    {{"init", "mode_kx", T_INT, "1", 1, 1e6, 0, NULL, "-", "Periods of the modes along lx."},
     OFF(init_mode_kx)},
    {{"init", "mode_kz", T_INT, "1", 1, 1e6, 0, NULL, "-", "Periods of the modes along lz."},
     OFF(init_mode_kz)},
    {{"init", "noise", T_DOUBLE, "0", 0, BIG, 0, NULL, "m/s",
      "Amplitude of uniform random noise on each velocity component, from the counter-based "
      "Philox generator (Random123) keyed by seed and particle id: independent of threads and "
      "ranks."},
     OFF(init_noise)},
    {{"init", "seed", T_LONG, "1", 0, 1e15, 0, NULL, "-",
      "Key of the random noise and of the synthetic eddies."},
     OFF(init_seed)},
    {{"init", "eddies", T_LONG, "0", 0, 1e8, 0, NULL, "-",
      "Number N of synthetic eddies of profile = synthetic, placed in the box lx x (2 delta + "
      "2 sigma) x lz (sigma = eddy_size delta); 0 = the box volume / sigma^3; at most 100 "
      "times that plus 1000 (more gives the same Gaussian field at a growing cost)."},
     OFF(init_eddies)},
    {{"init", "eddy_size", T_DOUBLE, "0.2", 0, BIG, LO_OPEN, NULL, "delta",
      "Half-width sigma of the synthetic eddies (tent shape functions), in units of delta; at "
      "most lx/2 and lz/2."},
     OFF(init_eddy_size)},
    {{"init", "from", T_STRING, "", 0, 0, 0, NULL, "-",
      "particles.nc of an earlier run with the same domain: with the same particle count its "
      "positions and velocities are taken as they are (by id); otherwise its velocity field is "
      "interpolated (linear moving least squares) onto this scene's lattice, e.g. a coarse LES to "
      "start a finer "
      "run. A relative path in a scene file is relative to the scene file's directory (on the "
      "command line, to the working directory). Overrides profile; streaks, modes and noise are "
      "added on top. A source that is not a state of the box is refused (exit 1): variables "
      "not 1-D over 'particle', no particles, ids not 0..n-1 each once, a NaN or Inf, rho or "
      "mass not positive, a position outside the box, a value equal to its _FillValue or "
      "missing_value, a packed id. CF-packed variables (scale_factor, add_offset, as NCO's "
      "ncpdq writes them) are unpacked, to the packing's precision (a note says so). The file's "
      "run_id and time are recorded in stats.nc (init_from_run_id, init_from_time): `chansph "
      "extract` joins a run only after the run whose final state it started from."},
     OFF(init_from)},
    {{"init", "density", T_CHOICE, "keep", 0, 0, 0, names_init_density, "-",
      "With init.from at the same particle count: keep the particles' densities, or (rho0) "
      "shift them all by one constant so that their mean is fluid.rho0. A developed state may "
      "carry a mean overpressure (the density's mean drifts slowly, over tens of turnovers), "
      "which acts on the symmetric pressure gradient as a background pressure "
      "(docs/validation/scheme_ab.md); rho0 starts without it."},
     OFF(init_density)},
    {{"output", "log_every", T_INT, "100", 1, 1e9, 0, NULL, "steps",
      "Steps between progress lines (stdout and DIR/log.txt)."},
     OFF(log_every)},
    {{"output", "series_every", T_INT, "10", 1, 1e9, 0, NULL, "steps",
      "Steps between records of the time series in stats.nc."},
     OFF(series_every)},
    {{"output", "stats_every", T_INT, "10", 1, 1e9, 0, NULL, "steps",
      "Steps between samples of the binned profiles."},
     OFF(stats_every)},
    {{"output", "write_every", T_DOUBLE, "0", 0, BIG, 0, NULL, "s",
      "Simulated time between rewrites of stats.nc (0 = only at the end)."},
     OFF(write_every)},
    {{"output", "t_average_start", T_DOUBLE, "0", 0, BIG, 0, NULL, "s",
      "Start of the averaging window of the profiles (ends at t_end)."},
     OFF(t_average_start)},
    {{"output", "n_bins", T_INT, "0", 0, 1e7, 0, NULL, "-",
      "Wall-normal bins of the profiles, uniform between the walls; 0 = one bin of width dr "
      "centred on each initial particle layer y = j dr (the strips of width dr/2 at the walls "
      "join the first and last bins)."},
     OFF(n_bins)},
    {{"output", "particles", T_INT, "1", 0, 1, 0, NULL, "-",
      "Write the final particle state to DIR/particles.nc (1) or not (0)."},
     OFF(particles)},
    {{"output", "q_criterion", T_INT, "0", 0, 1, 0, NULL, "-",
      "Add q_criterion to particles.nc and the snapshots: Q = (|Omega|^2 - |S|^2)/2 [1/s^2] of "
      "each "
      "fluid "
      "particle's first-order corrected velocity gradient (thesis Eq. 2.88-2.90), for vortex "
      "identification (Hunt, Wray & Moin 1988: Q > 0 where rotation exceeds strain; an iso-surface "
      "of Q in ParaView shows the vortices). Computed only when one of them is written."},
     OFF(q_criterion)},
};

/* The solver's keys after the engines': health checks, the run, checkpoints, snapshots. */
static const struct key keys_tail[] = {
    {{"health", "every", T_INT, "1", 1, 1e9, 0, NULL, "steps",
      "Steps between full health checks (NaN, wall crossing, CFL); 1 checks every step. "
      "Whatever the interval, a state is checked before it is written or sampled (checkpoint, "
      "snapshot, stats.nc, particles.nc, statistics sample, time-series row)."},
     OFF(health_every)},
    {{"run", "threads", T_INT, "0", 0, 4096, 0, NULL, "-",
      "OpenMP threads; 0 keeps OMP_NUM_THREADS (or all cores)."},
     OFF(threads)},
    {{"run", "balance_every", T_INT, "100", 0, 1e9, 0, NULL, "steps",
      "With several MPI ranks: steps between checks of the particles per rank (0 = never "
      "re-partition). Results do not depend on the partition (docs/parallel.md)."},
     OFF(balance_every)},
    {{"run", "ranks", T_LIST, "", 1, 1e6, 0, NULL, "-",
      "Px,Pz: the MPI ranks as Px x Pz blocks of whole cell pencils (Px along x, Pz along z; "
      "Px Pz = the ranks; each block at least 4 cells of size h along a cut direction); empty = "
      "the factorisation with the fewest ghosts per rank (logged). Results do not depend on it "
      "(docs/parallel.md)."},
     OFF(ranks)},
    {{"run", "partition", T_LIST, "", 1, 1e9, 0, NULL, "columns",
      "Slabs only (Pz = 1): cell columns per rank at the start (up to 8 ranks, summing to the "
      "columns of the grid, each at least 4); empty = an even split. The load balance may move "
      "the cuts later; the results do not depend on them."},
     OFF(partition)},
    {{"run", "check_ids", T_INT, "0", 0, 1, 0, NULL, "-",
      "Debug mode: after every step gather all particle ids on rank 0 and check that each id "
      "0 .. N-1 is held by exactly one rank (none lost or duplicated by the migration); stops "
      "with an internal error naming the step and the id otherwise."},
     OFF(check_ids)},
    {{"run", "balance_threshold", T_DOUBLE, "0.1", 0, 100, 0, NULL, "-",
      "Re-partition the cell columns along x when the most loaded rank holds more than (1 + "
      "threshold) times the mean particle count."},
     OFF(balance_threshold)},
    /* [checkpoint]: restart/ (docs/checkpoint-format.md, docs/batch-jobs.md) */
    {{"checkpoint", "every_steps", T_LONG, "0", 0, 1e18, 0, NULL, "steps",
      "Steps between checkpoints in DIR/checkpoints (0 = not by steps). A run also checkpoints "
      "at its end, on SIGTERM/SIGINT/SIGUSR1, a STOP file, --max-steps and --walltime."},
     OFF(ckpt_every_steps)},
    {{"checkpoint", "every_minutes", T_DOUBLE, "30", 0, BIG, 0, NULL, "min",
      "Wall-clock minutes between checkpoints (0 = not by time)."},
     OFF(ckpt_every_minutes)},
    {{"checkpoint", "keep", T_INT, "3", 1, 1e6, 0, NULL, "-",
      "Checkpoints kept in DIR/checkpoints; older ones are deleted after a successful write."},
     OFF(ckpt_keep)},
    {{"snapshots", "every", T_DOUBLE, "0", 0, BIG, 0, NULL, "s",
      "Simulated time between particle snapshots DIR/snapshots/snap_<step>.h5 with the index "
      "DIR/snapshots/particles.xdmf for ParaView (0 = none; docs/formats.md)."},
     OFF(snap_every)},
};

/** One key of the scene's table: its definition and where its value is: the field at offset
    in struct scene (the solver's keys, slot -1) or stats_keys[slot] (an engine's key). */
struct entry {
  const struct scene_key_def *d;
  size_t offset;
  int slot;
};

/* The scene's one table: the solver's keys_head, the keys of each engine of stats_engines
   (engine.h) in the order of that list, then keys_tail; built at the first use. */
static struct entry table[SCENE_MAX_KEYS];
static int n_keys;
static const struct scene_key_def *stats_defs[SCENE_STATS_KEYS]; /* the engines' keys by slot */
static int n_stats;

static void add_entry(const struct scene_key_def *d, size_t offset, int slot) {
  if (n_keys == SCENE_MAX_KEYS) die("the scene has more than SCENE_MAX_KEYS keys (scene.h)");
  table[n_keys++] = (struct entry){.d = d, .offset = offset, .slot = slot};
}

static void build_table(void) {
  if (n_keys) return;
  for (size_t i = 0; i < sizeof keys_head / sizeof keys_head[0]; i++)
    add_entry(&keys_head[i].d, keys_head[i].offset, -1);
  int slot = 0;
  for (int e = 0; e < stats_n_engines; e++)
    for (int i = 0; i < stats_engines[e]->n_keys; i++) {
      const struct scene_key_def *d = stats_engines[e]->keys[i];
      if (d->type == SCENE_STRING || d->type == SCENE_LONG)
        die("scene key %s.%s of the %s: an engine's key is an int, a number, a choice or a list",
            d->section, d->name, stats_engines[e]->name);
      if (slot == SCENE_STATS_KEYS)
        die("the engines declare more than SCENE_STATS_KEYS scene keys (scene.h)");
      stats_defs[slot] = d, n_stats = slot + 1;
      add_entry(d, 0, slot++);
    }
  for (size_t i = 0; i < sizeof keys_tail / sizeof keys_tail[0]; i++)
    add_entry(&keys_tail[i].d, keys_tail[i].offset, -1);
  /* each key once, each section in one run of keys (docs/scenes.md has one table per section):
     an engine's key in a section of the solver's or of another engine is a bug */
  for (int k = 0; k < n_keys; k++)
    for (int j = 0; j < k; j++) {
      const struct scene_key_def *a = table[j].d, *b = table[k].d;
      if (strcmp(a->section, b->section)) continue;
      if (!strcmp(a->name, b->name)) die("scene key %s.%s is declared twice", b->section, b->name);
      if (strcmp(table[k - 1].d->section, b->section))
        die("scene key %s.%s: section [%s] is split in the scene's table", b->section, b->name,
            b->section);
    }
}

/** Parser state: where each key was set, and the error count. */
struct parse_state {
  struct scene *s;
  const char *file;
  int line;                            /*!< current line, counted by the reader */
  int where[SCENE_MAX_KEYS];           /*!< 0 = default, >0 = file line, -1 = --set */
  int seen[SCENE_MAX_KEYS];            /*!< given with an invalid value */
  const char *set_text;                /*!< the --set argument being applied */
  const char *set_arg[SCENE_MAX_KEYS]; /*!< the --set argument that gave each key */
  int errors;
  FILE *fp;
  char section[64]; /*!< section of the last header line of the file */
  int section_line; /*!< its line (0: none yet) */
  int section_keys; /*!< keys read in it */
};

/** A key of an earlier version that is gone: a scene, or the scene text of a checkpoint written
    before, may still set it to the value that is now the only behaviour (`keeps`: ignored);
    any other value is refused with `why`. */
struct removed_key {
  const char *section, *name, *keeps, *why;
};

static const struct removed_key removed_keys[] = {
    {"sph", "precision", "double",
     "the force pair loops are in double only: the single-precision pair terms of 'mixed' were "
     "9-13% slower than double and less accurate (docs/performance.md, \"Precision\")"},
};

/** The removed key section.name, or NULL. */
static const struct removed_key *find_removed(const char *section, const char *name) {
  for (size_t i = 0; i < sizeof removed_keys / sizeof removed_keys[0]; i++)
    if (!strcmp(removed_keys[i].section, section) && !strcmp(removed_keys[i].name, name))
      return &removed_keys[i];
  return NULL;
}

static int find_key(const char *section, const char *name) {
  for (int i = 0; i < n_keys; i++)
    if (!strcmp(table[i].d->section, section) && !strcmp(table[i].d->name, name)) return i;
  return -1;
}

static int known_section(const char *section) {
  for (int i = 0; i < n_keys; i++)
    if (!strcmp(table[i].d->section, section)) return 1;
  return 0;
}

static void location(const struct parse_state *ps, int where, char *buf, size_t n) {
  if (where > 0)
    snprintf(buf, n, "%s:%d", ps->file, where);
  else if (where < 0)
    snprintf(buf, n, "--set %s", ps->set_text ? ps->set_text : "");
  else
    snprintf(buf, n, "%s", ps->file);
}

/** Parse text into the value of key k; returns a message on failure, NULL on success. */
static const char *set_value(struct scene *s, int k, const char *text) {
  const struct scene_key_def *K = table[k].d;
  char *end = NULL;
  const int slot = table[k].slot;
  void *field = slot >= 0 ? (void *)&s->stats_keys[slot] : (void *)((char *)s + table[k].offset);
  double v = 0.0;            /* a number, or a choice's index */
  if (K->type == T_STRING) { /* char[512] fields */
    if (strlen(text) >= 512) return "is longer than 511 characters";
    strcpy((char *)field, text);
    return NULL;
  }
  if (K->type == T_LIST) {
    struct scene_list *L = field;
    L->n = 0;
    for (const char *c = text; *c;) {
      while (*c == ' ' || *c == '\t') c++;
      if (!*c) break;
      if (L->n == SCENE_LIST_MAX) return "has more than 8 entries";
      const double x = strtod(c, &end);
      if (end == c) return "is not a comma-separated list of numbers";
      if (!isfinite(x) || x < K->lo || x > K->hi) return "has an entry out of range";
      L->v[L->n++] = x;
      c = end;
      while (*c == ' ' || *c == '\t') c++;
      if (*c == ',')
        c++;
      else if (*c)
        return "is not a comma-separated list of numbers";
    }
    return NULL;
  }
  if (K->type == T_CHOICE) {
    int idx = 0;
    while (K->choices[idx] && strcmp(K->choices[idx], text)) idx++;
    if (!K->choices[idx]) return "is not one of the allowed choices";
    v = idx;
  } else {
    v = strtod(text, &end);
    if (end == text || *end != '\0') return "is not a number";
    if (!isfinite(v)) return "is not finite";
    if (K->type != T_DOUBLE && v != floor(v)) return "is not an integer";
    /* a bound of +-BIG is no bound ("-inf" or "inf" in the range text): any finite value */
    if ((K->lo > -BIG && v < K->lo) || (K->hi < BIG && v > K->hi) ||
        ((K->flags & LO_OPEN) && v == K->lo))
      return "is out of range";
  }
  if (slot >= 0)
    *(struct scene_list *)field = (struct scene_list){.n = 1, .v = {v}};
  else if (K->type == T_INT || K->type == T_CHOICE)
    *(int *)field = (int)v;
  else if (K->type == T_LONG)
    *(long *)field = (long)v;
  else
    *(double *)field = v;
  return NULL;
}

static void range_text(const struct scene_key_def *K, char *buf, size_t n) {
  if (K->type == T_STRING) {
    snprintf(buf, n, "text");
    return;
  }
  if (K->type == T_CHOICE) { /* "a|b|c" */
    size_t m = 0;
    buf[0] = '\0';
    for (int i = 0; K->choices[i] && m < n; i++)
      m += (size_t)snprintf(buf + m, n - m, "%s%s", i ? "|" : "", K->choices[i]);
    return;
  }
  char lo[32] = "-inf", hi[32] = "inf";
  if (K->type == T_LIST) {
    snprintf(buf, n, "up to %d comma-separated numbers >= %g", SCENE_LIST_MAX, K->lo);
    return;
  }
  if (K->lo > -BIG) snprintf(lo, sizeof lo, "%g", K->lo);
  if (K->hi < BIG) snprintf(hi, sizeof hi, "%g", K->hi);
  snprintf(buf, n, "%s%s, %s]", (K->flags & LO_OPEN) ? "(" : "[", lo, hi);
}

static void report_value(struct parse_state *ps, int k, int where, const char *value,
                         const char *why) {
  char loc[600], range[128];
  location(ps, where, loc, sizeof loc);
  range_text(table[k].d, range, sizeof range);
  error_input("%s: key '%s.%s': value '%s' %s (allowed: %s %s)", loc, table[k].d->section,
              table[k].d->name, value, why, range, table[k].d->unit);
  ps->errors++;
}

static int apply(struct parse_state *ps, const char *section, const char *name, const char *value,
                 int where) {
  char loc[600];
  location(ps, where, loc, sizeof loc);
  const int k = find_key(section, name);
  const struct removed_key *gone = k < 0 ? find_removed(section, name) : NULL;
  if (gone && !strcmp(value, gone->keeps)) return 1; /* what the code now always does */
  if (gone) {
    error_input(
        "%s: key '%s.%s' was removed (%s); only '%s' is accepted, for scenes and "
        "checkpoints written before",
        loc, section, name, gone->why, gone->keeps);
    ps->errors++;
    return 0;
  }
  if (k < 0) {
    if (!known_section(section))
      error_input("%s: unknown section [%s] (key '%s')", loc, section, name);
    else
      error_input("%s: unknown key '%s' in section [%s] (see docs/scenes.md)", loc, name, section);
    ps->errors++;
    return 0;
  }
  if (where > 0 && ps->where[k] > 0) {
    error_input("%s: key '%s.%s' is set twice (first at line %d)", loc, section, name,
                ps->where[k]);
    ps->errors++;
    return 0;
  }
  const char *why = set_value(ps->s, k, value);
  if (why) {
    report_value(ps, k, where, value, why);
    ps->seen[k] = 1; /* present, though invalid: do not also report it as missing */
    return 0;
  }
  ps->where[k] = where;
  if (where < 0) ps->set_arg[k] = ps->set_text;
  return 1;
}

static int handler(void *user, const char *section, const char *name, const char *value) {
  struct parse_state *ps = user;
  ps->section_keys++;
  return apply(ps, section, name, value, ps->line);
}

/* The section before a new header (or the end of the file) ends: one without keys is reported
   here (an unknown one with keys is reported at each key). */
static void end_section(struct parse_state *ps) {
  if (ps->section_line <= 0 || !ps->section[0] || ps->section_keys) return;
  if (!known_section(ps->section))
    error_input("%s:%d: unknown section [%s] (no keys; see docs/scenes.md)", ps->file,
                ps->section_line, ps->section);
  else
    error_input(
        "%s:%d: section [%s] has no keys (set a key in it, or remove the header; see "
        "docs/scenes.md)",
        ps->file, ps->section_line, ps->section);
  ps->errors++;
}

/* A section header line ("[name]", optionally followed by a "; comment"): inih ignores what
   follows the ']', so anything else there ("[wall] law = reichardt", "[fluid]junk") is an
   error, as is an empty name. */
static void check_header(struct parse_state *ps, const char *line) {
  while (isspace((unsigned char)*line)) line++;
  if (*line != '[') return;
  const char *close = strchr(line, ']');
  if (!close) return; /* inih reports the syntax error */
  end_section(ps);
  snprintf(ps->section, sizeof ps->section, "%.*s", (int)(close - line - 1), line + 1);
  ps->section_line = ps->line, ps->section_keys = 0;
  if (!ps->section[0]) {
    error_input("%s:%d: empty section name '[]'", ps->file, ps->line);
    ps->errors++;
  }
  const char *rest = close + 1;
  while (isspace((unsigned char)*rest)) rest++;
  if (*rest && *rest != ';') {
    char text[80];
    snprintf(text, sizeof text, "%s", rest);
    text[strcspn(text, "\r\n")] = '\0';
    error_input(
        "%s:%d: text after the section header [%s]: '%s' (a 'key = value' goes on a line of "
        "its own; only a '; comment' may follow the header)",
        ps->file, ps->line, ps->section, text);
    ps->errors++;
  }
}

/* inih's line reader (fgets, which would end the line silently at a NUL byte): a NUL byte is an
   error naming the line. */
static char *reader(char *str, int num, void *stream) {
  struct parse_state *ps = stream;
  int n = 0, c = EOF, nul = 0;
  while (n < num - 1 && (c = getc(ps->fp)) != EOF) {
    if (c == '\0') {
      nul = 1;
      continue;
    }
    str[n++] = (char)c;
    if (c == '\n') break;
  }
  if (n == 0 && !nul) return NULL;
  str[n] = '\0';
  ps->line++;
  if (nul) {
    error_input("%s:%d: a NUL byte in the line (not a text file?)", ps->file, ps->line);
    ps->errors++;
  }
  check_header(ps, str);
  return str;
}

/** Report a geometry or combination problem at the line of the first key involved. */
static void inconsistent(struct parse_state *ps, const char *key, const char *fmt, ...) {
  const char *dot = strchr(key, '.');
  char sec[32];
  snprintf(sec, sizeof sec, "%.*s", (int)(dot - key), key);
  const int k = find_key(sec, dot + 1);
  char loc[600], text[400];
  ps->set_text = k >= 0 ? ps->set_arg[k] : NULL; /* a key given with --set: name the argument */
  location(ps, k >= 0 ? ps->where[k] : 0, loc, sizeof loc);
  ps->set_text = NULL;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  error_input("%s: key '%s': %s", loc, key, text);
  ps->errors++;
}

static int is_multiple(double len, double dr) {
  const double n = len / dr;
  return n >= 1.0 && fabs(n - floor(n + 0.5)) < 1e-9 * n;
}

/* The lattice: particles along x, y (layers plus one) and z fit an int index, and the particle
   count is exact in a double and an int64 id (larger counts would overflow before any
   allocation; check_memory() in sim.c then compares the memory with the machine's). */
static void check_counts(struct parse_state *ps) {
  const struct scene *s = ps->s;
  const double nmax = 0x1p30, nx = s->lx / s->dr, ny = 2.0 * s->delta / s->dr;
  const double nz = s->dim == 3 ? s->lz / s->dr : 1.0;
  if (nx > nmax)
    inconsistent(ps, "domain.lx", "lx / dr = %g / %g: more than 2^30 particles along x", s->lx,
                 s->dr);
  if (ny > nmax)
    inconsistent(ps, "domain.delta", "2 delta / dr = %g / %g: more than 2^30 particle layers",
                 2.0 * s->delta, s->dr);
  if (nz > nmax)
    inconsistent(ps, "domain.lz", "lz / dr = %g / %g: more than 2^30 particles along z", s->lz,
                 s->dr);
  const double n = nx * (ny + 1.0) * nz;
  if (nx <= nmax && ny <= nmax && nz <= nmax && n > 0x1p53)
    inconsistent(ps, "domain.dr",
                 "the domain holds %g particles with this dr, more than %g (keys domain.lx, "
                 "domain.delta, domain.lz, domain.dr)",
                 n, 0x1p53);
}

/** The checks of init.profile = synthetic (validate). */
static void validate_synthetic(struct parse_state *ps) {
  const struct scene *s = ps->s;
  const double sig = s->init_eddy_size * s->delta;
  if (s->dim != 3)
    inconsistent(ps, "init.profile", "synthetic needs a 3-D scene (dimension = %g)",
                 (double)s->dim);
  else if (sig > 0.5 * s->lx || sig > 0.5 * s->lz)
    inconsistent(ps, "init.eddy_size",
                 "eddy size sigma = %g (eddy_size delta) is more than half of min(lx, lz) = %g",
                 sig, fmin(s->lx, s->lz));
  if (!(s->nu > 0.0))
    inconsistent(ps, "fluid.nu", "profile = synthetic needs nu > 0 (got %g)", s->nu);
  /* the field is normalised by sqrt(box / sigma^3 / N): beyond a few times the default N it
     is the same Gaussian field, while the work grows as N times the particles (1e8 eddies
     in qdns180_smoke.ini ran for over 10 minutes at 5.5 GB before this limit) */
  const double box = s->lx * (2.0 * s->delta + 2.0 * sig) * s->lz / (sig * sig * sig);
  if (s->dim == 3 && sig > 0.0 && (double)s->init_eddies > 100.0 * box + 1000.0)
    inconsistent(ps, "init.eddies",
                 "%g synthetic eddies is more than 100 times the box volume / sigma^3 "
                 "(%.4g) plus 1000: no different a field, at a cost that grows with the "
                 "eddies (0 = the box volume / sigma^3)",
                 (double)s->init_eddies, box);
}

/** les.model = profile (validate): the table of les.profile into s->nu_prof, every problem
    named by file and line. A first line (after comments) that is not two numbers is a header. */
static void read_nu_profile(struct parse_state *ps) {
  struct scene *s = ps->s;
  struct nu_profile *t = &s->nu_prof;
  t->n = 0;
  if (!s->les_profile[0]) {
    inconsistent(ps, "les.model", "profile needs les.profile, the file of nu_r / nu against y");
    return;
  }
  FILE *f = fopen(s->les_profile, "r");
  if (!f) {
    inconsistent(ps, "les.profile", "cannot open %s", s->les_profile);
    return;
  }
  char line[512];
  int ln = 0, data = 0, bad = 0; /* lines, lines that are not comments, an error seen */
  while (!bad && fgets(line, sizeof line, f)) {
    ln++;
    char *c = line;
    while (isspace((unsigned char)*c)) c++;
    if (!*c || *c == '#') continue;
    char *end = NULL;
    const double y = strtod(c, &end);
    char *c2 = end;
    while (isspace((unsigned char)*c2) || *c2 == ',') c2++;
    char *end2 = NULL;
    const double v = end == c ? 0.0 : strtod(c2, &end2);
    const int two = end != c && end2 && end2 != c2;
    if (!two && data == 0) { /* the first line that is not a comment: a header */
      data++;
      continue;
    }
    data++;
    const char *why = !two                                ? "is not two numbers 'y nu_r/nu'"
                      : !isfinite(y) || !isfinite(v)      ? "has a value that is not finite"
                      : y < 0.0                           ? "has y < 0"
                      : t->n > 0 && !(y > t->y[t->n - 1]) ? "has y not above the line before"
                      : !(v > -1.0)            ? "has nu_r/nu <= -1 (nu + nu_r not positive)"
                      : t->n == NU_PROFILE_MAX ? "is past the 256 points allowed"
                                               : NULL;
    if (why) {
      inconsistent(ps, "les.profile", "%s line %d %s", s->les_profile, ln, why);
      bad = 1;
    } else {
      t->y[t->n] = y, t->v[t->n] = v, t->n++;
    }
  }
  fclose(f);
  if (!bad && t->n == 0)
    inconsistent(ps, "les.profile", "%s has no points", s->les_profile);
  else if (!bad && (t->y[0] != 0.0 || t->v[0] != 0.0))
    inconsistent(ps, "les.profile",
                 "%s starts at y = %g with nu_r/nu = %g: it must start at the wall, y = 0, with "
                 "nu_r/nu = 0 (the wall shear term takes the molecular viscosity)",
                 s->les_profile, t->y[0], t->v[0]);
}

static void validate(struct parse_state *ps) {
  const struct scene *s = ps->s;
  check_counts(ps);
  if (ps->errors) return; /* the other checks divide by the same numbers */
  const double h = scene_h(s), two_delta = 2.0 * s->delta;
  if (!is_multiple(two_delta, s->dr))
    inconsistent(ps, "domain.delta", "2 delta = %g is not a multiple of dr = %g", two_delta, s->dr);
  else if (two_delta / s->dr < 4.0 - 1e-9)
    inconsistent(ps, "domain.delta", "2 delta = %g must be at least 4 dr = %g", two_delta,
                 4.0 * s->dr);
  if (!is_multiple(s->lx, s->dr))
    inconsistent(ps, "domain.lx", "lx = %g is not a multiple of dr = %g", s->lx, s->dr);
  if (s->lx < 6.0 * h * (1.0 - 1e-12))
    inconsistent(ps, "domain.lx", "lx = %g is shorter than 3 kernel supports (6h = %g)", s->lx,
                 6.0 * h);
  if (s->dim == 3) {
    if (s->lz <= 0.0)
      inconsistent(ps, "domain.lz", "a 3-D scene needs lz > 0 (got %g)", s->lz);
    else if (!is_multiple(s->lz, s->dr))
      inconsistent(ps, "domain.lz", "lz = %g is not a multiple of dr = %g", s->lz, s->dr);
    else if (s->lz < 6.0 * h * (1.0 - 1e-12))
      inconsistent(ps, "domain.lz", "lz = %g is shorter than 3 kernel supports (6h = %g)", s->lz,
                   6.0 * h);
  } else if (s->lz != 0.0) {
    inconsistent(ps, "domain.lz", "lz = %g is given for a 2-D scene (dimension = %g)", s->lz, 2.0);
  }
  if (s->diff_substeps > 1 && s->damper > 0.0)
    inconsistent(ps, "sph.diffusion_substeps",
                 "sub-steps of the volume diffusion (%d) do not go with the acoustic damper "
                 "(sph.acoustic_damper = %g), whose rate takes the whole step's diffusion",
                 s->diff_substeps, s->damper);
  if (s->kernel == KERNEL_C4 && s->dim != 3)
    inconsistent(ps, "sph.kernel", "wendland_c4 needs a 3-D scene (dimension = %g)",
                 (double)s->dim);
  if (s->drive_mode == DRIVE_FLUX && s->u_bulk == 0.0)
    inconsistent(ps, "drive.mode", "flux mode needs drive.u_bulk != 0 (got %g)", s->u_bulk);
  if (s->les != LES_NONE && s->viscous != VISCOUS_VIOLEAU)
    inconsistent(ps, "les.model",
                 "the eddy viscosity needs the variable-viscosity operator: set sph.viscous = "
                 "violeau (thesis Eq. 2.100)");
  if (s->les == LES_PROFILE) read_nu_profile(ps);
  if ((s->les != LES_NONE || s->wall_law != 0) && !(s->nu > 0.0))
    inconsistent(ps, "fluid.nu", "wall laws and LES need nu > 0 (got %g)", s->nu);
  if ((s->les != LES_NONE || s->wall_law != 0) && two_delta < 4.0 * h * (1.0 - 1e-12))
    inconsistent(ps, "domain.delta",
                 "wall laws and LES need 2 delta = %g >= 4h = %g (no particle near both walls)",
                 two_delta, 4.0 * h);
  if (s->nu_start > 0.0 && s->nu_ramp_end < s->nu_ramp_begin)
    inconsistent(ps, "fluid.nu_ramp_end", "the ramp ends (%g) before it begins (%g)",
                 s->nu_ramp_end, s->nu_ramp_begin);
  if (s->t_average_start > s->t_end)
    inconsistent(ps, "output.t_average_start", "averaging start %g is after t_end = %g",
                 s->t_average_start, s->t_end);
  const double target = scene_stats_num(s, &euler_key_target_stderr);
  if (target > 0.0 && !scene_stats_num(s, &euler_key_eulerian))
    inconsistent(ps, "stats.target_stderr",
                 "a convergence target (%g) needs stats.eulerian = 1: it is met on the Eulerian "
                 "profiles",
                 target);
  const double u_tau_ref = scene_stats_num(s, &euler_key_u_tau_ref);
  int levels = 0; /* an engine's y+ levels are given */
  for (int k = 0; k < n_keys; k++)
    levels |= (table[k].d->flags & SCENE_Y_PLUS) && table[k].slot >= 0 &&
              s->stats_keys[table[k].slot].n > 0;
  if (levels && u_tau_ref == 0.0 && (s->drive_mode == DRIVE_FLUX || s->force <= 0.0))
    inconsistent(ps, "stats.u_tau_ref",
                 s->drive_mode == DRIVE_FLUX
                     ? "y+ levels need stats.u_tau_ref > 0 in flux mode (drive.force is only the "
                       "initial force there; u_tau_ref = %g, force = %g)"
                     : "y+ levels need stats.u_tau_ref > 0 unless a positive drive.force gives "
                       "it (u_tau_ref = %g, force = %g)",
                 u_tau_ref, s->force);
  if (s->init_profile == INIT_SYNTHETIC) validate_synthetic(ps);
  if (s->dt_fixed > 0.0 && s->dt_fixed > s->t_end)
    inconsistent(ps, "time.dt", "fixed dt = %g is larger than t_end = %g", s->dt_fixed, s->t_end);
}

/**
 * A relative init.from (or les.profile) written in a scene file names a file next to the scene (a
 * shipped scene finds its shipped state from any working directory); it becomes an absolute path,
 * so scene.used.ini and checkpoints hold a name that does not depend on where the run started. On
 * the command line (--set) a relative path stays relative to the working directory.
 */
static void resolve_path(struct parse_state *ps, const char *scene_path, const char *sec,
                         const char *key, char *value) {
  struct scene *s = ps->s;
  const int k = find_key(sec, key);
  if (ps->where[k] <= 0 || !value[0] || value[0] == '/') return;
  char dir[512], abs_dir[PATH_MAX], joined[PATH_MAX + 520];
  snprintf(dir, sizeof dir, "%s", scene_path);
  char *slash = strrchr(dir, '/');
  if (!slash)
    snprintf(dir, sizeof dir, ".");
  else if (slash == dir)
    dir[1] = '\0'; /* scene in / */
  else
    *slash = '\0';
  if (!realpath(dir, abs_dir)) snprintf(abs_dir, sizeof abs_dir, "%s", dir);
  snprintf(joined, sizeof joined, "%s/%s", abs_dir, value);
  char clean[PATH_MAX];
  const char *name = realpath(joined, clean) ? clean : joined; /* a missing file: said later */
  const char *why = set_value(s, k, name);
  if (why) report_value(ps, k, ps->where[k], name, why);
}

static void resolve_paths(struct parse_state *ps, const char *scene_path) {
  resolve_path(ps, scene_path, "init", "from", ps->s->init_from);
  resolve_path(ps, scene_path, "les", "profile", ps->s->les_profile);
}

/* scene_load and scene_load_text: fp (if not NULL) is read and closed. file_paths: relative
 * paths in the text are relative to the directory of path. */
static int load(struct scene *s, const char *path, FILE *fp, int file_paths, int n_set,
                char *const *set) {
  build_table();
  memset(s, 0, sizeof *s);
  struct parse_state ps = {.s = s, .file = path ? path : "(defaults)"};
  for (int k = 0; k < n_keys; k++)
    if (table[k].d->def && set_value(s, k, table[k].d->def))
      die("bad default of key %s", table[k].d->name);
  if (path) {
    snprintf(s->path, sizeof s->path, "%s", path);
    ps.fp = fp;
    if (!ps.fp) {
      error_input("%s: cannot open scene file", path);
      return CHANSPH_ERR;
    }
    const int rc = ini_parse_stream(reader, &ps, handler, &ps);
    fclose(ps.fp);
    end_section(&ps);
    if (rc > 0 && ps.errors == 0) {
      error_input("%s:%d: syntax error (expected '[section]' or 'key = value')", path, rc);
      ps.errors++;
    }
  }
  for (int i = 0; i < n_set; i++) {
    const char *eq = strchr(set[i], '='), *dot = strchr(set[i], '.');
    if (!eq || !dot || dot > eq) {
      error_input("--set %s: expected section.key=value", set[i]);
      ps.errors++;
      continue;
    }
    char sec[64], name[64];
    snprintf(sec, sizeof sec, "%.*s", (int)(dot - set[i]), set[i]);
    snprintf(name, sizeof name, "%.*s", (int)(eq - dot - 1), dot + 1);
    ps.set_text = set[i];
    apply(&ps, sec, name, eq + 1, -1);
    ps.set_text = NULL;
  }
  for (int k = 0; k < n_keys; k++)
    if ((table[k].d->flags & REQUIRED) && ps.where[k] == 0 && !ps.seen[k]) {
      error_input("%s: missing required key '%s' in section [%s] (%s)", ps.file, table[k].d->name,
                  table[k].d->section, table[k].d->help);
      ps.errors++;
    }
  if (ps.errors == 0 && file_paths) resolve_paths(&ps, path);
  if (ps.errors == 0) validate(&ps);
  return ps.errors ? CHANSPH_ERR : CHANSPH_OK;
}

int scene_load(struct scene *s, const char *path, int n_set, char *const *set) {
  return load(s, path, path ? fopen(path, "r") : NULL, 1, n_set, set);
}

int scene_load_text(struct scene *s, const char *name, const char *text, int n_set,
                    char *const *set) {
  FILE *fp = fmemopen((void *)text, strlen(text), "r");
  if (!fp) die("fmemopen failed for %s", name);
  return load(s, name, fp, 0, n_set, set);
}

int scene_key_count(void) {
  build_table();
  return n_keys;
}

static void value_text(const struct scene *s, int k, char *buf, size_t n);

void scene_key(const struct scene *s, int k, char *name, char *value) {
  build_table();
  snprintf(name, 64, "%s.%s", table[k].d->section, table[k].d->name);
  value_text(s, k, value, SCENE_VALUE_MAX);
}

double scene_h(const struct scene *s) {
  return s->h_over_dr * s->dr;
}

double scene_xi(const struct scene *s) {
  return s->xi > 0.0 ? s->xi : 1000.0 * s->dr / (2.0 * s->delta);
}

int scene_les(const struct scene *s) {
  return s->les != LES_NONE;
}

int scene_strain_lag(const struct scene *s) {
  return s->les == LES_SMAGORINSKY && s->strain == STRAIN_GRADIENT && s->strain_lag;
}

int scene_wall_tau(const struct scene *s) {
  return s->les == LES_SMAGORINSKY || s->wall_law != WALL_LAW_LAMINAR;
}

int scene_bins(const struct scene *s) {
  return s->n_bins > 0 ? s->n_bins : (int)floor(2.0 * s->delta / s->dr + 0.5) - 1;
}

const char *scene_choice(const char *key, int value) {
  build_table();
  const char *dot = strchr(key, '.');
  char sec[32];
  snprintf(sec, sizeof sec, "%.*s", (int)(dot - key), key);
  const int k = find_key(sec, dot + 1);
  if (k < 0 || table[k].d->type != T_CHOICE || value < 0) return "?";
  for (int i = 0; table[k].d->choices[i]; i++)
    if (i == value) return table[k].d->choices[i];
  return "?";
}

const struct scene_list *scene_stats_value(const struct scene *s, const struct scene_key_def *key) {
  build_table();
  for (int k = 0; k < n_keys; k++)
    if (table[k].d == key && table[k].slot >= 0) return &s->stats_keys[table[k].slot];
  die("scene key %s.%s is not an engine's key", key->section, key->name);
}

double scene_stats_num(const struct scene *s, const struct scene_key_def *key) {
  return scene_stats_value(s, key)->v[0];
}

const struct scene_key_def *const *scene_stats_defs(int *n) {
  build_table();
  *n = n_stats;
  return stats_defs;
}

static void value_text(const struct scene *s, int k, char *buf, size_t n) {
  const struct scene_key_def *K = table[k].d;
  const int slot = table[k].slot;
  const void *field = slot >= 0 ? (const void *)&s->stats_keys[slot]
                                : (const void *)((const char *)s + table[k].offset);
  /* an engine's number is the one entry of its value */
  const double num = slot >= 0 ? s->stats_keys[slot].v[0] : 0.0;
  switch (K->type) {
    case T_INT:
      snprintf(buf, n, "%d", slot >= 0 ? (int)num : *(const int *)field);
      break;
    case T_LONG:
      snprintf(buf, n, "%ld", *(const long *)field);
      break;
    case T_DOUBLE: { /* the shortest text that reads back to the same double */
      const double v = slot >= 0 ? num : *(const double *)field;
      for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, n, "%.*g", digits, v);
        if (strtod(buf, NULL) == v) break;
      }
      break;
    }
    case T_LIST: {
      const struct scene_list *L = field;
      size_t m = 0;
      buf[0] = '\0';
      for (int i = 0; i < L->n && m < n; i++)
        m += (size_t)snprintf(buf + m, n - m, "%s%.17g", i ? "," : "", L->v[i]);
      break;
    }
    case T_STRING:
      snprintf(buf, n, "%s", (const char *)field);
      break;
    case T_CHOICE: {
      char key[80];
      snprintf(key, sizeof key, "%s.%s", K->section, K->name);
      snprintf(buf, n, "%s", scene_choice(key, slot >= 0 ? (int)num : *(const int *)field));
      break;
    }
  }
}

char *scene_text(const struct scene *s) {
  build_table();
  size_t cap = 8192, len = 0;
  char *out = mem_alloc(1, cap, "scene text");
  out[0] = '\0';
  const char *section = "";
  for (int k = 0; k < n_keys; k++) {
    char val[600], line[800];
    value_text(s, k, val, sizeof val);
    int m = 0;
    if (strcmp(section, table[k].d->section)) {
      section = table[k].d->section;
      m = snprintf(line, sizeof line, "%s[%s]\n", len ? "\n" : "", section);
    }
    m += snprintf(line + m, sizeof line - m, "%s = %s\n", table[k].d->name, val);
    if (len + (size_t)m + 1 > cap) {
      cap *= 2;
      out = mem_realloc(out, cap, 1, "scene text");
    }
    memcpy(out + len, line, (size_t)m + 1);
    len += (size_t)m;
  }
  return out;
}

void scene_write_doc(FILE *f) {
  build_table();
  fprintf(f,
          "# Scene reference\n\n"
          "<!-- generated by `build/chansph scene-doc`; do not edit, edit solver/scene.c or the "
          "key table of the engine in stats/ -->\n\n"
          "A scene is an INI file (parsed with inih). Comments start with `#` or `;` at the "
          "start of a line, or `;` after a value or a section header.\n"
          "Any key can be overridden on the command line with `--set section.key=value`.\n"
          "Unknown keys and sections (also an empty `[]` or a section without keys, known or "
          "not), a NUL byte, text "
          "after a section header (`[wall] law = x`: a key goes on a line of its own), keys "
          "set twice, values out of range and inconsistent geometry are errors that name the "
          "file, line and key; so is a domain of more than 2^30 particles along a direction, "
          "or a scene whose particles, statistics (`output.n_bins` with the per-window records of "
          "the budgets, `correlations.*`, `lagrangian.*`), synthetic eddies and `init.from` "
          "state (from its dimension `particle`, before it is read) would need more than 80%% "
          "of the machine's memory, summed over the MPI ranks of the node (the estimate, a "
          "lower bound, is checked before anything is allocated and printed in the log).\n"
          "The physical keys have finite ranges (accelerations within 1e12 m/s^2, speeds within "
          "1e8 m/s, viscosities up to 1e6 m^2/s): beyond them there is no channel flow, and the "
          "time step would go to zero. A time step that is zero, subnormal or too small to "
          "advance the time (from the state's forces) stops the run as a numerical failure "
          "(exit 3, naming the limit), not a run that checkpoints without advancing.\n"
          "The fully resolved scene (defaults included) is written to `DIR/scene.used.ini` "
          "and into the `scene` attribute of `stats.nc`.\n");
  const char *section = "";
  for (int k = 0; k < n_keys; k++) {
    if (strcmp(section, table[k].d->section)) {
      section = table[k].d->section;
      fprintf(f,
              "\n## [%s]\n\n| key | default | allowed | unit | meaning |\n|---|---|---|---|---|\n",
              section);
    }
    char range[128];
    range_text(table[k].d, range, sizeof range);
    for (char *c = range; *c; c++)
      if (*c == '|') *c = '/';
    fprintf(f, "| `%s` | %s | %s | %s | %s |\n", table[k].d->name,
            table[k].d->def ? (table[k].d->def[0] ? table[k].d->def : "(empty)") : "**required**",
            range, table[k].d->unit, table[k].d->help);
  }
}
