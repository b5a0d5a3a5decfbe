/** @file euler_rs.c @brief Implementation of euler_rs.h. */
#include "euler_rs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "moments.h"

/* Shared with euler.c (declared in euler_rs.h), which calls into this file and not back. */

/* The share of a particle at y in the upper (side 1) or lower (side 0) half of the channel:
   all of it, or half within 1e-9 delta of the centre. */
double euler_side_weight(double y, double delta, int side) {
  if (fabs(y - delta) <= 1e-9 * delta) return 0.5;
  return (y > delta) == side ? 1.0 : 0.0;
}

/* Derivative of f at point i from its neighbours (3-point Lagrange on uneven points). */
double euler_deriv(const double *x, const double *f, const int *ok, int n, int i) {
  int l = i - 1, r = i + 1;
  while (l >= 0 && !ok[l]) l--;
  while (r < n && !ok[r]) r++;
  if (l < 0 && r >= n) return NAN;
  if (l < 0) return (f[r] - f[i]) / (x[r] - x[i]);
  if (r >= n) return (f[i] - f[l]) / (x[i] - x[l]);
  const double h1 = x[i] - x[l], h2 = x[r] - x[i];
  return (-h2 / (h1 * (h1 + h2))) * f[l] + ((h2 - h1) / (h1 * h2)) * f[i] +
         (h1 / (h2 * (h1 + h2))) * f[r];
}

/* The budget's bins are hat functions (cloud in cell): a particle at y between the centres of
   bins b and b + 1 counts 1 - s in b and s in b + 1 (all in the end bins beyond their centres),
   so that what a step's displacement carries into a bin changes smoothly with the positions:
   with hard bins it would be whole particles crossing an edge, a noise the sampling of one step
   in N does not average out (each sample stands for N steps whose crossings largely cancel).
   Returns b; *s the share of b + 1. */
static int hat(const struct euler_config *c, double y, double *s) {
  const double x = (y - c->y0) * (c->nb / (c->y1 - c->y0)) - 0.5;
  if (!(x > 0.0)) return *s = 0.0, 0;
  if (x >= c->nb - 1) return *s = 0.0, c->nb - 1;
  const int b = (int)x;
  *s = x - b;
  return b;
}

/* The hat bins b, b + 1 of (folded) position y with their shares phi[0..1], and the first node
   k of the two (k, k + 1: the bin centres) that make the local mean U(y) at y, with their
   weights psi[0..1]: linear between the nodes, extrapolated linearly from the two end nodes
   towards a wall (the particles' own near-wall profile: no U = 0 imposed at y = 0, which the
   particles nearest the wall, as the walls let them slip, do not follow), the last node's value
   beyond it in a folded profile (U' = 0 at the centre). */
struct rs_at {
  int b, k;
  double phi[2], psi[2];
};

static struct rs_at weights(const struct euler_config *c, double y) {
  double s;
  struct rs_at a;
  a.b = a.k = hat(c, y, &s);
  a.phi[0] = a.psi[0] = 1.0 - s, a.phi[1] = a.psi[1] = s;
  const double w = (c->y1 - c->y0) / c->nb, lo = c->y0 + 0.5 * w, hi = c->y1 - 0.5 * w;
  if (c->nb < 2) return a;
  if (y < lo) {
    const double r = (lo - y) / w;
    a.psi[0] = 1.0 + r, a.psi[1] = -r;
  } else if (y > hi && !c->fold) {
    const double r = (y - hi) / w;
    a.k = a.b - 1, a.psi[0] = -r, a.psi[1] = 1.0 + r;
  }
  return a;
}

/* Add a particle's values to the records of the bins of its weights a, each bin b its share
   phi_b of: np plain values at plain_at; nn values times the weight psi_n of each node n of
   U(y), at noded_at + (n - b + 1) nn; if pairs_at >= 0, m psi_n psi_n' (RQ_PP). */
