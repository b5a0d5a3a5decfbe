/**
 * @file forces.c
 * @brief sph_forces (sph.h): the accelerations of the fluid particles and the volume-diffusion
 *        sum, assembled from the terms of term_pressure.h, term_viscous.h, term_diffusion.h and
 *        term_gradient.h.
 *
 * One fused loop over each particle's neighbour list (pair_sums) adds every term's pair
 * contribution, so the pair geometry is computed once; the terms a scene needs are fixed for
 * the whole run, and the loop is specialised for them. The force loops are one function per
 * viscous operator and data path (forces_morris, forces_violeau, forces_les, forces_les_lag,
 * and the same with _arrays), chosen by one switch (force_loop_of); inside, the
 * pressure-gradient form is a constant of two inlined copies of the pair loop, so no loop has
 * a branch per pair and all vectorise. The data path: with AVX-512 the neighbours' pair records
 * are gathered into contiguous buffers (records.h), otherwise the loops read the particle
 * arrays through the list (pair_loop.h).
 * Each list holds its fluid neighbours first, then the wall vertices (nbr.h): the fluid part
 * adds the volume diffusion, the vertex part gives the viscous pull of the wall for the wall
 * shear stress of the statistics. Each term's per-particle finish follows in force_finish().
 *
 * Determinism: a particle's sums depend only on its own neighbour list, whose order is the same
 * on any number of threads and ranks (nbr.h), and every list starts at the same alignment, so
 * the vectorised partial sums are formed in the same order everywhere.
 */
#include <math.h>

#include "pair_loop.h"
#include "sph.h"
#include "term_diffusion.h"
#include "term_gradient.h"
#include "term_pressure.h"
#include "term_viscous.h"
#include "timers.h"
#include "turb.h"

/** The viscous operator of a force loop; VK_LES_LAG: the LES loop that also forms the
    velocity-gradient sums of the next step's eddy viscosity (les.strain_lag). */
enum visc_kind { VK_MORRIS, VK_VIOLEAU, VK_LES, VK_LES_LAG };

/** What every force loop reads. */
struct fctx {
  const struct model *M;
  const struct particles *P;
  const struct nbr *nb;
  const struct walls *W;
  struct pair_view arrays;    /*!< the particle arrays as a pair view (nl set per particle) */
  int pgrad;                  /*!< the pressure-gradient form (enum pressure_gradient) */
  double fx;                  /*!< driving acceleration (time-step limit only) [m/s^2] */
  double *wall_ax;            /*!< x-acceleration from the walls, or NULL */
  double *sx;                 /*!< parts of the x-acceleration (enum part_sx), or NULL */
  double *nur_next, *kr_next; /*!< VK_LES_LAG: nu_r and k_r of the next step */
};

/** Pair sums of one particle over one part of its neighbour list, by term. */
struct fsums {
  struct pressure_sums p; /*!< term_pressure.h */
  struct viscous_sums v;  /*!< term_viscous.h */
  double diff;            /*!< term_diffusion.h (fluid part only) */
};

/** Sums over the neighbours j0 .. j1-1 of particle a (view V) for the operator `visc`, the
    pressure-gradient form `corr` (enum pressure_gradient; kgc: arrays only, `gathered` = 0), with
   (`fluid`) or without the volume diffusion, the kernel `shape`; `gathered` as for the view.
   VK_LES_LAG keeps F_ab and r_ab in geo (enum GEO_F ..., ld apart) for the velocity-gradient sums.
   Always inlined with constant flags: one specialised loop per combination. */
