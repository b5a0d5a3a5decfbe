/**
 * @file kgc.c
 * @brief sph_kgc_matrices (sph.h): the correction matrices B of the kgc pressure gradient
 *        (term_pressure.h), one pass over the neighbour lists before the force pass.
 *
 * B_a = w L_a + (1 - w) I with L_a = A_a^-1, A_a = -sum_b V_b F_ab r_ab (x) r_ab over the whole
 * list of particle a (fluid and wall vertices) plus the analytic moment of the half-spaces
 * behind the walls (kgc_moment_behind, as the Laplacian normalisation's part behind the walls,
 * docs/theory.md): in the continuum A_a = I at any wall distance, so B corrects only the
 * discreteness of the arrangement, not the truncation of the support by a wall (gamma_a and the
 * wall term do that). Near the walls the deviation of the initial lattice's A from its value far
 * from them is subtracted (kgc_lattice_correction), so that the whole lattice has one B. Vertex
 * particles get their B the same way, for their fluid neighbours' pair terms. The weight w of the
 * blend: kgc_blend.
 *
 * Determinism: each particle's sum runs over its own list in list order (nbr.h), a gather; the
 * ghosts' copies are refreshed at PR_KGC. B depends on the positions and volumes only and is
 * recomputed after every neighbour build (and after a restart), so it is not checkpointed.
 */
#include <math.h>

#include "pair_loop.h"
#include "sph.h"
#include "term_gradient.h"
#include "term_pressure.h"
#include "timers.h"

/* The moment matrix of particle a over its list (arrays path), {xx, xy, xz, yy, yz, zz}. */
static CHANSPH_CLONES void kgc_moment(const struct model *M, const struct particles *P,
                                      const struct nbr *nb, size_t a, double A[6]) {
  const struct pair_frame F = pair_frame_of(M);
  const int32_t *restrict nl = pair_list(nb, a);
  const double *restrict x = P->x, *restrict y = P->y, *restrict z = P->z;
  const double *restrict vol = P->vol;
  const double xa = x[a], ya = y[a], za = z[a];
  double axx = 0, axy = 0, axz = 0, ayy = 0, ayz = 0, azz = 0;
  const int n = nb->count[a];
#pragma omp simd reduction(+ : axx, axy, axz, ayy, ayz, azz)
  for (int j = 0; j < n; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    const struct sym3 t = gradient_moment(&g, vol[b]);
    axx += t.xx, axy += t.xy, axz += t.xz, ayy += t.yy, ayz += t.yz, azz += t.zz;
  }
  A[0] = axx, A[1] = axy, A[2] = axz, A[3] = ayy, A[4] = ayz, A[5] = azz;
}

void sph_kgc_matrices(const struct model *M, struct particles *P, const struct nbr *nb) {
  timer_push("kgc");
#pragma omp parallel for schedule(dynamic, 256)
  for (size_t a = 0; a < P->n; a++) {
    double A[6], B[6];
    kgc_moment(M, P, nb, a, A);
    kgc_moment_behind(&M->k, M->dim, M->k.inv_h, P->y[a], M->ly, A);
    kgc_lattice_correction(M, P->kind[a] == KIND_VERTEX, P->y[a], A);
    kgc_blend(M->dim, A, B);
    P->kgc_xx[a] = B[0], P->kgc_xy[a] = B[1], P->kgc_xz[a] = B[2];
    P->kgc_yy[a] = B[3], P->kgc_yz[a] = B[4], P->kgc_zz[a] = B[5];
  }
  timer_pop();
}