static void add_at(const struct rs_at *a, const double *plain, int np, int plain_at,
                   const double *noded, int nn, int noded_at, int pairs_at, double m, double *P,
                   size_t stride, size_t offset) {
  const int b = a->b, k = a->k;
  const double *phi = a->phi, *psi = a->psi;
  for (int t = 0; t < 2 && (t == 0 || phi[1] > 0.0); t++) {
    double *R = P + (size_t)(b + t) * stride + offset;
    const int n0 = k - (b + t) + 1; /* node index (RS_NODE) of node k seen from bin b + t */
    for (int i = 0; i < np; i++) R[plain_at + i] += phi[t] * plain[i];
    for (int n = 0; n < 2; n++) {
      const double wn = phi[t] * psi[n];
      double *N = R + noded_at + (n0 + n) * nn;
      if (wn != 0.0)
        for (int i = 0; i < nn; i++) N[i] += wn * noded[i];
    }
    if (pairs_at >= 0) {
      R[pairs_at + 2 * n0] += phi[t] * m * psi[0] * psi[0];
      R[pairs_at + 2 * n0 + 1] += phi[t] * m * psi[0] * psi[1];
      R[pairs_at + 2 * n0 + 2] += phi[t] * m * psi[1] * psi[1];
    }
  }
}

/* Add the quantities q (RQ_*) of mass m and velocity u with weights a, at record offset at. */
static void add_state(const struct rs_at *a, double m, const double u[3], int at, double *P,
                      size_t stride, size_t offset) {
  const double q[RQ_MU] = {m, m * u[0] * u[0], m * u[1] * u[1], m * u[2] * u[2], m * u[0] * u[1]};
  const double mu[3] = {m * u[0], m * u[1], m * u[2]};
  add_at(a, q, RQ_MU, at, mu, 3, at + RQ_MU, at + RQ_PP, m, P, stride, offset);
}

void euler_rs_add(const struct euler_config *c, const struct stats_snapshot *s, size_t a, double yf,
                  double *P, size_t stride, size_t offset) {
  const double ma = s->m ? s->m[a] : 1.0, dt = s->dt;
  const double *sx = s->sx + a * STATS_ACC;
  /* the parts of the acceleration by component, the body force last */
  double A[RS_NPART][3];
  for (int k = 0; k < STATS_PARTS; k++)
    for (int d = 0; d < 3; d++) A[k][d] = sx[d * STATS_PARTS + k];
  A[RS_BODY][0] = s->fx, A[RS_BODY][1] = 0.0, A[RS_BODY][2] = 0.0;
  for (int d = 0; d < 3; d++) A[RS_NOISE][d] = s->sx_noise ? s->sx_noise[3 * a + d] : 0.0;
  double tot[3] = {0.0, 0.0, 0.0}; /* the noise is inside the pressure part */
  for (int k = 0; k <= RS_BODY; k++)
    for (int d = 0; d < 3; d++) tot[d] += A[k][d];
  const double u[3] = {s->u[a], s->v[a], s->w[a]};
  const double ub[3] = {u[0] - 0.5 * dt * tot[0], u[1] - 0.5 * dt * tot[1],
                        u[2] - 0.5 * dt * tot[2]};
  for (int side = 0; side < 2; side++) {
    const int mirror = c->fold && side;
    const double sg = mirror ? -1.0 : 1.0;
    const double um[3] = {u[0], sg * u[1], u[2]};
    /* before the step: the forces, and the new state's quantities by the old membership */
    const double wf = euler_side_weight(yf, c->delta, side);
    if (wf > 0.0) {
      const double m = wf * ma, b[3] = {ub[0], sg * ub[1], ub[2]};
      double sp[RS_NPART * RS_NPROD], mf[RS_NPART * 3];
      for (int k = 0; k < RS_NPART; k++) {
        const double f[3] = {A[k][0], sg * A[k][1], A[k][2]};
        double *S = sp + k * RS_NPROD;
        S[RS_XX] = m * b[0] * f[0], S[RS_YY] = m * b[1] * f[1], S[RS_ZZ] = m * b[2] * f[2];
        S[RS_XY] = m * b[0] * f[1], S[RS_YX] = m * b[1] * f[0];
        mf[3 * k] = m * f[0], mf[3 * k + 1] = m * f[1], mf[3 * k + 2] = m * f[2];
      }
      const struct rs_at at = weights(c, mirror ? 2.0 * c->delta - yf : yf);
      add_at(&at, sp, RS_NPART * RS_NPROD, RSP_S, mf, RS_NPART * 3, RSP_F, -1, 0.0, P, stride,
             offset);
      add_state(&at, m, um, RSP_OLD, P, stride, offset);
    }
    /* the new state by its own positions */
    const double wh = euler_side_weight(s->y[a], c->delta, side);
    if (wh > 0.0) {
      const struct rs_at at = weights(c, mirror ? 2.0 * c->delta - s->y[a] : s->y[a]);
      add_state(&at, wh * ma, um, RSP_NEW, P, stride, offset);
    }
  }
}

