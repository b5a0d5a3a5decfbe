/*
 * test_kgc: the conservative kernel-gradient-corrected pressure gradient
 * (sph.pressure_gradient = kgc, solver/term_pressure.h, solver/kgc.c) against the symmetric one.
 * 1. Linear pressure p = G (x - lx/2) on a 3-D lattice displaced by up to 0.2 dr per component
 *    (a hash of the id), density rho0, away from the walls (wall distance > 2h) and from the
 *    jump of p at the periodic end (x within 2h of 0 or lx left out): the RMS of
 *    |a + grad p / rho0| / (|G| / rho0). Both forms keep a zeroth-order error p_a E_a (E_a the
 *    gradient of a uniform pressure 1 on the disordered arrangement: 2 sum_b V_b grad W_ab for
 *    symmetric, sum_b V_b (B_a + B_b) grad W_ab for kgc), which kgc does not correct and which
 *    dominates even where |p| < G h (|x - lx/2| < h) at this disorder: measured 0.145 (kgc)
 *    against 0.141 (symmetric) there and 0.514 against 0.445 over the interior, so the total
 *    error must only stay below 1.5 times symmetric in both regions. The first-order part,
 *    a(p) - p_a a(1) (a is linear in the
 *    pressure field; a(1) the acceleration of the uniform pressure 1), must be exact for kgc
 *    (below 1e-8, B = A^-1 there; measured 3e-16) while symmetric keeps its moment-matrix error
 *    (above 1e-3; measured 0.051).
 * 2. Momentum: a random pressure field that vanishes within 4h of the walls (so that neither the
 *    wall term nor gamma != 1 enters): |sum_a m_a a_a| below 1e-12 of sum_a m_a |a_a| in each
 *    component, for kgc (and printed for symmetric).
 * 3. A fluid at rest on the initial lattice between the walls, with the background pressure
 *    (0.01 rho0 c0^2), 2-D and 3-D: after 200 steps max |v| must be below 1e-6 c0 and below 10
 *    times the symmetric form's (or 1e-9 c0 if that is smaller). Measured: 8.5e-16 c0 (2-D) and
 *    1.1e-15 c0 (3-D) against 7.8e-16 and 1.1e-15 for symmetric; without the lattice correction
 *    of B (kgc_lattice_correction) kgc reached 6.2e-6 c0 in 2-D, so this part can fail.
 */
#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "records.h"
#include "sim.h"
#include "test_hash.h"

/* The 3-D channel of the tests 1-2 with the pressure-gradient form pg, its fluid particles
   displaced by up to 0.2 dr per component, neighbours and B of these positions, at rest. */
static int disordered(const char *pg, struct scene *sc, struct sim *S) {
  char form[64];
  snprintf(form, sizeof form, "sph.pressure_gradient=%s", pg);
  char *set[] = {"domain.dimension=3", "domain.lx=0.6", "domain.lz=0.4",
                 "domain.dr=0.05",     "fluid.nu=0.1",  "fluid.c0=10",
                 "drive.force=0",      "time.t_end=1",  form};
  if (scene_load(sc, NULL, sizeof set / sizeof set[0], set) || sim_init(S, sc)) return 1;
  struct particles *P = &S->P;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    P->x[a] += 0.2 * sc->dr * hash_unit(P->id[a], 0);
    P->y[a] += 0.2 * sc->dr * hash_unit(P->id[a], 1);
    P->z[a] += 0.2 * sc->dr * hash_unit(P->id[a], 2);
  }
  sim_restored(S);
  return 0;
}

/* Set the pressure of every particle (and of the walls) to f(a) and compute the forces. */
static void forces_of(struct sim *S, double (*f)(const struct sim *, size_t, double), double arg) {
  struct particles *P = &S->P;
  for (size_t a = 0; a < P->n; a++) {
    const double p = f(S, a, arg), r = P->rho[a];
    P->pr2[a] = p / (r * r);
    if (P->kind[a] == KIND_VERTEX) S->W.p[part_vertex_slot(P, P->id[a])] = p;
  }
  if (records_fast()) records_pack(P, P->n + P->n_ghost); /* what the gathered loops read */
  struct force_info fi = {0};
  sph_forces(&S->M, P, &S->nb, &S->W, 0.0, &fi);
}

static double p_linear(const struct sim *S, size_t a, double G) {
  return G * (S->P.x[a] - 0.5 * S->M.lx);
}
static double p_one(const struct sim *S, size_t a, double unused) {
  (void)S, (void)a, (void)unused;
  return 1.0;
}
static double p_random(const struct sim *S, size_t a, double scale) {
  const double y = S->P.y[a], h4 = 4.0 * S->M.h;
  if (y < h4 || y > S->M.ly - h4) return 0.0;
  return scale * (1.0 + 0.5 * hash_unit(S->P.id[a], 3));
}

/* Part 1 for form pg: RMS relative errors of the gradient where |x - lx/2| < h, |p| < G h (e[0]),
   over the whole interior (e[1]), and of its first-order part there (e[2]). */
