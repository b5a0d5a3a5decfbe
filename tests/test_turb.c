/*
 * test_turb: the turbulence model terms of solver/turb.c and sph.c against values computed by
 * hand (closed forms) on small particle sets:
 *  - rate of strain from the first-order corrected gradient (thesis Eq. 2.88-2.90) on a random
 *    cloud of 40 neighbours is exact for a linear velocity field: S = (2 S:S)^(1/2) of the
 *    field's gradient to 1e-12 (2-D and 3-D, including compressible and rotational parts), and
 *    so is the Q criterion (|Omega|^2 - |S|^2)/2 = -C_ij C_ji / 2;
 *  - van Driest damping (Eq. 5.50, sign corrected) at y+ = 0, A+, 10^6;
 *  - in a 3-D channel with the linear shear u = g (y - delta), away from the walls (d >= 2h):
 *    Smagorinsky nu_r = (C_S Delta_G)^2 |g| and Yoshizawa k_r = 2 C_Y (Delta_G g)^2 (Eq. 5.46-
 *    5.49, no damping) to 1e-10; the pressure seen by the forces gains 2/3 rho k_r (Eq. 5.42);
 *    with damping, nu_r = (C_S Delta_G (1 - exp(-y+/A+)))^2 |g| with y+ from the wall stress at
 *    the foot of the nearest wall;
 *  - the chunked model of les.strain_lag (turb_model_chunk) on corrected-gradient sums formed
 *    here gives the unlagged pass's nu_r and k_r to 1e-12, and the same bits whatever a
 *    particle's place in a chunk (chunks of 128 from 0 against chunks of 37 from 5);
 *  - the Violeau-Issa strain (Eq. 5.48 solved for S) away from the walls equals
 *    |g| (-(1/(rho_a gamma_a)) sum_b V_b (rho_a + rho_b)/2 y_ab^2 F_ab)^(1/2), summed here;
 *  - the wall-law stress of every near-wall particle is rho u_tau(U, max(d, dr))^2 along its
 *    velocity, with u_tau from walllaw.h (Reichardt);
 *  - les.model = profile: the table of a file with comments, a header and a blank line at and
 *    between its points and beyond the last, and nu_r = nu g(d / delta) of every fluid particle,
 *    no k_r, the largest nu + nu_r;
 *  - Violeau's wall moment table (sph.c): -1 at the wall (half of the full-space -2) to 1e-8
 *    and 0 at q = 2.
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sim.h"
#include "turb.h"
#include "wall.h"

static double lcg(unsigned long long *s) {
  *s = *s * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(*s >> 11) * 0x1.0p-53;
}

/** Corrected-gradient strain of a random cloud for a linear field v = C r. */
static int check_strain_cloud(int dim) {
  const struct kernel K = kernel_make(dim, 1.0);
  const double C[3][3] = {{0.3, 1.7, -0.4}, {-0.9, 0.2, 0.6}, {0.5, -1.1, -0.5}};
  unsigned long long seed = 12345;
  double A[6] = {0}, B[9] = {0};
  for (int j = 0; j < 40; j++) {
    double r[3] = {0, 0, 0}, rr;
    do {
      for (int k = 0; k < dim; k++) r[k] = 4.0 * lcg(&seed) - 2.0;
      rr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    } while (rr >= 2.0 || rr < 1e-3);
    const double vf = (0.5 + lcg(&seed)) * kernel_f(&K, rr); /* volume x F, r = r_a - r_b */
    double du[3];                                            /* v_b - v_a = -C r */
    for (int i = 0; i < 3; i++) du[i] = -(C[i][0] * r[0] + C[i][1] * r[1] + C[i][2] * r[2]);
    A[0] -= vf * r[0] * r[0], A[1] -= vf * r[0] * r[1], A[2] -= vf * r[0] * r[2];
    A[3] -= vf * r[1] * r[1], A[4] -= vf * r[1] * r[2], A[5] -= vf * r[2] * r[2];
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) B[3 * i + k] += vf * du[i] * r[k];
  }
  double s2 = 0.0;
  for (int i = 0; i < dim; i++)
    for (int k = 0; k < dim; k++) s2 += 0.5 * (C[i][k] + C[k][i]) * (C[i][k] + C[k][i]);
  const double want = sqrt(s2), got = turb_strain_gradient(dim, A, B);
  const double err = fabs(got - want) / want;
  printf("strain, corrected gradient, %d-D cloud of 40: S = %.15g, exact %.15g, rel. error %.2e\n",
         dim, got, want, err);
  double qwant = 0.0; /* Q = (W:W - S:S)/2 = -C_ij C_ji / 2 */
  for (int i = 0; i < dim; i++)
    for (int k = 0; k < dim; k++) qwant -= 0.5 * C[i][k] * C[k][i];
  const double qgot = turb_q_gradient(dim, A, B), qerr = fabs(qgot - qwant) / fabs(qwant);
  printf("Q criterion, same cloud: Q = %.15g, exact %.15g, rel. error %.2e\n", qgot, qwant, qerr);
  return err > 1e-12 || qerr > 1e-12;
}