void euler_rs_snapshot(const struct euler_config *c, const double *snap, size_t stride,
                       size_t offset, double t, double dt, double t_prev, double *row) {
  const double tau = isfinite(t_prev) && t > t_prev ? t - t_prev : dt;
  for (int b = 0; b < c->nb; b++) {
    const double *R = snap + (size_t)b * stride + offset;
    double blk[RB_LEN];
    blk[RB_N] = 1.0, blk[RB_TAU] = tau, blk[RB_MASS] = tau * R[RSP_NEW + RQ_M];
    for (int i = 0; i < RS_NPART * RS_NPROD; i++) blk[RB_S + i] = tau * R[RSP_S + i];
    for (int i = 0; i < RS_NPART * RS_NODE * 3; i++) blk[RB_F + i] = tau * R[RSP_F + i];
    for (int i = 0; i < RS_NQ; i++) blk[RB_K + i] = tau / dt * (R[RSP_NEW + i] - R[RSP_OLD + i]);
    double *W = row + (size_t)b * RW_LEN;
    if (W[RW_SUM + RB_N] == 0.0) {
      memcpy(W + RW_FIRST, blk, sizeof blk);
      memcpy(W + RW_Q_FIRST, R + RSP_NEW, RS_NQ * sizeof(double));
      W[RW_T_FIRST] = t;
    }
    for (int i = 0; i < RB_LEN; i++) W[RW_SUM + i] += blk[i];
    memcpy(W + RW_Q_LAST, R + RSP_NEW, RS_NQ * sizeof(double));
    W[RW_T_LAST] = t;
  }
}

double euler_rs_last_time(const struct euler_config *c, const double *rsb, size_t last) {
  for (size_t r = last + 1; r-- > 0;) {
    const double *W = rsb + r * (size_t)c->nb * RW_LEN; /* bin 0: every bin has every sample */
    if (W[RW_SUM + RB_N] > 0.0) return W[RW_T_LAST];
  }
  return NAN;
}

const char *euler_rs_field_name(int k) {
  static char name[RW_LEN][40];
  static const char *const part[RS_NPART] = {"pressure", "viscous", "model",
                                             "wall",     "body",    "pressure_noise"};
  static const char *const prod[RS_NPROD] = {"ubx_Ax", "uby_Ay", "ubz_Az", "ubx_Ay", "uby_Ax"};
  static const char *const qn[RS_NQ] = {"m",           "muu",
                                        "mvv",         "mww",
                                        "muv",         "mu_lower",
                                        "mv_lower",    "mw_lower",
                                        "mu_own",      "mv_own",
                                        "mw_own",      "mu_upper",
                                        "mv_upper",    "mw_upper",
                                        "mpsi_lower2", "mpsi_lower_own",
                                        "mpsi_own2",   "mpsi_own_upper",
                                        "mpsi_upper2"};
  static const char *const node[RS_NODE] = {"lower", "own", "upper"};
  static const char *const xyz[3] = {"x", "y", "z"};
  if (k < 0 || k >= RW_LEN) return "";
  if (!name[k][0]) {
    const char *blk = k < RW_FIRST ? "sum" : "first";
    const int i = k < RW_FIRST ? k : k < RW_Q_FIRST ? k - RW_FIRST : -1;
    if (i == RB_N)
      snprintf(name[k], sizeof name[k], "%s_samples", blk);
    else if (i == RB_TAU)
      snprintf(name[k], sizeof name[k], "%s_tau", blk);
    else if (i == RB_MASS)
      snprintf(name[k], sizeof name[k], "%s_tau_mass", blk);
    else if (i >= RB_S && i < RB_F)
      snprintf(name[k], sizeof name[k], "%s_%s_%s", blk, part[(i - RB_S) / RS_NPROD],
               prod[(i - RB_S) % RS_NPROD]);
    else if (i >= RB_F && i < RB_K)
      snprintf(name[k], sizeof name[k], "%s_%s_A%s_%s", blk, part[(i - RB_F) / 3 % RS_NPART],
               xyz[(i - RB_F) % 3], node[(i - RB_F) / (3 * RS_NPART)]);
    else if (i >= RB_K)
      snprintf(name[k], sizeof name[k], "%s_carried_%s", blk, qn[i - RB_K]);
    else if (k < RW_Q_LAST)
      snprintf(name[k], sizeof name[k], "state_first_%s", qn[k - RW_Q_FIRST]);
    else if (k < RW_T_FIRST)
      snprintf(name[k], sizeof name[k], "state_last_%s", qn[k - RW_Q_LAST]);
    else
      snprintf(name[k], sizeof name[k], k == RW_T_FIRST ? "time_first" : "time_last");
  }
  return name[k];
}