static int linear(const char *pg, double e[3]) {
  struct scene sc;
  struct sim S;
  if (disordered(pg, &sc, &S)) return 1;
  struct particles *P = &S.P;
  const double G = 1000.0, r0 = sc.rho0, h = S.M.h, h2 = 2.0 * h;
  double *a1 = S.scratch[0];
  forces_of(&S, p_one, 0.0);
  for (size_t a = 0; a < P->n; a++) a1[a] = P->ax[a];
  forces_of(&S, p_linear, G);
  double s[3] = {0, 0, 0};
  int n[3] = {0, 0, 0};
  for (size_t a = 0; a < P->n; a++) {
    const double x = P->x[a], y = P->y[a];
    if (P->kind[a] != KIND_FLUID || y < h2 || y > S.M.ly - h2 || x < h2 || x > S.M.lx - h2)
      continue;
    const double ex = P->ax[a] + G / r0, ey = P->ay[a], ez = P->az[a];
    const double e2 = ex * ex + ey * ey + ez * ez;
    if (fabs(x - 0.5 * S.M.lx) < h) s[0] += e2, n[0]++;
    s[1] += e2, n[1]++;
    const double f1 = P->ax[a] - p_linear(&S, a, G) * a1[a] + G / r0;
    s[2] += f1 * f1, n[2]++;
  }
  for (int k = 0; k < 3; k++) e[k] = sqrt(s[k] / n[k]) / (G / r0);
  printf(
      "linear pressure, %s: RMS |a + grad p/rho| / (|grad p|/rho) = %.4e where |p| < G h (%d "
      "particles), %.4e over the interior (%d); of the first-order part a(p) - p_a a(1): "
      "%.4e\n",
      pg, e[0], n[0], e[1], n[1], e[2]);
  sim_free(&S);
  return n[0] == 0;
}

/* Part 2 for form pg: the worst component of |sum m a| / sum m |a|. */
static int momentum(const char *pg, double *worst) {
  struct scene sc;
  struct sim S;
  if (disordered(pg, &sc, &S)) return 1;
  struct particles *P = &S.P;
  forces_of(&S, p_random, 1000.0);
  double sum[3] = {0, 0, 0}, mag[3] = {0, 0, 0};
  for (size_t a = 0; a < P->n; a++) { /* serial, fixed order */
    if (P->kind[a] != KIND_FLUID) continue;
    const double acc[3] = {P->ax[a], P->ay[a] - S.M.gy, P->az[a]};
    for (int c = 0; c < 3; c++) sum[c] += P->m[a] * acc[c], mag[c] += P->m[a] * fabs(acc[c]);
  }
  *worst = 0.0;
  for (int c = 0; c < 3; c++) *worst = fmax(*worst, mag[c] > 0 ? fabs(sum[c]) / mag[c] : 1.0);
  printf("momentum, %s: |sum m a| / sum m |a| = %.3e, %.3e, %.3e\n", pg, fabs(sum[0]) / mag[0],
         fabs(sum[1]) / mag[1], fabs(sum[2]) / mag[2]);
  sim_free(&S);
  return 0;
}

/* Part 3: max |v| / c0 after 200 steps from the lattice at rest, dimension dim, form pg. */
static int at_rest(int dim, const char *pg, double *vmax) {
  char form[64], d[32], lz[32] = "domain.lx=0.5";
  snprintf(form, sizeof form, "sph.pressure_gradient=%s", pg);
  snprintf(d, sizeof d, "domain.dimension=%d", dim);
  if (dim == 3) snprintf(lz, sizeof lz, "domain.lz=0.4");
  char *set[] = {d,
                 "domain.lx=0.5",
                 "domain.dr=0.05",
                 "fluid.nu=0.1",
                 "fluid.c0=10",
                 "drive.force=0",
                 lz,
                 "time.t_end=100",
                 form};
  struct scene sc;
  struct sim S;
  if (scene_load(&sc, NULL, sizeof set / sizeof set[0], set) || sim_init(&S, &sc)) return 1;
  for (int k = 0; k < 200; k++) sim_step(&S);
  const struct particles *P = &S.P;
  double v = 0.0;
  for (size_t a = 0; a < P->n; a++)
    if (P->kind[a] == KIND_FLUID)
      v = fmax(v, sqrt(P->u[a] * P->u[a] + P->v[a] * P->v[a] + P->w[a] * P->w[a]));
  *vmax = v / sc.c0;
  printf("at rest, %d-D, %s: max |v| / c0 after 200 steps = %.3e\n", dim, pg, *vmax);
  sim_free(&S);
  return 0;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int fail = 0;
  double es[3], ek[3], ms, mk;
  fail |= linear("standard", es) || linear("kgc", ek);
  if (!fail) {
    const int bad = !(ek[0] < 1.5 * es[0] && ek[2] < 1e-8 && es[2] > 1e-3 && ek[1] < 1.5 * es[1]);
    printf(
        "linear pressure: kgc / symmetric error where |p| < G h = %.3f (want < 1.5), over the "
        "interior %.3f (want < 1.5: the zeroth-order part p_a sum_b V_b (B_a + B_b) grad W_ab is "
        "not corrected); first-order part %.2e (want < 1e-8) against %.2e (want > 1e-3): %s\n",
        ek[0] / es[0], ek[1] / es[1], ek[2], es[2], bad ? "FAIL" : "ok");
    fail |= bad;
  }
  fail |= momentum("standard", &ms) || momentum("kgc", &mk);
  if (!fail) {
    const int bad = !(mk < 1e-12);
    printf("momentum, kgc: worst %.3e (want < 1e-12): %s\n", mk, bad ? "FAIL" : "ok");
    fail |= bad;
  }
  for (int dim = 2; dim <= 3 && !fail; dim++) {
    double vs, vk;
    fail |= at_rest(dim, "standard", &vs) || at_rest(dim, "kgc", &vk);
    if (fail) break;
    const int bad = !(vk < 1e-6 && vk < fmax(10.0 * vs, 1e-9));
    printf(
        "at rest, %d-D: kgc %.3e, symmetric %.3e (want < 1e-6 and < max(10 x symmetric, "
        "1e-9)): %s\n",
        dim, vk, vs, bad ? "FAIL" : "ok");
    fail |= bad;
  }
  printf(fail ? "FAIL\n" : "PASS\n");
  MPI_Finalize();
  return fail;
}
