/** @file term_viscous.c @brief The out-of-line part of term_viscous.h. */
#include "term_viscous.h"

CHANSPH_CLONES double viscous_molecular_x(const struct model *M, const struct pair_view *arrays,
                                          const struct nbr *nb, size_t a) {
  const struct pair_frame F = pair_frame_of(M);
  const int32_t *restrict nl = pair_list(nb, a);
  const double *restrict x = arrays->f[REC_X], *restrict y = arrays->f[REC_Y];
  const double *restrict z = arrays->f[REC_Z], *restrict u = arrays->f[REC_U];
  const double *restrict v = arrays->f[REC_V], *restrict w = arrays->f[REC_W];
  const double *restrict vol = arrays->f[REC_VOL], *restrict rho = arrays->f[REC_RHO];
  const double xa = x[a], ya = y[a], za = z[a], ra = rho[a], ua = u[a], va = v[a], wa = w[a];
  const double nu = M->nu, np2 = M->dim + 2.0, eta2 = M->eta2;
  const int nf = nb->nfluid[a];
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (int j = 0; j < nf; j++) {
    const int32_t b = nl[j];
    const struct pair g = pair_at(&F, xa - x[b], ya - y[b], za - z[b]);
    const struct v3 uab = {ua - u[b], va - v[b], wa - w[b]};
    sum += viscous_violeau_pair(&g, vol[b], 0.5 * (ra + rho[b]) * nu, np2, eta2, uab).x;
  }
  return sum;
}
