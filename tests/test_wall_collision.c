/*
 * test_wall_collision: a fluid particle that reaches a wall (sph.wall_collision, solver/sim.c).
 * A 3-D channel at rest; one particle next to each wall is given a wall-normal velocity that
 * carries it through its wall in one step of fixed dt. The same step is taken twice:
 * - stop (the default): the health check names the lowest-id particle through a wall;
 * - reflect: the two particles end mirrored in their walls, y -> -y and 2 ly - y, their v
 *   turned into the fluid, u and w as in the stop run, bit for bit; every other particle is
 *   bit-identical to the stop run; the counter says 2 and the health check passes.
 */
#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "health.h"
#include "sim.h"

/* One step from the prepared state; lo, hi: the indices of the two particles sent at the
   walls. */
static int one_step(const char *mode, struct scene *sc, struct sim *S, size_t *lo, size_t *hi) {
  char key[64];
  snprintf(key, sizeof key, "sph.wall_collision=%s", mode);
  char *set[] = {
      "domain.dimension=3", "domain.lx=0.5", "domain.lz=0.4", "domain.dr=0.05", "fluid.nu=0.1",
      "fluid.c0=200",       "drive.force=0", "time.t_end=1",  "time.dt=1e-3",   key};
  if (scene_load(sc, NULL, 10, set)) return 1;
  if (sim_init(S, sc)) return 1;
  struct particles *P = &S->P;
  *lo = *hi = P->n;
  for (size_t a = 0; a < P->n; a++) { /* the fluid particles nearest each wall, lowest id */
    if (P->kind[a] != KIND_FLUID) continue;
    if (*lo == P->n || P->y[a] < P->y[*lo] || (P->y[a] == P->y[*lo] && P->id[a] < P->id[*lo]))
      *lo = a;
    if (*hi == P->n || P->y[a] > P->y[*hi] || (P->y[a] == P->y[*hi] && P->id[a] < P->id[*hi]))
      *hi = a;
  }
  P->v[*lo] = -1.5 * P->y[*lo] / sc->dt_fixed; /* 1.5 times what reaches the wall */
  P->v[*hi] = 1.5 * (S->M.ly - P->y[*hi]) / sc->dt_fixed;
  P->u[*lo] = 0.7, P->w[*hi] = -0.4;
  const int64_t id_lo = P->id[*lo], id_hi = P->id[*hi];
  sim_restored(S);
  sim_step(S); /* which may reorder the particles: find the two again */
  for (size_t a = 0; a < P->n; a++) {
    if (P->id[a] == id_lo) *lo = a;
    if (P->id[a] == id_hi) *hi = a;
  }
  return 0;
}

/* The index of the particle with this id in P (P->n if none). */
static size_t index_of(const struct particles *P, int64_t id) {
  for (size_t a = 0; a < P->n; a++)
    if (P->id[a] == id) return a;
  return P->n;
}

static double id_of(const struct particles *P, size_t a) {
  return (double)P->id[a];
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int fail = 0;
  struct scene sa, sb;
  struct sim A, B;
  size_t lo, hi, lo2, hi2;
  if (one_step("stop", &sa, &A, &lo, &hi) || one_step("reflect", &sb, &B, &lo2, &hi2)) {
    printf("FAIL: set-up\n");
    return 1;
  }
  const struct particles *PA = &A.P, *PB = &B.P;
  const double ly = A.M.ly;
  /* stop: the state holds particles through both walls and the health check names one */
  struct health_report rep;
  const int bad = health_check(&A.M, PA, A.step, A.t, &rep);
  printf("stop: particle %.0f at y = %.6g, particle %.0f at y = %.6g (ly %g); health: %s\n",
         id_of(PA, lo), PA->y[lo], id_of(PA, hi), PA->y[hi], ly, bad ? rep.what : "passed");
  fail |= !(PA->y[lo] < 0.0 && PA->y[hi] > ly && bad && strstr(rep.what, "through a wall"));
  /* reflect: the specular map of the stop run's end state, for those two only */
  size_t other_diff = 0;
  for (size_t a = 0; a < PA->n; a++) {
    if (a == lo || a == hi) continue;
    const size_t b = index_of(PB, PA->id[a]);
    if (b == PB->n) {
      other_diff++;
      continue;
    }
    other_diff += PA->x[a] != PB->x[b] || PA->y[a] != PB->y[b] || PA->z[a] != PB->z[b] ||
                  PA->u[a] != PB->u[b] || PA->v[a] != PB->v[b] || PA->w[a] != PB->w[b];
  }
  lo2 = index_of(PB, PA->id[lo]), hi2 = index_of(PB, PA->id[hi]);
  const int lo_ok = lo2 < PB->n && PB->y[lo2] == -PA->y[lo] && PB->v[lo2] == -PA->v[lo] &&
                    PB->v[lo2] > 0.0 && PB->u[lo2] == PA->u[lo] && PB->w[lo2] == PA->w[lo] &&
                    PB->x[lo2] == PA->x[lo] && PB->z[lo2] == PA->z[lo];
  const int hi_ok = hi2 < PB->n && PB->y[hi2] == 2.0 * ly - PA->y[hi] && PB->v[hi2] == -PA->v[hi] &&
                    PB->v[hi2] < 0.0 && PB->u[hi2] == PA->u[hi] && PB->w[hi2] == PA->w[hi] &&
                    PB->x[hi2] == PA->x[hi] && PB->z[hi2] == PA->z[hi];
  const int healthy = !health_check(&B.M, PB, B.step, B.t, &rep);
  printf(
      "reflect: lower (y %.6g, v %.6g) %s, upper (y %.6g, v %.6g) %s; other particles "
      "differing from the stop run: %zu; reflections counted %ld (want 2); health %s\n",
      PB->y[lo2], PB->v[lo2], lo_ok ? "mirrored" : "WRONG", PB->y[hi2], PB->v[hi2],
      hi_ok ? "mirrored" : "WRONG", other_diff, B.reflections, healthy ? "passed" : rep.what);
  fail |= !(lo_ok && hi_ok && other_diff == 0 && B.reflections == 2 && healthy);
  sim_free(&A);
  sim_free(&B);
  printf("%s\n", fail ? "FAIL" : "PASS");
  MPI_Finalize();
  return fail;
}