/* The velocity indices (i, j) of each stored component, and its quantity q = m u_i u_j. */
static const int comp_ij[4][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}};
static const int comp_q[4] = {RQ_UU, RQ_VV, RQ_WW, RQ_UV};

/* The products m ub_i A_j and m ub_j A_i of component c. */
static const int comp_prod[4][2] = {{RS_XX, RS_XX}, {RS_YY, RS_YY}, {RS_ZZ, RS_ZZ}, {RS_XY, RS_YX}};

/* sum phi m (u_i - U_i(y))(u_j - U_j(y)) of component c from the quantities Q (RQ_*) of a bin,
   Un [node][component] the local mean's node values b - 1, b, b + 1. */
static double centred(const double *Q, int c, double Un[RS_NODE][3]) {
  const int i = comp_ij[c][0], j = comp_ij[c][1];
  double e = Q[comp_q[c]];
  for (int n = 0; n < RS_NODE; n++) {
    const double *mu = Q + RQ_MU + 3 * n;
    e -= Un[n][i] * mu[j] + Un[n][j] * mu[i];
    e += Un[n][i] * Un[n][j] * Q[RQ_PP + 2 * n];
    if (n + 1 < RS_NODE)
      e += (Un[n][i] * Un[n + 1][j] + Un[n + 1][i] * Un[n][j]) * Q[RQ_PP + 2 * n + 1];
  }
  return e;
}

/* The terms (RT_PRESSURE .. RT_TRANSFER, RT_RATE) of the four stored components from a block
   of sums B and the states Q0 at t0, Q1 at t1, with the local mean's node values Un. */
static void terms(const double *B, const double *Q0, const double *Q1, double t0, double t1,
                  double Un[RS_NODE][3], double out[4][RS_NTERM]) {
  const double mass = B[RB_MASS], mean_mass = B[RB_MASS] / B[RB_TAU];
  for (int c = 0; c < 4; c++) {
    const int i = comp_ij[c][0], j = comp_ij[c][1];
    for (int k = 0; k < RS_NPART; k++) {
      const double *S = B + RB_S + k * RS_NPROD;
      double v = S[comp_prod[c][0]] + S[comp_prod[c][1]];
      for (int n = 0; n < RS_NODE; n++) {
        const double *F = B + RB_F + (n * RS_NPART + k) * 3;
        v -= Un[n][i] * F[j] + Un[n][j] * F[i];
      }
      out[c][k == RS_BODY ? RT_DRIVE : k == RS_NOISE ? RT_NOISE : RT_PRESSURE + k] = v / mass;
    }
    /* the quantity (u_i - U_i)(u_j - U_j) m carried by the displacements, and its state */
    out[c][RT_TRANSFER] = centred(B + RB_K, c, Un) / mass;
    const double e0 = centred(Q0, c, Un), e1 = centred(Q1, c, Un);
    out[c][RT_RATE] = t1 > t0 ? (e1 - e0) / (t1 - t0) / mean_mass : NAN;
  }
}

