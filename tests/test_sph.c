/*
 * test_sph: the lattice table of the `lattice` pressure wall weight (solver/sph.c) against the
 * discrete first moment sum_b V_b (y_a - y_b) F_ab of the real particles on the initial lattice
 * (2-D and 3-D, h/dr = 1.3 and 1.6): |grad gamma| + excess must equal the particles' moment for
 * every particle within 2h of a wall (docs/theory.md, "the sheared lattice").
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>

#include "sim.h"
#include "wall.h"

static int check(const char *name, char **set, int nset) {
  struct scene sc;
  if (scene_load(&sc, NULL, nset, set)) return 1;
  struct sim S;
  if (sim_init(&S, &sc)) return 1;
  const struct model *M = &S.M;
  const struct particles *P = &S.P;
  double worst = 0.0;
  int checked = 0;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    for (int wall = 0; wall < 2; wall++) {
      const double d = wall ? M->ly - P->y[a] : P->y[a], q = d * M->k.inv_h;
      if (q >= 2.0) continue;
      const double ny = wall ? -1.0 : 1.0;
      double mom1 = 0.0;
      const int32_t *nl = S.nb.list + a * (size_t)S.nb.stride;
      for (int j = 0; j < S.nb.count[a]; j++) {
        const int32_t b = nl[j];
        const double dx = nbr_wrap(P->x[a] - P->x[b], M->lx), dy = P->y[a] - P->y[b];
        const double dz = M->dim == 3 ? nbr_wrap(P->z[a] - P->z[b], M->lz) : 0.0;
        mom1 += P->m[b] / P->rho[b] * kernel_f(&M->k, sqrt(dx * dx + dy * dy + dz * dz)) * dy;
      }
      /* the table at this layer's q (a knot): linear interpolation returns the knot value */
      double e = 0.0;
      for (int k = 0; k < M->n_lat; k++)
        if (fabs(M->lat_q[k] - q) < 1e-9) e = M->lat_e[k];
      const double want = ny * mom1, got = wall_dgamma(M->dim, q) * M->k.inv_h + e;
      /* relative to the wall-gradient scale |grad gamma|(0), as both sides vanish at q = 2 */
      const double err = fabs(got - want) / (wall_dgamma(M->dim, 0.0) * M->k.inv_h);
      if (err > worst) worst = err;
      checked++;
    }
  }
  printf(
      "%s: %d near-wall particles, %d table knots, max difference %.3e of |grad gamma|(0) (tol "
      "1e-12)\n",
      name, checked, M->n_lat, worst);
  sim_free(&S);
  return !(worst <= 1e-12 && checked > 0);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  char *s2[] = {"domain.dimension=2", "domain.lx=1", "domain.dr=0.05",
                "fluid.nu=0.1",       "fluid.c0=10", "time.t_end=1"};
  char *s2b[] = {"domain.dimension=2", "domain.lx=1",  "domain.dr=0.05",   "fluid.nu=0.1",
                 "fluid.c0=10",        "time.t_end=1", "sph.h_over_dr=1.6"};
  char *s3[] = {"domain.dimension=3", "domain.lx=0.4", "domain.lz=0.4", "domain.dr=0.05",
                "fluid.nu=0.1",       "fluid.c0=10",   "time.t_end=1"};
  int fail = check("2-D h/dr=1.3", s2, 6);
  fail |= check("2-D h/dr=1.6", s2b, 7);
  fail |= check("3-D h/dr=1.3", s3, 7);
  printf("test_sph: %s\n", fail ? "FAILED" : "passed");
  MPI_Finalize();
  return fail;
}
