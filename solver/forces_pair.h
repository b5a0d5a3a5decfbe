/**
 * @file forces_pair.h
 * @brief The pair loop of the forces (forces.c), written once for the real type R of the pair
 *        terms and included twice by forces.c: pair_sums (double) and pair_sums_f (float pair
 *        terms, sph.precision = mixed). No include guard, on purpose.
 *
 * Before inclusion: R and PF(name) as for pair_terms.h. Whatever the type of the terms, the
 * values read at the neighbour, the differences u_a - u_b, rho_a - rho_b and the separations
 * are formed in double, and every sum over the neighbours is kept in double.
 */
/** Sums over the neighbours j0 .. j1-1 of particle a for the operator `visc`, the corrected
    (`corr`) or symmetric pressure gradient, with (`fluid`) or without the volume diffusion.
    The neighbours' values are read either from the buffers their records were gathered into
    (`gathered`: bf + REC_X * ld holds the x of neighbour j at index j, and so on) or from the
    particle arrays (neighbour j at index nl[j]). Always inlined with constant flags: one
    specialised loop per combination. */
static inline __attribute__((always_inline)) void PF(pair_sums)(
    const struct fctx *C, size_t a, double *bf, int ld, const int32_t *restrict nl, int j0, int j1,
    const int gathered, const int fluid, const int visc, const int corr, struct fsums *out) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  const struct kernel K = M->k;
#define FIELD(k, arr) (gathered ? bf + (size_t)(k)*ld : P->arr)
  const double *restrict x = FIELD(REC_X, x), *restrict y = FIELD(REC_Y, y);
  const double *restrict z = FIELD(REC_Z, z), *restrict u = FIELD(REC_U, u);
  const double *restrict v = FIELD(REC_V, v), *restrict w = FIELD(REC_W, w);
  const double *restrict vol = FIELD(REC_VOL, vol), *restrict rho = FIELD(REC_RHO, rho);
  const double *restrict m = FIELD(REC_M, m), *restrict pr2 = FIELD(REC_PR2, pr2);
  const double *restrict c = FIELD(REC_C, c), *restrict nur = FIELD(REC_NUR, nur);
#undef FIELD
  const double lx = M->lx, lz = M->lz, eta2 = M->eta2, nu = M->nu, np2 = M->dim + 2.0;
  const int d3 = M->dim == 3;
  const double dgrav = M->e.rho0 / (M->e.c0 * M->e.c0) * M->gy; /* Eq. 3.61 */
  const double xa = P->x[a], ya = P->y[a], za = P->z[a], ua = P->u[a], va = P->v[a];
  const double wa = P->w[a], ra = P->rho[a], pa = P->pr2[a], ca = P->c[a], ira = 1.0 / ra;
  const double pm_a = corr ? pa * ra * ra : 0.0;
  const int les = visc == VK_LES || visc == VK_LES_LAG, keep = visc == VK_LES_LAG;
  double *restrict geo = bf + (size_t)PAIRBUF_RECORDS * ld; /* pair geometry kept (keep) */
  const double mu_a = les ? ra * (nu + P->nur[a]) : 0.0;
  double gpx = 0, gpy = 0, gpz = 0, vx = 0, vy = 0, vz = 0, mo2 = 0, moyy = 0, mo1 = 0;
  double diff = 0, m1x = 0, m2x = 0, m1z = 0, m2z = 0;
  double axx = 0, axy = 0, axz = 0, ayy = 0, ayz = 0, azz = 0, gcx = 0, gcy = 0, gcz = 0;
#pragma omp simd reduction(+ : gpx, gpy, gpz, vx, vy, vz, mo2, moyy, mo1, diff, m1x, m2x, m1z, \
                               m2z, axx, axy, axz, ayy, ayz, azz, gcx, gcy, gcz)
  for (int j = j0; j < j1; j++) {
    const int32_t b = gathered ? j : nl[j];
    const struct PF(pair) g = PF(pair_geom)(&K, lx, lz, d3, xa - x[b], ya - y[b], za - z[b]);
    const double vb = vol[b], rb = rho[b];
    if (keep) { /* for strain_sums: V_b F_ab and r_ab */
      geo[j] = vb * g.f, geo[ld + j] = g.dx, geo[2 * (size_t)ld + j] = g.dy;
      geo[3 * (size_t)ld + j] = g.dz;
    }
    if (corr) {
      const struct PF(sym3) t = PF(term_moment)(&g, vb);
      axx += t.xx, axy += t.xy, axz += t.xz, ayy += t.yy, ayz += t.yz, azz += t.zz;
      const struct PF(v3) d = PF(term_difference)(&g, vb, pr2[b] * rb * rb - pm_a);
      gcx += d.x, gcy += d.y, gcz += d.z;
    } else {
      const struct PF(v3) t = PF(term_pressure)(&g, m[b], pa, pr2[b]);
      gpx += t.x, gpy += t.y, gpz += t.z;
    }
    const struct PF(v3) uab = {(R)(ua - u[b]), (R)(va - v[b]), (R)(wa - w[b])};
    struct PF(v3) t;
    if (visc == VK_MORRIS)
      t = PF(term_morris)(&g, m[b], ira, vb, eta2, uab);
    else if (visc == VK_VIOLEAU)
      t = PF(term_violeau)(&g, vb, 0.5 * (ra + rb), np2, eta2, uab);
    else /* Eq. 2.100 with mu = rho (nu + nu_r) */
      t = PF(term_violeau)(&g, vb, 0.5 * (mu_a + rb * (nu + nur[b])), np2, eta2, uab);
    vx += t.x, vy += t.y, vz += t.z;
    const struct PF(v3) mo = PF(term_moments)(&g, vb);
    mo2 += mo.x, moyy += mo.y, mo1 += mo.z;
    if (visc != VK_MORRIS) {
      const struct PF(v3) vm = PF(term_violeau_moments)(&g, vb, np2, eta2);
      m1x += vm.x, m2x += vm.x * g.dy, m1z += vm.y, m2z += vm.y * g.dy;
    }
    if (fluid) diff += PF(term_diffusion)(&g, vb, ca, c[b], ra - rb, dgrav);
  }
  *out = (struct fsums){{gpx, gpy, gpz},
                        {vx, vy, vz},
                        {mo2, moyy, mo1},
                        diff,
                        m1x,
                        m2x,
                        m1z,
                        m2z,
                        {axx, axy, axz, ayy, ayz, azz},
                        {gcx, gcy, gcz}};
}
