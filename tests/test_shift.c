/*
 * test_shift: particle shifting (solver/shift.c, docs/theory.md "Particle shifting").
 * 1. The initial lattice of a channel at rest (2-D and 3-D) is an equilibrium of the shift,
 *    walls included: the shift of every particle is below 1e-12 dr, and after 20 steps with
 *    shifting on no particle has moved by more than 1e-12 dr.
 * 2. A 2-D channel at rest whose particles were displaced from the lattice by up to 0.2 dr per
 *    component (a hash of the id, the same on any machine), with the density rho0 of those
 *    positions: after 50 steps the spread (std / mean) of the nearest-neighbour distance is
 *    below half its initial value with shifting (measured 0.35 with the default coefficient)
 *    and above 0.7 of it without (0.83: the background pressure alone orders slowly).
 * 3. The Taylor correction of the velocities (sph.shift_velocity = taylor) is exact for a
 *    velocity linear in y on a disordered arrangement, away from the walls.
 * 4. The conservative momentum transport (sph.shift_velocity = conservative) of a random
 *    velocity field on a disordered 3-D arrangement conserves momentum between fluid
 *    particles: with the velocities zero within 2h of the walls (where the wall takes its
 *    part), |sum_a m_a du_a| is below 1e-12 of sum_a m_a |du_a| in each component, du != 0.
 */
#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>

#include "shift.h"
#include "sim.h"
#include "test_hash.h"

/* Relative spread (standard deviation over mean) of the nearest-neighbour distance of the
   fluid particles. */
static double nn_spread(const struct sim *S) {
  const struct particles *P = &S->P;
  const struct model *M = &S->M;
  double s1 = 0.0, s2 = 0.0;
  size_t n = 0;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    const int32_t *nl = S->nb.list + a * (size_t)S->nb.stride;
    double rmin = INFINITY;
    for (int j = 0; j < S->nb.count[a]; j++) {
      const int32_t b = nl[j];
      const double dx = nbr_wrap(P->x[a] - P->x[b], M->lx), dy = P->y[a] - P->y[b];
      const double dz = M->dim == 3 ? nbr_wrap(P->z[a] - P->z[b], M->lz) : 0.0;
      rmin = fmin(rmin, sqrt(dx * dx + dy * dy + dz * dz));
    }
    s1 += rmin, s2 += rmin * rmin, n++;
  }
  const double mean = s1 / n;
  return sqrt(fmax(0.0, s2 / n - mean * mean)) / mean;
}

/* Part 1: the lattice at rest stays where it is. */
static int lattice_at_rest(const char *name, char **set, int nset) {
  struct scene sc;
  if (scene_load(&sc, NULL, nset, set)) return 1;
  struct sim S;
  if (sim_init(&S, &sc)) return 1;
  struct particles *P = &S.P;
  const double dr = sc.dr;
  double *sx = S.scratch[0], *sz = S.scratch[1], smax = 0.0, moved = 0.0;
  shift_compute(&S.M, P, &S.nb, sx, P->shift_dy, sz);
  for (size_t a = 0; a < P->n; a++)
    smax = fmax(smax, sqrt(sx[a] * sx[a] + P->shift_dy[a] * P->shift_dy[a] + sz[a] * sz[a]));
  for (int k = 0; k < 20; k++) sim_step(&S);
  for (size_t a = 0; a < P->n; a++) { /* lattice: x = (i + 1/2) dr, y = j dr, z = (k + 1/2) dr */
    const double fx = P->x[a] / dr - 0.5, fy = P->y[a] / dr;
    moved = fmax(moved, fmax(fabs(fx - round(fx)), fabs(fy - round(fy))) * dr);
    if (sc.dim == 3) moved = fmax(moved, fabs(P->z[a] / dr - 0.5 - round(P->z[a] / dr - 0.5)) * dr);
  }
  printf(
      "%s: lattice at rest: largest shift %.3e dr, largest displacement after 20 steps %.3e dr "
      "(tol 1e-12)\n",
      name, smax / dr, moved / dr);
  sim_free(&S);
  return !(smax <= 1e-12 * dr && moved <= 1e-12 * dr);
}