static inline __attribute__((always_inline)) void pair_sums(const struct fctx *C, size_t a,
                                                            const struct pair_view *V, double *geo,
                                                            int ld, int j0, int j1,
                                                            const int gathered, const int fluid,
                                                            const int visc, const int corr,
                                                            const int shape, struct fsums *out) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  const struct pair_frame F = pair_frame_of(M);
  const double *restrict x = V->f[REC_X], *restrict y = V->f[REC_Y], *restrict z = V->f[REC_Z];
  const double *restrict u = V->f[REC_U], *restrict v = V->f[REC_V], *restrict w = V->f[REC_W];
  const double *restrict vol = V->f[REC_VOL], *restrict rho = V->f[REC_RHO];
  const double *restrict m = V->f[REC_M], *restrict pr2 = V->f[REC_PR2];
  const double *restrict c = V->f[REC_C], *restrict nur = V->f[REC_NUR];
  const int32_t *restrict nl = V->nl;
  const int kgc = corr == PGRAD_KGC; /* the neighbours' B (through the list: arrays only) */
  const double *restrict bxx = P->kgc_xx, *restrict bxy = P->kgc_xy, *restrict bxz = P->kgc_xz;
  const double *restrict byy = P->kgc_yy, *restrict byz = P->kgc_yz, *restrict bzz = P->kgc_zz;
  const double eta2 = M->eta2, nu = M->nu, np2 = M->dim + 2.0, dgrav = diffusion_dgrav(M);
  const double dlr = M->diff_lr, dlc = M->diff_lc;
  const double xa = P->x[a], ya = P->y[a], za = P->z[a], ua = P->u[a], va = P->v[a];
  const double wa = P->w[a], ra = P->rho[a], pa = P->pr2[a], ca = P->c[a], ira = 1.0 / ra;
  const double pm_a = corr == PGRAD_CORRECTED ? pa * ra * ra : 0.0;
  const int les = visc == VK_LES || visc == VK_LES_LAG, keep = visc == VK_LES_LAG;
  const double mu_a = les ? ra * (nu + P->nur[a]) : 0.0;
  double *restrict gf = geo + (size_t)GEO_F * ld, *restrict gx = geo + (size_t)GEO_X * ld;
  double *restrict gy = geo + (size_t)GEO_Y * ld, *restrict gz = geo + (size_t)GEO_Z * ld;
  double gpx = 0, gpy = 0, gpz = 0, vx = 0, vy = 0, vz = 0, mo2 = 0, moyy = 0, mo1 = 0;
  double diff = 0, m1x = 0, m2x = 0, m1z = 0, m2z = 0;
  /* kgc sums its B_b terms in axx, axy, axz (the corrected form's moment matrix, unused by
     kgc): three more reduction variables in every loop raised GCC's profitability threshold
     above the LES loops' neighbour counts, which then ran scalar (2.3 times slower) */
  double axx = 0, axy = 0, axz = 0, ayy = 0, ayz = 0, azz = 0, gcx = 0, gcy = 0, gcz = 0;
#pragma omp simd reduction(+ : gpx, gpy, gpz, vx, vy, vz, mo2, moyy, mo1, diff, m1x, m2x, m1z, \
                               m2z, axx, axy, axz, ayy, ayz, azz, gcx, gcy, gcz)
  for (int j = j0; j < j1; j++) {
    const int32_t b = pair_index(gathered, nl, j);
    const struct pair g = pair_at_shape(&F, shape, xa - x[b], ya - y[b], za - z[b]);
    const double vb = vol[b], rb = rho[b];
    if (keep) gf[j] = g.f, gx[j] = g.dx, gy[j] = g.dy, gz[j] = g.dz;
    if (kgc) { /* term_pressure.h, kgc form */
      const struct v3 d = pressure_kgc_pair(&g, vb, pr2[b], rb);
      gcx += d.x, gcy += d.y, gcz += d.z;
      const struct sym3 bb = {bxx[b], bxy[b], bxz[b], byy[b], byz[b], bzz[b]};
      const struct v3 t = pressure_kgc_matrix_pair(&g, vb, bb);
      axx += t.x, axy += t.y, axz += t.z; /* the B_b sums (above) */
    } else if (corr == PGRAD_CORRECTED) { /* term_pressure.h, corrected form */
      const struct sym3 t = gradient_moment(&g, vb);
      axx += t.xx, axy += t.xy, axz += t.xz, ayy += t.yy, ayz += t.yz, azz += t.zz;
      const struct v3 d = pressure_corrected_pair(&g, vb, pr2[b], rb, pm_a);
      gcx += d.x, gcy += d.y, gcz += d.z;
    } else { /* term_pressure.h, symmetric form */
      const struct v3 t = pressure_pair(&g, m[b], pa, pr2[b]);
      gpx += t.x, gpy += t.y, gpz += t.z;
    }
    const struct v3 uab = {ua - u[b], va - v[b], wa - w[b]}; /* term_viscous.h */
    struct v3 t;
    if (visc == VK_MORRIS)
      t = viscous_morris_pair(&g, m[b], ira, vb, eta2, uab);
    else if (visc == VK_VIOLEAU)
      t = viscous_violeau_pair(&g, vb, 0.5 * (ra + rb), np2, eta2, uab);
    else /* Eq. 2.100 with mu = rho (nu + nu_r) */
      t = viscous_violeau_pair(&g, vb, 0.5 * (mu_a + rb * (nu + nur[b])), np2, eta2, uab);
    vx += t.x, vy += t.y, vz += t.z;
    const struct v3 mo = viscous_moments(&g, vb);
    mo2 += mo.x, moyy += mo.y, mo1 += mo.z;
    if (visc != VK_MORRIS) {
      const struct v3 vm = viscous_violeau_moments(&g, vb, np2, eta2);
      m1x += vm.x, m2x += vm.x * g.dy, m1z += vm.y, m2z += vm.y * g.dy;
    }
    if (fluid)
      diff += diffusion_pair(&g, vb, ca, c[b], ra - rb, dgrav, dlr, dlc); /* term_diffusion.h */
  }
  out->p = (struct pressure_sums){{gpx, gpy, gpz}, {axx, axy, axz, ayy, ayz, azz}, {gcx, gcy, gcz}};
  out->v = (struct viscous_sums){{vx, vy, vz}, {mo2, moyy, mo1}, m1x, m2x, m1z, m2z};
  out->diff = diff;
}

