/*
 * test_damper: the acoustic damper (solver/term_damper.h, sph.acoustic_damper = alpha) against
 * the damping rate of a sound wave in a fluid with bulk viscosity zeta = alpha rho0 c0 h.
 *
 * A 2-D channel of height 1 at rest except for the standing wall-normal sound wave
 * v = 0.01 c0 sin(4 pi y) (init.profile = wave; k = 4 pi, period 2 pi / (c0 k)). Its acoustic
 * energy E = sum m (|u|^2 / 2 + e(rho)) decays as exp(-2 gamma t); the bulk viscosity adds
 * gamma_b = (zeta / rho0) k^2 / 2 = alpha c0 h k^2 / 2 to whatever the scheme's own terms (volume
 * diffusion, viscosity, walls) give. The rate is the least-squares slope of ln E over 2-12
 * wave periods; the test runs alpha = 0, 0.05 and 0.1 and requires the rate added by the
 * damper to be gamma_b within 15% for both, so the coefficient, the sign and the use of the
 * density rate are checked, not only that something damps. Likewise the delta-SPH form of the
 * volume diffusion (sph.diffusion = delta_sph), delta h c0 lap rho in the continuum, must add
 * delta h c0 k^2 / 2 to the rate without volume diffusion; and the test prints the delta that
 * the default (Ferrand) diffusion is worth on this wave. Every run must stay healthy.
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <string.h>

#include "health.h"
#include "sim.h"

/** Internal energy per unit mass of the Tait equation (p_background = 0). */
static double internal_energy(const struct eos *e, double rho) {
  const double B = e->rho0 * e->c0 * e->c0 / e->zeta, r0 = e->rho0, z = e->zeta;
  return B * (pow(rho / r0, z - 1.0) - 1.0) / ((z - 1.0) * r0) - B * (1.0 / r0 - 1.0 / rho);
}

static double energy(const struct sim *S) {
  double E = 0.0;
  const struct particles *P = &S->P;
  for (size_t a = 0; a < P->n; a++) { /* serial, fixed order */
    if (P->kind[a] != KIND_FLUID) continue;
    E += P->m[a] *
         (0.5 * (P->u[a] * P->u[a] + P->v[a] * P->v[a]) + internal_energy(&S->M.e, P->rho[a]));
  }
  return E;
}

/** The decay rate gamma of the wave's amplitude with the scheme settings k1 and k2 (scene
    --set strings); h receives the kernel's h. */
static int rate(const char *label, char *k1, char *k2, double *gamma, double *h) {
  char *set[] = {"domain.dimension=2",
                 "domain.delta=0.5",
                 "domain.lx=0.2",
                 "domain.dr=0.02",
                 "fluid.nu=1e-4",
                 "fluid.c0=10",
                 "init.profile=wave",
                 "init.wave=0.1",
                 "time.t_end=0.6",
                 k1,
                 k2};
  struct scene sc;
  if (scene_load(&sc, NULL, sizeof set / sizeof set[0], set)) return 1;
  struct sim S;
  if (sim_init(&S, &sc)) return 1;
  *h = S.M.h;
  const double period = 2.0 * M_PI / (sc.c0 * 4.0 * M_PI);
  double st = 0, sl = 0, stt = 0, stl = 0;
  int n = 0;
  while (!sim_done(&S)) {
    sim_step(&S);
    struct health_report rep;
    if (health_check(&S.M, &S.P, S.step, S.t, &rep)) {
      printf("%s: stopped by the health check: %s\n", label, rep.what);
      sim_free(&S);
      return 1;
    }
    if (S.t < 2.0 * period || S.t > 12.0 * period) continue;
    const double l = log(energy(&S)); /* E = kinetic + internal: its oscillation is small */
    st += S.t, sl += l, stt += S.t * S.t, stl += S.t * l, n++;
  }
  *gamma = -0.5 * (n * stl - st * sl) / (n * stt - st * st);
  printf("%s: %d samples over 2-12 periods, gamma = %.4f 1/s\n", label, n, *gamma);
  sim_free(&S);
  return 0;
}

/** PASS if the rate added, got, is want within 15%. */
static int near(const char *what, double got, double want) {
  const double err = got / want - 1.0;
  printf("%s: added rate %.4f 1/s, theory %.4f 1/s: %+.1f%% (tol 15%%)\n", what, got, want,
         100.0 * err);
  return !(fabs(err) <= 0.15);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  double g0, g1, g2, gn, gd, h;
  char none[] = "sph.acoustic_damper=0", a05[] = "sph.acoustic_damper=0.05";
  char a10[] = "sph.acoustic_damper=0.1", nodiff[] = "sph.xi=1e300";
  char dsph[] = "sph.diffusion=delta_sph", d10[] = "sph.delta=0.1", same[] = "time.cfl=0.8";
  int fail = rate("reference", none, same, &g0, &h) || rate("alpha = 0.05", a05, same, &g1, &h) ||
             rate("alpha = 0.1", a10, same, &g2, &h) ||
             rate("no volume diffusion", nodiff, same, &gn, &h) ||
             rate("delta-SPH, delta = 0.1", dsph, d10, &gd, &h);
  if (!fail) {
    /* bulk viscosity zeta / rho0 = alpha c0 h and the delta-SPH diffusion delta h c0 lap rho
       both damp a sound wave of wavenumber k at (diffusivity) k^2 / 2 */
    const double k = 4.0 * M_PI, c0 = 10.0, unit = c0 * h * k * k / 2.0;
    fail |= near("acoustic damper, alpha = 0.05", g1 - g0, 0.05 * unit);
    fail |= near("acoustic damper, alpha = 0.1", g2 - g0, 0.1 * unit);
    fail |= near("delta-SPH diffusion, delta = 0.1", gd - gn, 0.1 * unit);
    printf(
        "the default volume diffusion (xi = 1000 dr / (2 delta)) damps this wave as a "
        "delta-SPH diffusion of delta = %.4f would\n",
        (g0 - gn) / unit);
  }
  printf("%s\n", fail ? "FAILED" : "PASSED");
  MPI_Finalize();
  return fail;
}