/* A channel of the scene `set` whose fluid particles are displaced from the lattice by up to
   0.2 dr per component (a hash of the id, the same on any machine); 0 on success. The caller
   sets the velocities and calls sim_restored for the neighbours of these positions. */
static int disordered(char **set, int nset, struct scene *sc, struct sim *S) {
  if (scene_load(sc, NULL, nset, set) || sim_init(S, sc)) return 1;
  struct particles *P = &S->P;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    P->x[a] += 0.2 * sc->dr * hash_unit(P->id[a], 0);
    P->y[a] += 0.2 * sc->dr * hash_unit(P->id[a], 1);
    if (sc->dim == 3) P->z[a] += 0.2 * sc->dr * hash_unit(P->id[a], 2);
  }
  return 0;
}

/* Part 2: the spread of the nearest-neighbour distance after 50 steps from a perturbed
   lattice, relative to the initial one. */
static int perturbed(char **set, int nset, double *ratio) {
  struct scene sc;
  struct sim S;
  if (disordered(set, nset, &sc, &S)) return 1;
  struct particles *P = &S.P;
  /* neighbours, kernel sums and wall values of the perturbed positions; the density stays rho0
     (the stored kernel sums are those of these positions), so only the arrangement is off */
  sim_restored(&S);
  for (size_t a = 0; a < P->n; a++) P->ksum[a] = S.ksum_new[a];
  const double d0 = nn_spread(&S);
  for (int k = 0; k < 50; k++) sim_step(&S);
  *ratio = nn_spread(&S) / d0;
  printf("  %s: nearest-neighbour spread %.4f -> %.4f after 50 steps (ratio %.3f)\n", set[nset - 1],
         d0, d0 * *ratio, *ratio);
  sim_free(&S);
  return 0;
}

/* Part 3: the Taylor correction (sph.shift_velocity = taylor) of a velocity field linear in y,
   u = A y, w = B y, on a disordered 3-D arrangement: the first-order corrected gradient is
   exact for it, so du = A delta y, dv = 0, dw = B delta y to round-off for every particle
   more than 2h from the walls (closer, the wall vertices at rest break the linear field). */
static int taylor_linear(char **set, int nset) {
  struct scene sc;
  struct sim S;
  if (disordered(set, nset, &sc, &S)) return 1;
  struct particles *P = &S.P;
  const double A = 3.0, B = -1.5;
  for (size_t a = 0; a < P->n; a++)
    if (P->kind[a] == KIND_FLUID) P->u[a] = A * P->y[a], P->v[a] = 0.0, P->w[a] = B * P->y[a];
  sim_restored(&S); /* neighbours and ghosts of these positions and velocities */
  double *sx = S.scratch[0], *sz = S.scratch[1], *du = S.scratch[2], *dv = S.scratch[3];
  double *dw = S.scratch[4], worst = 0.0, largest = 0.0;
  shift_compute(&S.M, P, &S.nb, sx, P->shift_dy, sz);
  shift_velocity(&S.M, P, &S.nb, sx, P->shift_dy, sz, du, dv, dw);
  int n = 0;
  for (size_t a = 0; a < P->n; a++) {
    const double y = P->y[a];
    if (P->kind[a] != KIND_FLUID || y < 2.0 * S.M.h || y > 2.0 * sc.delta - 2.0 * S.M.h) continue;
    const double dy = P->shift_dy[a];
    worst = fmax(worst, fmax(fabs(du[a] - A * dy), fmax(fabs(dv[a]), fabs(dw[a] - B * dy))));
    largest = fmax(largest, fabs(A * dy));
    n++;
  }
  printf(
      "Taylor correction of u = %g y, w = %g y on a disordered lattice: %d particles, largest "
      "|du - A dy| etc. %.3e (largest du %.3e; tol 1e-10 of it)\n",
      A, B, n, worst, largest);
  sim_free(&S);
  return !(n > 0 && largest > 0.0 && worst <= 1e-10 * largest);
}