/** Acceleration of fluid particle a from its pair sums (fluid part s, vertex part sv): each
    term's finish and wall term, the body force, the budget parts on sampled steps; the
    time-step maxima go to mx[0] (max |a|^2) and mx[1] (max |grad gamma . v|). */
static void force_finish(const struct fctx *C, size_t a, const struct fsums *s,
                         const struct fsums *sv, double mx[2]) {
  const struct model *M = C->M;
  const struct particles *P = C->P;
  struct sym_solve L;
  struct v3 acc = pressure_finish(M, P, a, &s->p, &sv->p, &L);
  const struct viscous_norm vn = viscous_norm(M, P, a, &s->v, &sv->v);
  double awall = viscous_finish(&vn, &s->v, &sv->v, &acc);
  const struct viscous_wall_moments wm = {s->v.mom.z + sv->v.mom.z, s->v.m1x + sv->v.m1x,
                                          s->v.m1z + sv->v.m1z};
  const double gv = pressure_wall(M, P, C->W, a, wm.mom1, &acc);
  viscous_wall(M, P, C->W, a, &vn, &wm, &acc, &awall);
  acc.y += M->gy;
  P->ax[a] = acc.x, P->ay[a] = acc.y, P->az[a] = acc.z;
  if (C->sx) { /* the budget parts, as this particle's sums give them (sph_budget_pairs then
                   splits off their conservative part); the rest of ax is the walls' */
    const struct v3 pb = pressure_budget(M, P, a, &s->p, &L), vb = viscous_budget(&vn, &s->v);
    const double pc[3] = {pb.x, pb.y, pb.z}, vc[3] = {vb.x, vb.y, vb.z};
    const double ac[3] = {acc.x, acc.y - M->gy, acc.z}; /* without the body forces */
    for (int c = 0; c < 3; c++) {
      double *sx = C->sx + a * SX_STRIDE + c * SX_LEN;
      sx[SX_PRESSURE] = pc[c], sx[SX_VISCOUS] = vc[c], sx[SX_MODEL] = 0.0;
      sx[SX_WALL] = ac[c] - pc[c] - vc[c];
    }
    P->vfx[a] = vn.vis * vn.kx, P->vfy[a] = vn.vis * vn.kappa, P->vfz[a] = vn.vis * vn.kz;
  }
  if (C->wall_ax) C->wall_ax[a] = awall;
  P->ddiff[a] = diffusion_finish(M, s->diff);
  const double ax2 = (acc.x + C->fx) * (acc.x + C->fx) + acc.y * acc.y + acc.z * acc.z;
  if (ax2 > mx[0]) mx[0] = ax2;
  if (gv > mx[1]) mx[1] = gv;
}

/** The force pass over particles a0 .. a1-1 (one chunk) for the operator `visc`, the pressure
    form `corr`, the kernel `shape` and the data path `gathered`; VK_LES_LAG then forms the chunk's
    eddy viscosity of the next step from its velocity-gradient sums (turb_model_chunk). */