/** Whether two doubles differ in their bits (NaN included). */
static int pass_differs(double x, double y) {
  return memcmp(&x, &y, sizeof x) != 0;
}

static int check_channel(int damping, int strain) {
  char dmp[32], str[48];
  snprintf(dmp, sizeof dmp, "les.van_driest=%d", damping);
  snprintf(str, sizeof str, "les.strain=%s", strain ? "violeau_issa" : "gradient");
  char *set[] = {"domain.dimension=3",
                 "domain.lx=1",
                 "domain.lz=0.5",
                 "domain.dr=0.05",
                 "domain.delta=0.5",
                 "fluid.nu=1e-3",
                 "fluid.c0=10",
                 "time.t_end=1",
                 "sph.viscous=violeau",
                 "les.model=smagorinsky",
                 "les.cs=0.1",
                 "les.cy=0.05",
                 "wall.law=reichardt",
                 dmp,
                 str};
  struct scene sc;
  if (scene_load(&sc, NULL, sizeof set / sizeof set[0], set)) return 1;
  struct sim S;
  if (sim_init(&S, &sc)) return 1;
  struct particles *P = &S.P;
  const struct model *M = &S.M;
  const double g = 2.5, two_h = 2.0 * M->h;
  for (size_t a = 0; a < P->n; a++)
    if (P->kind[a] == KIND_FLUID) P->u[a] = g * (P->y[a] - sc.delta);
  /* the pressure the forces see before the model adds 2/3 rho k_r */
  double pr2_before = 0.0;
  size_t probe = 0;
  for (size_t a = 0; a < P->n; a++)
    if (P->kind[a] == KIND_FLUID && fabs(P->y[a] - sc.delta) < 0.5 * sc.dr) probe = a;
  pr2_before = P->pr2[probe];
  turb_wall_law(M, P, &S.nb, &S.W); /* one rank: no ghosts to refresh */
  turb_eddy_viscosity(M, P, &S.nb, &S.W);
  if (M->cy > 0.0) sph_kr_pressure(M, P, &S.nb, &S.W);
  double worst_nu = 0.0, worst_k = 0.0, worst_tau = 0.0;
  int n_inner = 0, n_wall = 0;
  const struct wall_law_def *L = &M->law;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    const double y = P->y[a], d = fmin(y, M->ly - y);
    const int wall = M->ly - y < y;
    if (d < two_h) { /* wall-law stress of the particle */
      const double U = fabs(P->u[a]);
      const double ut = wall_law_utau(L, U, fmax(d, M->wall_dmin), M->nu);
      const double want = P->rho[a] * ut * ut * (P->u[a] > 0 ? 1 : -1);
      const double err = fabs(P->twx[a] - want) / fabs(want);
      if (err > worst_tau) worst_tau = err;
      n_wall++;
      continue;
    }
    double damp = 1.0;
    if (damping) {
      double rs, tx, tz;
      sph_wall_stress(M, &S.W, wall, P->x[a], P->z[a], &rs, &tx, &tz);
      const double yp = d * sqrt(sqrt(tx * tx + tz * tz) / rs) / M->nu;
      damp = 1.0 - exp(-yp / M->a_plus);
    }
    double Sv = fabs(g);
    if (strain) { /* Violeau-Issa: the pair sum by hand */
      double sum = 0.0;
      const int32_t *nl = S.nb.list + a * (size_t)S.nb.stride;
      for (int j = 0; j < S.nb.count[a]; j++) {
        const int32_t b = nl[j];
        const double dx = nbr_wrap(P->x[a] - P->x[b], M->lx), dy = P->y[a] - P->y[b];
        const double dz = nbr_wrap(P->z[a] - P->z[b], M->lz);
        const double du = P->u[a] - P->u[b];
        sum -= P->m[b] / P->rho[b] * 0.5 * (P->rho[a] + P->rho[b]) * du * du *
               kernel_f(&M->k, sqrt(dx * dx + dy * dy + dz * dz));
      }
      Sv = sqrt(sum / (P->rho[a] * P->gam[a]));
    }
    const double l = M->cs * M->delta_g * damp;
    const double nur = l * l * Sv, kr = 2.0 * sc.cy * pow(M->delta_g * damp * Sv, 2);
    const double e1 = fabs(P->nur[a] - nur) / nur, e2 = fabs(P->kr[a] - kr) / kr;
    if (e1 > worst_nu) worst_nu = e1;
    if (e2 > worst_k) worst_k = e2;
    n_inner++;
  }
  /* les.strain_lag's path, turb_model_chunk, on the corrected-gradient sums summed here: the
     same nu_r and k_r (to 1e-12 of the unlagged pass above) in chunks of TURB_CHUNK from 0, and
     the same bits in chunks of 37 from 5 (a particle's result may not depend on its place in a
     chunk: vector body or remainder) */
  int chunk_fail = 0;
  double worst_chunk = 0.0;
  if (!strain) {
    double *nur1 = calloc(P->n, sizeof(double)), *kr1 = calloc(P->n, sizeof(double));
    double *nur2 = calloc(P->n, sizeof(double)), *kr2 = calloc(P->n, sizeof(double));
    static double ab[15][TURB_CHUNK];
    for (int pass = 0; pass < 2; pass++) {
      const size_t first = pass ? 5 : 0, len = pass ? 37 : TURB_CHUNK;
      double *nr = pass ? nur2 : nur1, *kk = pass ? kr2 : kr1;
      for (size_t a0 = first; a0 < P->n; a0 += len) {
        const int n = (int)(a0 + len < P->n ? len : P->n - a0);
        for (int i = 0; i < n; i++) {
          const size_t a = a0 + (size_t)i;
          for (int k = 0; k < 15; k++) ab[k][i] = 0.0;
          if (P->kind[a] != KIND_FLUID) continue;
          const int32_t *nl = S.nb.list + a * (size_t)S.nb.stride;
          for (int j = 0; j < S.nb.count[a]; j++) {
            const int32_t b = nl[j];
            const double r[3] = {nbr_wrap(P->x[a] - P->x[b], M->lx), P->y[a] - P->y[b],
                                 nbr_wrap(P->z[a] - P->z[b], M->lz)};
            const double dv[3] = {P->u[b] - P->u[a], P->v[b] - P->v[a], P->w[b] - P->w[a]};
            const double vf = P->m[b] / P->rho[b] *
                              kernel_f(&M->k, sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]));
            const int sym[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
            for (int k = 0; k < 6; k++) ab[k][i] -= vf * r[sym[k][0]] * r[sym[k][1]];
            for (int k = 0; k < 9; k++) ab[6 + k][i] += vf * dv[k / 3] * r[k % 3];
          }
        }
        turb_model_chunk(M, P, &S.W, a0, n, (const double(*)[TURB_CHUNK])ab, nr + a0, kk + a0);
      }
    }
    for (size_t a = 0; a < P->n; a++) {
      if (a < 5) continue; /* the second pass starts at 5 */
      if (pass_differs(nur1[a], nur2[a]) || pass_differs(kr1[a], kr2[a])) chunk_fail = 1;
      if (P->kind[a] != KIND_FLUID) {
        chunk_fail |= nur1[a] != 0.0 || kr1[a] != 0.0;
        continue;
      }
      const double e = fmax(fabs(nur1[a] - P->nur[a]) / fmax(P->nur[a], 1e-300),
                            fabs(kr1[a] - P->kr[a]) / fmax(P->kr[a], 1e-300));
      if (e > worst_chunk) worst_chunk = e;
    }
    free(nur1), free(kr1), free(nur2), free(kr2);
    printf(
        "turb_model_chunk: nu_r, k_r within %.2e of the unlagged pass; chunks of %d from 0 "
        "and of 37 from 5 %s\n",
        worst_chunk, TURB_CHUNK, chunk_fail ? "DIFFER" : "bitwise identical");
    chunk_fail |= !(worst_chunk < 1e-12);
  }
  const double dpr2 = P->pr2[probe] - pr2_before;
  const double want_pr2 = 2.0 / 3.0 * P->kr[probe] / P->rho[probe];
  const double e3 = fabs(dpr2 - want_pr2) / want_pr2;
  printf(
      "channel, %s strain, damping %s: %d inner particles: nu_r rel. error %.2e, k_r %.2e; "
      "pressure + 2/3 rho k_r %.2e; %d near-wall wall-law stresses %.2e\n",
      strain ? "Violeau-Issa" : "gradient", damping ? "on" : "off", n_inner, worst_nu, worst_k, e3,
      n_wall, worst_tau);
  sim_free(&S);
  return chunk_fail || !(n_inner > 0 && n_wall > 0 && worst_nu < 1e-10 && worst_k < 1e-10 &&
                         e3 < 1e-10 && worst_tau < 1e-12);
}