/* Part 4: the conservative transport (sph.shift_velocity = conservative) moves momentum between
   fluid particles only: sum_a m_a du_a = 0 to round-off for any velocity field. */
static int conservative_sum_zero(char **set, int nset) {
  struct scene sc;
  struct sim S;
  if (disordered(set, nset, &sc, &S)) return 1;
  struct particles *P = &S.P;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    P->u[a] = 1.0 + hash_unit(P->id[a], 3), P->v[a] = 0.3 * hash_unit(P->id[a], 4);
    P->w[a] = 0.3 * hash_unit(P->id[a], 5);
    const double y = P->y[a]; /* the walls' part acts where u_a != 0: none there */
    if (y < 2.0 * S.M.h || y > 2.0 * sc.delta - 2.0 * S.M.h) P->u[a] = P->v[a] = P->w[a] = 0.0;
  }
  sim_restored(&S);
  double *du = S.scratch[2], *dv = S.scratch[3], *dw = S.scratch[4];
  shift_compute(&S.M, P, &S.nb, P->shift_dx, P->shift_dy, P->shift_dz);
  shift_velocity_conservative(&S.M, P, &S.nb, du, dv, dw);
  double sum[3] = {0, 0, 0}, mag[3] = {0, 0, 0};
  for (size_t a = 0; a < P->n; a++) {
    const double d[3] = {du[a], dv[a], dw[a]};
    for (int c = 0; c < 3; c++) sum[c] += P->m[a] * d[c], mag[c] += P->m[a] * fabs(d[c]);
  }
  int bad = 0;
  for (int c = 0; c < 3; c++) bad |= !(mag[c] > 0.0 && fabs(sum[c]) <= 1e-12 * mag[c]);
  printf(
      "conservative transport on a disordered lattice: |sum m du| / sum m |du| = %.3e, %.3e, "
      "%.3e (tol 1e-12)\n",
      fabs(sum[0]) / mag[0], fabs(sum[1]) / mag[1], fabs(sum[2]) / mag[2]);
  sim_free(&S);
  return bad;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int fail = 0;
  char *s2[] = {"domain.dimension=2", "domain.lx=1",   "domain.dr=0.05", "fluid.nu=0.1",
                "fluid.c0=10",        "drive.force=0", "time.t_end=1",   "sph.shifting=fickian"};
  char *s3[] = {"domain.dimension=3", "domain.lx=0.5", "domain.lz=0.4",
                "domain.dr=0.05",     "fluid.nu=0.1",  "fluid.c0=10",
                "drive.force=0",      "time.t_end=1",  "sph.shifting=fickian"};
  fail |= lattice_at_rest("2-D", s2, 8);
  fail |= lattice_at_rest("3-D", s3, 9);
  char *p[] = {"domain.dimension=2", "domain.lx=1",   "domain.dr=0.05", "fluid.nu=0.1",
               "fluid.c0=10",        "drive.force=0", "time.t_end=10",  "sph.shifting=none"};
  double r_none, r_shift;
  fail |= perturbed(p, 8, &r_none);
  p[7] = "sph.shifting=fickian";
  fail |= perturbed(p, 8, &r_shift);
  printf(
      "perturbed lattice (2-D, 0.2 dr): spread ratio %.3f with shifting, %.3f without "
      "(want < 0.5 with, > 0.7 without)\n",
      r_shift, r_none);
  fail |= !(r_shift < 0.5 && r_none > 0.7);
  char *t3[] = {"domain.dimension=3",   "domain.lx=0.5",
                "domain.lz=0.4",        "domain.dr=0.05",
                "fluid.nu=0.1",         "fluid.c0=10",
                "drive.force=0",        "time.t_end=1",
                "sph.shifting=fickian", "sph.shift_velocity=taylor"};
  fail |= taylor_linear(t3, 10);
  t3[9] = "sph.shift_velocity=conservative";
  fail |= conservative_sum_zero(t3, 10);
  printf(fail ? "FAIL\n" : "PASS\n");
  MPI_Finalize();
  return fail;
}