static inline __attribute__((always_inline)) void force_range(const struct fctx *C, size_t a0,
                                                              size_t a1, double mx[2],
                                                              const int visc, const int corr,
                                                              const int shape, const int gathered) {
  const struct nbr *nb = C->nb;
  const struct particles *P = C->P;
  const int ld = nb->pairbuf_ld;
  double *bf = pair_buffer(nb), *geo = bf + (size_t)PAIRBUF_RECORDS * ld;
  double ab[GRADIENT_SUMS][TURB_CHUNK]; /* VK_LES_LAG: the velocity-gradient sums of the chunk */
  for (size_t a = a0; a < a1; a++) {
    const int i = (int)(a - a0);
    if (P->kind[a] != KIND_FLUID) {
      if (visc == VK_LES_LAG)
        for (int k = 0; k < GRADIENT_SUMS; k++) ab[k][i] = 0.0;
      continue;
    }
    const int32_t *nl = pair_list(nb, a);
    /* the fluid part of the list is 0 .. nf-1, the vertices nf .. n-1; gathered, each part
       padded to whole vectors */
    int nf = nb->nfluid[a], n = nb->count[a];
    struct pair_view V = C->arrays;
    V.nl = nl;
    if (gathered) {
      n = records_gather_padded(P->rec, nl, nf, n, bf, ld, &nf);
      V = pair_view_gathered(bf, ld);
    }
    struct fsums s, sv;
    pair_sums(C, a, &V, geo, ld, 0, nf, gathered, 1, visc, corr, shape, &s);
    pair_sums(C, a, &V, geo, ld, nf, n, gathered, 0, visc, corr, shape, &sv);
    force_finish(C, a, &s, &sv, mx);
    if (visc == VK_LES_LAG) { /* the velocity-gradient sums of this state, for the next step */
      const struct gradient_src src = {
          pair_frame_of(C->M), geo, ld, P->x[a], P->y[a], P->z[a], P->u[a], P->v[a], P->w[a]};
      double g[GRADIENT_SUMS];
      gradient_sums_kept(&src, &V, n, gathered, g);
      for (int k = 0; k < GRADIENT_SUMS; k++) ab[k][i] = g[k];
    }
  }
  if (visc == VK_LES_LAG) /* and the model of the whole chunk */
    turb_model_chunk(C->M, P, C->W, a0, (int)(a1 - a0), (const double(*)[TURB_CHUNK])ab,
                     C->nur_next + a0, C->kr_next + a0);
}

/** force_range for one operator, kernel shape and data path, with the pressure form of the run
    (kgc reads the neighbours' B through the list: the arrays path only, force_loop_of). */
static inline __attribute__((always_inline)) void force_chunk(const struct fctx *C, size_t a0,
                                                              size_t a1, double mx[2],
                                                              const int visc, const int shape,
                                                              const int gathered) {
  if (C->pgrad == PGRAD_CORRECTED)
    force_range(C, a0, a1, mx, visc, PGRAD_CORRECTED, shape, gathered);
  else if (!gathered && C->pgrad == PGRAD_KGC)
    force_range(C, a0, a1, mx, visc, PGRAD_KGC, shape, 0);
  else
    force_range(C, a0, a1, mx, visc, PGRAD_STANDARD, shape, gathered);
}

/** One force loop over the particles a0 .. a1-1; each is built for several instruction sets
    (pair.h). Each operator, kernel shape and data path is a function of its own: inlined into
    one, GCC 12 leaves the gathered pair loops unvectorised at run time (measured 3-4 times
    slower for the two data paths; 2.3 times for the two shapes). */
typedef void (*force_loop)(const struct fctx *C, size_t a0, size_t a1, double mx[2]);

/** Defines the force loop FN for the operator VISC, the kernel SHAPE (enum kernel_shape) and
    gathered records (GATHERED = 1, AVX-512) or the particle arrays through the list (0). Each
    loop's name is written out below (no token pasting), so a grep finds its definition. The
    four loops of an operator: sph.viscous = morris or violeau; the LES operator with nu_r of
    this step (les.strain_lag = 0, or its first step); the LES operator that forms the eddy
    viscosity of the next step (les.strain_lag). */
#define FORCE_LOOP(FN, VISC, SHAPE, GATHERED)                                               \
  static CHANSPH_CLONES void FN(const struct fctx *C, size_t a0, size_t a1, double mx[2]) { \
    force_chunk(C, a0, a1, mx, VISC, SHAPE, GATHERED);                                      \
  }