/* les.model = profile: the table read from a file with comments and a header (at the points,
   between them by hand, beyond the last point), and nu_r = nu g(d / delta) of every fluid particle
   with d its distance to the nearest wall, k_r = 0, the largest nu + nu_r returned. */
static int check_profile(void) {
  char path[] = "/tmp/test_turb_profile_XXXXXX";
  const int fd = mkstemp(path);
  FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
  if (!f) return 1;
  fprintf(f, "# a test table\ny_over_delta, nu_r_over_nu\n0 0\n0.25, -0.5\n\n0.5 0.25\n");
  fprintf(f, "# between\n0.75 0.5\n");
  fclose(f);
  char prof[600];
  snprintf(prof, sizeof prof, "les.profile=%s", path);
  char *set[] = {"domain.dimension=3",  "domain.lx=1",       "domain.lz=0.5", "domain.dr=0.05",
                 "domain.delta=0.5",    "fluid.nu=1e-3",     "fluid.c0=10",   "time.t_end=1",
                 "sph.viscous=violeau", "les.model=profile", "les.cy=0.05",   prof};
  struct scene sc;
  const int bad = scene_load(&sc, NULL, sizeof set / sizeof set[0], set);
  remove(path);
  if (bad) return 1;
  const struct nu_profile *t = &sc.nu_prof;
  const double probe[][2] = {{0.0, 0.0},  {0.125, -0.25}, {0.25, -0.5}, {0.375, -0.125},
                             {0.6, 0.35}, {0.75, 0.5},    {1.0, 0.5},   {2.0, 0.5}};
  double worst_table = 0.0;
  for (size_t i = 0; i < sizeof probe / sizeof probe[0]; i++)
    worst_table = fmax(worst_table, fabs(turb_profile_value(t, probe[i][0]) - probe[i][1]));
  struct sim S;
  if (sim_init(&S, &sc)) return 1;
  struct particles *P = &S.P;
  const struct model *M = &S.M;
  const double numax = turb_eddy_viscosity(M, P, &S.nb, &S.W);
  double worst = 0.0, kr_max = 0.0, want_max = M->nu;
  int n = 0;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) {
      worst = fmax(worst, fabs(P->nur[a]));
      continue;
    }
    const double s = fmin(P->y[a], M->ly - P->y[a]) / sc.delta;
    double g = 0.5; /* beyond the last point */
    if (s < 0.25)
      g = -0.5 * s / 0.25;
    else if (s < 0.5)
      g = -0.5 + 0.75 * (s - 0.25) / 0.25;
    else if (s < 0.75)
      g = 0.25 + 0.25 * (s - 0.5) / 0.25;
    worst = fmax(worst, fabs(P->nur[a] - M->nu * g) / M->nu);
    kr_max = fmax(kr_max, fabs(P->kr[a]));
    want_max = fmax(want_max, M->nu * (1.0 + g));
    n++;
  }
  printf(
      "les.model = profile: table error %.2e at 8 probes; %d fluid particles, nu_r / nu "
      "error %.2e, max |k_r| %g, largest nu + nu_r %.17g (by hand %.17g)\n",
      worst_table, n, worst, kr_max, numax, want_max);
  sim_free(&S);
  return !(worst_table < 1e-15 && n > 0 && worst < 1e-14 && kr_max == 0.0 &&
           fabs(numax - want_max) < 1e-15 * want_max);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int fail = 0;
  fail |= check_strain_cloud(2);
  fail |= check_strain_cloud(3);
  const double v0 = turb_van_driest(0.0, 25.0), v1 = turb_van_driest(25.0, 25.0);
  const double v2 = turb_van_driest(1e6, 25.0);
  printf("van Driest: %.3g at y+ = 0, %.15f at y+ = A+ (1 - 1/e = %.15f), %.17g at 1e6\n", v0, v1,
         1.0 - exp(-1.0), v2);
  fail |= v0 != 0.0 || fabs(v1 - (1.0 - exp(-1.0))) > 1e-15 || v2 != 1.0;
  for (int dmp = 0; dmp < 2; dmp++)
    for (int st = 0; st < 2; st++) fail |= check_channel(dmp, st);
  fail |= check_profile();
  for (int dim = 2; dim <= 3; dim++) {
    struct model M = {.dim = dim};
    sph_violeau_table(&M);
    const double m0 = sph_violeau_moment(&M, 0.0), m2 = sph_violeau_moment(&M, 2.0);
    printf("Violeau wall moment %d-D: %.12f at the wall (want -1), %g at q = 2\n", dim, m0, m2);
    /* 8 x 8 panels of 12-point Gauss-Legendre; the square-root edge of the support limits the
       2-D quadrature to about 1e-9 (the table itself is interpolated linearly in q) */
    fail |= fabs(m0 + 1.0) > 1e-8 || m2 != 0.0;
  }
  printf(fail ? "FAILED\n" : "PASSED\n");
  MPI_Finalize();
  return fail;
}
