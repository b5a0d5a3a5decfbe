/*
 * test_budget_parts: the budget parts of the force pass (part.sx, solver/budget_pairs.c; docs/
 * theory.md "Momentum at the walls"), on sampled steps of a turbulent start-up:
 * 1. in each component (x, y, z) the parts of every fluid particle add up to its acceleration
 *    without the body forces (within 1e-12 of the largest part);
 * 2. the pair parts (pressure, molecular viscous, eddy-viscous) conserve momentum in each
 *    component: their sum of m a over all fluid particles is zero within 1e-12 of the largest
 *    sum of |m a| of a part;
 * 3. beyond 4h from the walls (where neither particle of a pair lies within 2h of a wall) the
 *    walls' part holds only the rest of the viscous normalisation, which differs from particle
 *    to particle as the discrete moment behind kappa_a scatters: below 10% of the particle's
 *    largest pair part (measured 4% with LES, 0.8% with Morris in these start-ups).
 * Scenes: the LES smoke scene (Violeau with the eddy viscosity, Reichardt's wall law) and the
 * quasi-DNS smoke scene with Morris' operator, 30 steps sampled at every step.
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>

#include "sim.h"

/* Checks of the parts of the current sample; returns 1 on a failure. */
static int check_sample(const struct sim *S, double *worst_sum, double *worst_cons,
                        double *worst_bulk) {
  const struct particles *P = &S->P;
  const struct model *M = &S->M;
  double tot[3][SX_LEN] = {{0}}, mag[3][SX_LEN] = {{0}};
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    const double acc[3] = {P->ax[a], P->ay[a] - M->gy, P->az[a]};
    const double yw = fmin(P->y[a], M->ly - P->y[a]);
    for (int c = 0; c < 3; c++) {
      const double *sx = P->sx + a * SX_STRIDE + c * SX_LEN;
      double sum = 0.0, big = 0.0, pairs = 0.0;
      for (int k = 0; k < SX_LEN; k++) {
        sum += sx[k], big = fmax(big, fabs(sx[k]));
        tot[c][k] += P->m[a] * sx[k], mag[c][k] += P->m[a] * fabs(sx[k]);
        if (k != SX_WALL) pairs = fmax(pairs, fabs(sx[k]));
      }
      if (big > 0.0) *worst_sum = fmax(*worst_sum, fabs(sum - acc[c]) / big);
      if (yw > 4.0 * M->h * 1.0001 && pairs > 0.0) {
        *worst_bulk = fmax(*worst_bulk, fabs(sx[SX_WALL]) / pairs);
      }
    }
  }
  double scale = 0.0; /* the largest part's magnitude: at the start a part may be all round-off */
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < SX_LEN; k++) scale = fmax(scale, mag[c][k]);
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < SX_LEN; k++)
      if (k != SX_WALL && scale > 0.0) *worst_cons = fmax(*worst_cons, fabs(tot[c][k]) / scale);
  return 0;
}

static int run(const char *name, const char *path, char **set, int nset) {
  struct scene sc;
  if (scene_load(&sc, path, nset, set)) return 1;
  struct sim S;
  if (sim_init(&S, &sc)) return 1;
  double ws = 0.0, wc = 0.0, wb = 0.0;
  int samples = 0;
  for (int k = 0; k < 30; k++) {
    sim_step(&S);
    if (!S.P.sx_live) continue;
    check_sample(&S, &ws, &wc, &wb);
    samples++;
  }
  const int fail = !(samples == 30 && ws <= 1e-12 && wc <= 1e-12 && wb <= 0.1);
  printf(
      "%s: %d samples; parts vs acceleration %.2e (tol 1e-12); pair parts' net force %.2e "
      "of the largest part (tol 1e-12); walls' part beyond 4h %.2e of the pair parts (tol "
      "0.1)%s\n",
      name, samples, ws, wc, wb, fail ? "  FAIL" : "");
  sim_free(&S);
  return fail;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  if (argc != 2) {
    fprintf(stderr, "usage: test_budget_parts SCENES_DIR\n");
    MPI_Finalize();
    return 1;
  }
  char les[512], qdns[512];
  snprintf(les, sizeof les, "%s/les395_smoke.ini", argv[1]);
  snprintf(qdns, sizeof qdns, "%s/qdns180_smoke.ini", argv[1]);
  char *s1[] = {"output.stats_every=1", "stats.budget_every=1"};
  char *s2[] = {"output.stats_every=1", "stats.budget_every=1", "sph.viscous=morris"};
  int fail = run("quasi-DNS smoke (Morris)", qdns, s2, 3);
  fail |= run("LES smoke (Violeau + eddy viscosity, wall law)", les, s1, 2);
  printf(fail ? "FAIL\n" : "PASS\n");
  MPI_Finalize();
  return fail;
}