FORCE_LOOP(forces_morris_C2_gathered, VK_MORRIS, KERNEL_C2, 1)
FORCE_LOOP(forces_morris_C2_arrays, VK_MORRIS, KERNEL_C2, 0)
FORCE_LOOP(forces_morris_C4_gathered, VK_MORRIS, KERNEL_C4, 1)
FORCE_LOOP(forces_morris_C4_arrays, VK_MORRIS, KERNEL_C4, 0)
FORCE_LOOP(forces_violeau_C2_gathered, VK_VIOLEAU, KERNEL_C2, 1)
FORCE_LOOP(forces_violeau_C2_arrays, VK_VIOLEAU, KERNEL_C2, 0)
FORCE_LOOP(forces_violeau_C4_gathered, VK_VIOLEAU, KERNEL_C4, 1)
FORCE_LOOP(forces_violeau_C4_arrays, VK_VIOLEAU, KERNEL_C4, 0)
FORCE_LOOP(forces_les_C2_gathered, VK_LES, KERNEL_C2, 1)
FORCE_LOOP(forces_les_C2_arrays, VK_LES, KERNEL_C2, 0)
FORCE_LOOP(forces_les_C4_gathered, VK_LES, KERNEL_C4, 1)
FORCE_LOOP(forces_les_C4_arrays, VK_LES, KERNEL_C4, 0)
FORCE_LOOP(forces_les_lag_C2_gathered, VK_LES_LAG, KERNEL_C2, 1)
FORCE_LOOP(forces_les_lag_C2_arrays, VK_LES_LAG, KERNEL_C2, 0)
FORCE_LOOP(forces_les_lag_C4_gathered, VK_LES_LAG, KERNEL_C4, 1)
FORCE_LOOP(forces_les_lag_C4_arrays, VK_LES_LAG, KERNEL_C4, 0)

/** The force loops by [enum visc_kind][kernel shape][gathered]. */
static const force_loop force_loops[4][2][2] = {
    {{forces_morris_C2_arrays, forces_morris_C2_gathered},
     {forces_morris_C4_arrays, forces_morris_C4_gathered}},
    {{forces_violeau_C2_arrays, forces_violeau_C2_gathered},
     {forces_violeau_C4_arrays, forces_violeau_C4_gathered}},
    {{forces_les_C2_arrays, forces_les_C2_gathered},
     {forces_les_C4_arrays, forces_les_C4_gathered}},
    {{forces_les_lag_C2_arrays, forces_les_lag_C2_gathered},
     {forces_les_lag_C4_arrays, forces_les_lag_C4_gathered}}};

/** The force loop of a model and data path: the one switch over the viscous operators. */
static force_loop force_loop_of(const struct model *M, int gathered) {
  const int visc = M->strain_lag                   ? VK_LES_LAG
                   : M->les                        ? VK_LES
                   : M->viscous == VISCOUS_VIOLEAU ? VK_VIOLEAU
                                                   : VK_MORRIS;
  return force_loops[visc][M->k.shape == KERNEL_C4][gathered != 0];
}

/** Particles per task of the force loop. */
enum { FORCE_CHUNK = TURB_CHUNK };

void sph_forces(const struct model *M, struct particles *P, const struct nbr *nb,
                const struct walls *W, double fx, struct force_info *info) {
  timer_push("forces");
  const force_loop loop = force_loop_of(M, records_fast() && M->pgrad != PGRAD_KGC);
  const struct fctx C = {
      M,        P,           nb,        W, pair_view_arrays(P, NULL), M->pgrad, fx, info->wall_ax,
      info->sx, P->nur_next, P->kr_next};
  const size_t n = P->n, nchunk = (n + FORCE_CHUNK - 1) / FORCE_CHUNK;
  double amax2 = 0.0, gvmax = 0.0;
#pragma omp parallel for schedule(dynamic, 4) reduction(max : amax2, gvmax)
  for (size_t k = 0; k < nchunk; k++) {
    double mx[2] = {0.0, 0.0};
    const size_t a0 = k * FORCE_CHUNK, a1 = a0 + FORCE_CHUNK < n ? a0 + FORCE_CHUNK : n;
    loop(&C, a0, a1, mx);
    if (mx[0] > amax2) amax2 = mx[0];
    if (mx[1] > gvmax) gvmax = mx[1];
  }
  info->amax = sqrt(amax2);
  info->gvmax = gvmax;
  timer_pop();
}