/* The local mean's node values (bin centres), out[nb][3]: those whose U(y) passes through
   each usable bin's point (y_mean, U) (a tridiagonal system: a bin's mean position lies
   between its centre and a neighbour's), so that a bin whose particles sit at one height sees
   no spread of the mean; a bin without samples (or a singular system) keeps the linear
   interpolation of the points, zero at the walls (y = 0; 2 delta unfolded). */
static void node_values(const struct euler_config *c, double *const *pr, const int *ok,
                        double (*out)[3]) {
  const int nb = c->nb, comp[3] = {EP_U, EP_V, EP_W};
  double *x = mem_alloc(5 * ((size_t)nb + 2), sizeof(double), "Eulerian statistics");
  double *f = x + nb + 2, *lo = f + nb + 2, *di = lo + nb + 2, *up = di + nb + 2;
  const double w = (c->y1 - c->y0) / nb;
  for (int d = 0; d < 3; d++) {
    int n = 0; /* the linear interpolation of the points */
    x[n] = 0.0, f[n++] = 0.0;
    for (int b = 0; b < nb; b++)
      if (ok[b]) x[n] = pr[EP_Y_MEAN][b], f[n++] = pr[comp[d]][b];
    if (!c->fold) x[n] = 2.0 * c->delta, f[n++] = 0.0;
    for (int b = 0, k = 0; b < nb; b++) {
      const double y = c->y0 + (b + 0.5) * w;
      while (k + 1 < n && x[k + 1] < y) k++;
      const double h = k + 1 < n ? x[k + 1] - x[k] : 0.0;
      out[b][d] = h > 0.0 ? f[k] + (f[k + 1] - f[k]) * fmin(fmax((y - x[k]) / h, 0.0), 1.0) : f[k];
    }
    /* the system: row b, U(y_mean_b) = U_b, or node b = its interpolated value */
    for (int b = 0; b < nb; b++) {
      const struct rs_at a = ok[b] ? weights(c, pr[EP_Y_MEAN][b]) : (struct rs_at){.k = -2};
      lo[b] = up[b] = 0.0, di[b] = 1.0, f[b] = out[b][d];
      if (a.k == b)
        di[b] = a.psi[0], up[b] = a.psi[1], f[b] = pr[comp[d]][b];
      else if (a.k == b - 1)
        lo[b] = a.psi[0], di[b] = a.psi[1], f[b] = pr[comp[d]][b];
    }
    int good = 1; /* Thomas algorithm */
    for (int b = 1; b < nb && good; b++) {
      good = fabs(di[b - 1]) > 1e-9;
      const double r = good ? lo[b] / di[b - 1] : 0.0;
      di[b] -= r * up[b - 1], f[b] -= r * f[b - 1];
    }
    good = good && fabs(di[nb - 1]) > 1e-9;
    for (int b = nb - 1; b >= 0 && good; b--) {
      x[b] = (f[b] - (b + 1 < nb ? up[b] * x[b + 1] : 0.0)) / di[b];
      good = isfinite(x[b]);
    }
    for (int b = 0; b < nb && good; b++) out[b][d] = x[b];
  }
  free(x);
}

/* Production from the profiles (-<u_i'v'> dU_j/dy - <u_j'v'> dU_i/dy, U = U(y) e_x), the
   transport (transfer - production), the closure, and k from the stored components. */
static void derived(double t[RS_NCOMP][RS_NTERM], double dudy, double uv, double vv) {
  const double prod[4] = {-2.0 * uv * dudy, 0.0, 0.0, -vv * dudy};
  for (int c = 0; c < 4; c++) {
    t[c][RT_PRODUCTION] = prod[c];
    t[c][RT_TRANSPORT] = t[c][RT_TRANSFER] - prod[c];
    t[c][RT_CLOSURE] = t[c][RT_PRESSURE] + t[c][RT_VISCOUS] + t[c][RT_MODEL] + t[c][RT_WALL] +
                       t[c][RT_DRIVE] + t[c][RT_TRANSFER] - t[c][RT_RATE];
  }
  for (int k = 0; k < RS_NTERM; k++) t[RS_K][k] = 0.5 * (t[RS_UU][k] + t[RS_VV][k] + t[RS_WW][k]);
}

int euler_rs_profiles(const struct euler_config *c, const double *rsb, const int *complete,
                      size_t r0, size_t r1, struct euler_result *res) {
  const int nb = c->nb;
  int any = 0;
  double *const *pr = res->prof;
  int *ok = mem_alloc((size_t)nb, sizeof(int), "Eulerian statistics");
  for (int b = 0; b < nb; b++) ok[b] = isfinite(pr[EP_U][b]);
  double(*Uc)[3] = mem_alloc((size_t)nb, sizeof *Uc, "Eulerian statistics");
  node_values(c, pr, ok, Uc);
  for (int b = 0; b < nb; b++) {
    double sum[RB_LEN] = {0}, batch[RS_NCOMP * RS_NTERM][SCAL_LEN];
    memset(batch, 0, sizeof batch);
    const double *first = NULL, *last = NULL;
    double Un[RS_NODE][3];
    for (int n = 0; n < RS_NODE; n++)
      for (int d = 0; d < 3; d++)
        Un[n][d] = b + n - 1 >= 0 && b + n - 1 < nb ? Uc[b + n - 1][d] : 0.0;
    const double dudy = ok[b] ? euler_deriv(pr[EP_Y_MEAN], pr[EP_U], ok, nb, b) : NAN;
    for (size_t r = r0; r < r1 && rsb; r++) {
      const double *W = rsb + (r * (size_t)nb + (size_t)b) * RW_LEN;
      if (W[RW_SUM + RB_N] <= 0.0) continue;
      if (!first) first = W;
      last = W;
      for (int i = 0; i < RB_LEN; i++) sum[i] += W[RW_SUM + i];
      /* a complete window is a batch: its samples after the first, its first and last state */
      if (!complete[r] || W[RW_SUM + RB_N] < 2.0 || !ok[b]) continue;
      double blk[RB_LEN], t[RS_NCOMP][RS_NTERM];
      for (int i = 0; i < RB_LEN; i++) blk[i] = W[RW_SUM + i] - W[RW_FIRST + i];
      if (!(blk[RB_MASS] > 0.0)) continue;
      terms(blk, W + RW_Q_FIRST, W + RW_Q_LAST, W[RW_T_FIRST], W[RW_T_LAST], Un, t);
      derived(t, dudy, pr[EP_UV][b], pr[EP_VV][b]);
      for (int k = 0; k < RS_NCOMP * RS_NTERM; k++)
        scal_add(batch[k], t[k / RS_NTERM][k % RS_NTERM]);
    }
    /* the range: its samples after the first, from the first state to the last */
    if (first)
      for (int i = 0; i < RB_LEN; i++) sum[i] -= first[RW_FIRST + i];
    if (!first || sum[RB_N] < 1.0 || !(sum[RB_MASS] > 0.0) || !ok[b]) {
      for (int k = EP_RSB; k < EP_RSB_SE_END; k++) pr[k][b] = NAN;
      continue;
    }
    any = 1;
    double t[RS_NCOMP][RS_NTERM];
    terms(sum, first + RW_Q_FIRST, last + RW_Q_LAST, first[RW_T_FIRST], last[RW_T_LAST], Un, t);
    derived(t, dudy, pr[EP_UV][b], pr[EP_VV][b]);
    for (int k = 0; k < RS_NCOMP * RS_NTERM; k++) {
      pr[EP_RSB + k][b] = t[k / RS_NTERM][k % RS_NTERM];
      const double *s = batch[k];
      pr[EP_RSB_SE + k][b] =
          s[SCAL_N] >= 2.0 ? sqrt(s[SCAL_M2] / (s[SCAL_N] - 1.0) / s[SCAL_N]) : NAN;
    }
  }
  if (!any)
    for (int k = EP_RSB; k < EP_RSB_SE_END; k++)
      for (int b = 0; b < nb; b++) pr[k][b] = NAN;
  free(ok), free(Uc);
  return any;
}
