/** @file euler.c @brief Implementation of euler.h. */
#include "euler.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "euler_rs.h"
#include "moments.h"
#include "spar.h"
#include "state.h"

/* Per-(column, bin) partial of one snapshot: a moment record, then the sum of u and the count
   (the weight sum with EULER_SPH) behind the per-snapshot bin mean of u, then the momentum
   budget: for each side of the channel (y < delta, y > delta; folded: the first) the sums of
   m a_x of each part of the acceleration, of m and m u by the positions before the step
   (HB_MU0), of m u and m u v by the sampled positions, then the same sums weighted by the
   particle's offset from its bin centre in bin widths, phi (add_particle, budget_planes; the
   weighted m u v is not used); then the same two records for the total (EU_PART_TL: the whole
   acceleration in the first part's place, every snapshot; euler.h, TL_FORCES). */
enum { HB_MASS = STATS_PARTS, HB_MU, HB_MU0, HB_UV, HB_LEN };
enum {
  EU_PART_U = MOM_LEN,
  EU_PART_N,
  EU_PART_PL,
  EU_PART_PL1 = EU_PART_PL + 2 * HB_LEN,
  EU_PART_RS = EU_PART_PL1 + 2 * HB_LEN, /* the Reynolds-stress budget (euler_rs.h) */
  EU_PART_TL = EU_PART_RS + RSP_LEN,     /* the total of the momentum budget */
  EU_PART = EU_PART_TL + 4 * HB_LEN
};

/* Scratch of euler_sample. The columns are merged over a fixed binary tree on the global
   column index: node [lo, hi) with hi - lo >= 2 has the children [lo, mid) and [mid, hi),
   mid = lo + (hi - lo) / 2; the leaves are the columns. A rank's range [col0, col1) is the
   union of maximal nodes (its subtrees, at most about 2 log2 ncol); each rank merges its
   subtrees, and every rank merges the gathered subtree records up to the root. */
struct euler_work {
  double *part;             /* [ncol][nb][EU_PART]: per-column partials (this rank's columns) */
  double *mine, *all, *scr; /* subtree records: this rank's, all ranks', recursion scratch */
  int *node;                /* [2 x nodes] lo, hi of the gathered subtrees, in gather order */
  size_t part_cap, mine_cap, all_cap, scr_cap, node_cap; /* capacities (records, nodes) */
};

/* The Reynolds-stress budget profiles of component c (its name in the long names: what), all
   terms in the order of RT_*; sfx, pre: the name suffix and long-name prefix (standard errors). */
#define RSB_META(c, what, sfx, pre)                                                               \
  {"rsb_" c "_pressure" sfx, "m^2/s^3",                                                           \
   pre "budget of " what                                                                          \
       ": the fluctuating velocities times the pressure pair forces (velocity-"                   \
       "pressure-gradient term; DNS: pressure-strain + pressure diffusion)"},                     \
      {"rsb_" c "_viscous" sfx, "m^2/s^3",                                                        \
       pre "budget of " what                                                                      \
           ": the fluctuating velocities times the molecular viscous pair "                       \
           "forces (DNS: dissipation + viscous diffusion, with rsb_" c "_wall)"},                 \
      {"rsb_" c "_model" sfx, "m^2/s^3",                                                          \
       pre "budget of " what                                                                      \
           ": the fluctuating velocities times the eddy-viscous pair forces "                     \
           "(LES)"},                                                                              \
      {"rsb_" c "_wall" sfx, "m^2/s^3",                                                           \
       pre "budget of " what                                                                      \
           ": the fluctuating velocities times everything the walls exert "                       \
           "(vertex pressure and viscous terms, wall law, the pair forces' non-antisymmetric "    \
           "rest)"},                                                                              \
      {"rsb_" c "_drive" sfx, "m^2/s^3",                                                          \
       pre "budget of " what                                                                      \
           ": the fluctuating velocities times the body force (zero on "                          \
           "average)"},                                                                           \
      {"rsb_" c "_transfer" sfx, "m^2/s^3",                                                       \
       pre "budget of " what                                                                      \
           ": carried into the bin by the particles' displacements, with the "                    \
           "fluctuations about the bin's mean velocity (production + turbulent transport)"},      \
      {"rsb_" c "_production" sfx, "m^2/s^3",                                                     \
       pre "budget of " what                                                                      \
           ": production -<u_i'v'> dU_j/dy - <u_j'v'> dU_i/dy from the "                          \
           "profiles"},                                                                           \
      {"rsb_" c "_transport" sfx, "m^2/s^3",                                                      \
       pre "budget of " what                                                                      \
           ": turbulent transport, transfer less production (DNS: turbulent "                     \
           "diffusion)"},                                                                         \
      {"rsb_" c "_rate" sfx, "m^2/s^3",                                                           \
       pre "budget of " what                                                                      \
           ": rate of change from the first to the last sample (zero in a "                       \
           "steady state)"},                                                                      \
      {"rsb_" c "_closure" sfx, "m^2/s^3",                                                        \
       pre "budget of " what                                                                      \
           ": pressure + viscous + model + wall + drive + transfer - rate "                       \
           "(round-off when sampled every step)"},                                                \
  {                                                                                               \
    "rsb_" c "_pressure_noise" sfx, "m^2/s^3",                                                    \
        pre "budget of " what                                                                     \
            ": the configurational part of the pressure term, the fluctuating "                   \
            "velocities times the pair forces 2 p_a/rho_a^2 sum_b m_b grad W_ab that vanish for " \
            "a uniform particle arrangement (the scheme's pressure noise; included in pressure)"  \
  }
#define RSB_ALL(sfx, pre)                                                     \
  RSB_META("uu", "<u'u'>", sfx, pre), RSB_META("vv", "<v'v'>", sfx, pre),     \
      RSB_META("ww", "<w'w'>", sfx, pre), RSB_META("uv", "<u'v'>", sfx, pre), \
      RSB_META("k", "k = <u_i'u_i'>/2", sfx, pre)

const struct euler_meta euler_prof_meta[EP_NPROF] = {
    [EP_Y] = {"y", "m", "wall-normal bin centre (walls at 0 and 2 delta)"},
    [EP_Y_MEAN] = {"y_mean", "m", "mean position of the samples in the bin"},
    [EP_N] = {"n_samples", "1",
              "particle samples in the bin (SPH interpolation: sum of the weights V_a W1)"},
    [EP_U] = {"u_mean", "m/s", "mean streamwise velocity"},
    [EP_V] = {"v_mean", "m/s", "mean wall-normal velocity"},
    [EP_W] = {"w_mean", "m/s", "mean spanwise velocity"},
    [EP_P] = {"p_mean", "Pa", "mean pressure"},
    [EP_RHO] = {"rho_mean", "kg/m^3", "mean density"},
    [EP_UU] = {"uu", "m^2/s^2", "Reynolds stress <u'u'>"},
    [EP_VV] = {"vv", "m^2/s^2", "Reynolds stress <v'v'>"},
    [EP_WW] = {"ww", "m^2/s^2", "Reynolds stress <w'w'>"},
    [EP_UV] = {"uv", "m^2/s^2", "Reynolds stress <u'v'>"},
    [EP_UW] = {"uw", "m^2/s^2", "Reynolds stress <u'w'>"},
    [EP_VW] = {"vw", "m^2/s^2", "Reynolds stress <v'w'>"},
    [EP_SE_U + 0] = {"u_mean_stderr", "m/s", "standard error of u_mean (batch means)"},
    [EP_SE_U + 1] = {"v_mean_stderr", "m/s", "standard error of v_mean (batch means)"},
    [EP_SE_U + 2] = {"w_mean_stderr", "m/s", "standard error of w_mean (batch means)"},
    [EP_SE_U + 3] = {"p_mean_stderr", "Pa", "standard error of p_mean (batch means)"},
    [EP_SE_U + 4] = {"rho_mean_stderr", "kg/m^3", "standard error of rho_mean (batch means)"},
    [EP_SE_U + 5] = {"uu_stderr", "m^2/s^2", "standard error of uu (batch means)"},
    [EP_SE_U + 6] = {"vv_stderr", "m^2/s^2", "standard error of vv (batch means)"},
    [EP_SE_U + 7] = {"ww_stderr", "m^2/s^2", "standard error of ww (batch means)"},
    [EP_SE_U + 8] = {"uv_stderr", "m^2/s^2", "standard error of uv (batch means)"},
    [EP_SE_U + 9] = {"uw_stderr", "m^2/s^2", "standard error of uw (batch means)"},
    [EP_SE_U + 10] = {"vw_stderr", "m^2/s^2", "standard error of vw (batch means)"},
    [EP_SKEW_U] = {"u_skewness", "1", "skewness of u"},
    [EP_SKEW_V] = {"v_skewness", "1", "skewness of v"},
    [EP_SKEW_W] = {"w_skewness", "1", "skewness of w"},
    [EP_FLAT_U] = {"u_flatness", "1", "flatness (kurtosis) of u"},
    [EP_FLAT_V] = {"v_flatness", "1", "flatness (kurtosis) of v"},
    [EP_FLAT_W] = {"w_flatness", "1", "flatness (kurtosis) of w"},
    [EP_SE_SF + 0] = {"u_skewness_stderr", "1", "standard error of u_skewness (batch means)"},
    [EP_SE_SF + 1] = {"v_skewness_stderr", "1", "standard error of v_skewness (batch means)"},
    [EP_SE_SF + 2] = {"w_skewness_stderr", "1", "standard error of w_skewness (batch means)"},
    [EP_SE_SF + 3] = {"u_flatness_stderr", "1", "standard error of u_flatness (batch means)"},
    [EP_SE_SF + 4] = {"v_flatness_stderr", "1", "standard error of v_flatness (batch means)"},
    [EP_SE_SF + 5] = {"w_flatness_stderr", "1", "standard error of w_flatness (batch means)"},
    [EP_VISC] = {"viscous_stress", "m^2/s^2",
                 "viscous shear stress (nu + <nu_t>) dU/dy (Eq. 5.11; nu_t with LES only)"},
    [EP_TOTAL] =
        {"total_stress", "m^2/s^2",
         "total shear stress: the sum of the momentum budget reynolds_stress + "
         "viscous_pair_stress + model_pair_stress + pair_stress + wall_term_stress + "
         "advective_stress (method of planes); without it (no sampled forces) nu dU/dy - <u'v'> "
         "(Eq. 5.12)"},
    [EP_TOTAL_EXPECTED] = {"total_stress_expected", "m^2/s^2",
                           "what the total must be in a steady state: the body force on the fluid "
                           "between the plane and the centre per unit area and rho0, tau_w / rho "
                           "(1 - y / delta) for a uniform density (Eq. 5.13)"},
    [EP_NUT] = {"nu_t_mean", "m^2/s", "mean eddy viscosity (LES, thesis Eq. 5.45)"},
    [EP_KR] = {"k_r_mean", "m^2/s^2", "mean residual kinetic energy (LES, Yoshizawa)"},
    [EP_TAU_REYNOLDS] =
        {"reynolds_stress", "m^2/s^2",
         "momentum budget: the Reynolds part of the particles' kinetic flux, -<u'v'>"},
    [EP_TAU_VISCOUS] = {"viscous_pair_stress", "m^2/s^2",
                        "momentum budget: x-momentum flux through the plane carried by the "
                        "viscous pair forces (molecular viscosity), method of planes"},
    [EP_TAU_MODEL] = {"model_pair_stress", "m^2/s^2",
                      "momentum budget: flux carried by the eddy-viscous pair forces (LES)"},
    [EP_TAU_PAIR] = {"pair_stress", "m^2/s^2",
                     "momentum budget: flux carried by the pressure pair forces, background "
                     "pressure included: the configurational stress of the particle arrangement, "
                     "the scheme's own numerical stress"},
    [EP_TAU_WALL] = {"wall_term_stress", "m^2/s^2",
                     "momentum budget: x-force of the wall terms on the fluid between the plane "
                     "and the centre per unit area and rho0"},
    [EP_TAU_ADVECT] = {"advective_stress", "m^2/s^2",
                       "momentum budget: the rest of the particles' kinetic flux through the "
                       "bin's planes (the momentum the sampled step's displacements carried; "
                       "without the step, the bin sum of m u v / (rho0 A w)) less "
                       "reynolds_stress: the mean flow's advection -U V, the density weighting "
                       "of -<u'v'> and particle shifting; zero in a steady state of uniform "
                       "density"},
    [EP_TAU_SOURCE] = {"pair_momentum_source", "m^2/s^2",
                       "net x-force of all pair forces on the fluid of this side of the channel "
                       "per unit area and rho0 (the scheme's momentum source; zero if the pair "
                       "forces conserve momentum): the walls balance it with drag in excess of "
                       "the body force"},
    [EP_TAU_INERTIA] = {"momentum_change", "m^2/s^2",
                        "rate of change of the x-momentum of the fluid between the plane and the "
                        "centre per unit area and rho0 (first to last sample; zero in a steady "
                        "state): total_stress + momentum_change = total_stress_expected"},
    [EP_SE_TAU + 0] = {"reynolds_stress_stderr", "m^2/s^2",
                       "standard error of reynolds_stress (batch means)"},
    [EP_SE_TAU + 1] = {"viscous_pair_stress_stderr", "m^2/s^2",
                       "standard error of viscous_pair_stress (batch means)"},
    [EP_SE_TAU + 2] = {"model_pair_stress_stderr", "m^2/s^2",
                       "standard error of model_pair_stress (batch means)"},
    [EP_SE_TAU + 3] = {"pair_stress_stderr", "m^2/s^2",
                       "standard error of pair_stress (batch means)"},
    [EP_SE_TAU + 4] = {"wall_term_stress_stderr", "m^2/s^2",
                       "standard error of wall_term_stress (batch means)"},
    [EP_SE_TAU + 5] = {"advective_stress_stderr", "m^2/s^2",
                       "standard error of advective_stress (batch means)"},
    [EP_SE_TAU + 6] = {"total_stress_stderr", "m^2/s^2",
                       "standard error of total_stress (batch means)"},
    [EP_ALL_TOTAL] = {"total_stress_all", "m^2/s^2",
                      "total shear stress from every statistics snapshot: the particles' kinetic "
                      "flux and the flux of all the forces through the plane (the force pass's "
                      "whole acceleration), where total_stress sums the parts of the budget "
                      "snapshots (every stats.budget_every-th); their difference is the parts' "
                      "sampling"},
    [EP_ALL_EXPECTED] = {"total_stress_expected_all", "m^2/s^2",
                         "total_stress_expected over every statistics snapshot"},
    [EP_ALL_INERTIA] = {"momentum_change_all", "m^2/s^2",
                        "momentum_change over every statistics snapshot (first to last): "
                        "total_stress_all + momentum_change_all = total_stress_expected_all"},
    [EP_ALL_SE] = {"total_stress_all_stderr", "m^2/s^2",
                   "standard error of total_stress_all (batch means)"},
    [EP_UU_BIN + 0] = {"uu_bin", "m^2/s^2",
                       "<u'u'> about the bin mean: includes the spread of the mean velocity over "
                       "the bin (compare --binned)"},
    [EP_UU_BIN + 1] = {"vv_bin", "m^2/s^2", "<v'v'> about the bin mean (compare --binned)"},
    [EP_UU_BIN + 2] = {"ww_bin", "m^2/s^2", "<w'w'> about the bin mean (compare --binned)"},
    [EP_UU_BIN + 3] = {"uv_bin", "m^2/s^2",
                       "<u'v'> about the bin mean: includes the covariance of the mean velocity "
                       "with v over the bin (compare --binned)"},
    [EP_UU_BIN + 4] = {"uw_bin", "m^2/s^2", "<u'w'> about the bin mean (compare --binned)"},
    [EP_UU_BIN + 5] = {"vw_bin", "m^2/s^2", "<v'w'> about the bin mean (compare --binned)"},
    [EP_LOCAL] = {"local_mean", "1",
                  "flag: 1 where uu .. vw are fluctuations about the local mean U(y) = U_b + "
                  "dU/dy (y - y_mean) (the bin's co-moments with y), 0 where about the bin mean "
                  "(records of checkpoint format 1.11 or older in the range)"},
    [EP_CORR_TIME] = {"correlation_time_bin", "s",
                      "integrated correlation time of the bin's per-snapshot mean of u "
                      "(statistical inefficiency of the batch means)"},
    [EP_NEFF] = {"n_eff_windows", "1",
                 "effective number of independent windows behind the batch-means standard "
                 "errors at the bin's correlation time (exponential correlation; the complete "
                 "windows when they are much longer than it)"},
    [EP_SHORT] = {"short_windows", "1",
                  "flag: 1 where the averaging windows are shorter than the bin's correlation "
                  "time (its batch-means standard errors are too small; compare widens them by "
                  "sqrt(n_windows / n_eff_windows))"},
    [EP_RSB] = RSB_ALL("", "Reynolds-stress "),
    [EP_RSB_SE] = RSB_ALL("_stderr", "standard error (batch means) of the Reynolds-stress "),
};

double euler_centre(const struct euler_config *cfg, int i) {
  return cfg->y0 + (i + 0.5) * (cfg->y1 - cfg->y0) / cfg->nb;
}

static void widen_mom(void *owner, int rank, const size_t *dims);

/** One per-window array of struct euler: its checkpoint name, fields per record, the record
    width an older checkpoint format may hold (0: none; after_read widens it), per bin (1) or
    one record per window (0), where it is in struct euler, and whether a checkpoint of an
    earlier format may lack it. */
struct euler_array {
  const char *name;
  size_t len, len_old;
  int per_bin;
  size_t offset;
  int optional;
  void (*after_read)(void *owner, int rank, const size_t *dims);
};

/* The per-window arrays, in the order of enum EULER_ARRAYS (euler.h). */
static const struct euler_array euler_arrays[EULER_ARRAYS] = {
    {"stats/eulerian/windows", WIN_LEN, 0, 0, offsetof(struct euler, win), 0, NULL},
    /* format 1.11 has 21 moments per record */
    {"stats/eulerian/moments", MOM_LEN, MOM_LEN_1_11, 1, offsetof(struct euler, mom), 0, widen_mom},
    {"stats/eulerian/snapshot_u", SCAL_LEN, 0, 1, offsetof(struct euler, snp), 0, NULL},
    /* format 1.1 has no budget: zero rows, no budget profiles */
    {"stats/eulerian/planes", PL_LEN, 0, 1, offsetof(struct euler, pln), 1, NULL},
    /* format 1.4: before it, rows without the advective part */
    {"stats/eulerian/planes_kinetic", KN_LEN, 0, 1, offsetof(struct euler, kin), 1, NULL},
    /* format 1.6: before it, rows without the Reynolds-stress budget */
    {"stats/eulerian/reynolds_budget", RW_LEN, 0, 1, offsetof(struct euler, rsb), 1, NULL},
    /* format 1.14: before it, the total from the budget samples' parts only */
    {"stats/eulerian/planes_total", PL_LEN, 0, 1, offsetof(struct euler, tpl), 1, NULL},
    {"stats/eulerian/planes_total_kinetic", KN_LEN, 0, 1, offsetof(struct euler, tkn), 1, NULL},
};

/* The array a of e (a pointer to its member). */
static double **array_of(struct euler *e, int a) {
  return (double **)(void *)((char *)e + euler_arrays[a].offset);
}

/* Make room for rows 0..rows-1; new rows are zero. */
static void reserve_rows(struct euler *e, size_t rows) {
  if (rows <= e->cap) return;
  const size_t nb = (size_t)e->cfg.nb, old = e->cap;
  size_t cap = old ? old : 8;
  while (cap < rows) cap *= 2;
  for (int a = 0; a < EULER_ARRAYS; a++) {
    const size_t row = euler_arrays[a].len * (euler_arrays[a].per_bin ? nb : 1);
    double **p = array_of(e, a);
    *p = mem_realloc(*p, cap * row, sizeof(double), "Eulerian statistics");
    memset(*p + old * row, 0, (cap - old) * row * sizeof(double));
  }
  e->cap = cap;
}

static void open_row(struct euler *e, double t0) {
  reserve_rows(e, e->nwin + 1);
  double *w = e->win + e->nwin * WIN_LEN;
  w[WIN_T0] = t0;
  w[WIN_T1] = e->cfg.window > 0.0 ? t0 + e->cfg.window : INFINITY;
}

/* Shape of the Wendland kernel (thesis Eq. 2.63-2.66) without its constant: the constant
   cancels in the ratio of Eq. 5.56. */
static double wendland_shape(double q) {
  if (q >= 2.0) return 0.0;
  const double t = 1.0 - 0.5 * q;
  return t * t * t * t * (2.0 * q + 1.0);
}

/* W1(s) = int over the plane of w(sqrt(s^2 + rho^2)): in 3-D proportional to
   int_0^L w(sqrt(s^2 + t^2)) t dt, in 2-D to int_0^L w(sqrt(s^2 + t^2)) dt, L = sqrt(4 - s^2)
   (composite Simpson, 256 intervals). */
static void build_w1(struct euler *e) {
  for (int i = 0; i <= EULER_W1_N; i++) {
    const double s = 2.0 * i / EULER_W1_N, L = sqrt(fmax(0.0, 4.0 - s * s));
    const int m = 256;
    double sum = 0.0;
    for (int k = 0; k <= m; k++) {
      const double t = L * k / m, c = k == 0 || k == m ? 1.0 : k % 2 ? 4.0 : 2.0;
      sum += c * wendland_shape(sqrt(s * s + t * t)) * (e->cfg.dim == 3 ? t : 1.0);
    }
    e->w1[i] = sum * L / (3.0 * m);
  }
}

static double w1_at(const struct euler *e, double q) {
  const double x = q * (0.5 * EULER_W1_N);
  if (x >= EULER_W1_N) return 0.0;
  const int i = (int)x;
  return e->w1[i] + (x - i) * (e->w1[i + 1] - e->w1[i]);
}

void euler_init(struct euler *e, const struct euler_config *cfg) {
  memset(e, 0, sizeof *e);
  e->cfg = *cfg;
  if (cfg->method == EULER_SPH) build_w1(e);
  open_row(e, cfg->t_start);
}

void euler_free(struct euler *e) {
  struct euler_work *k = e->work;
  if (k) free(k->part), free(k->mine), free(k->all), free(k->scr), free(k->node), free(k);
  for (int a = 0; a < EULER_ARRAYS; a++) free(*array_of(e, a));
  memset(e, 0, sizeof *e);
}

size_t euler_rows(const struct euler *e) {
  return e->nwin + (e->win[e->nwin * WIN_LEN + WIN_NSNAP] > 0.0);
}

size_t euler_work_bytes(const struct euler *e) {
  const struct euler_work *k = e->work;
  if (!k) return 0;
  const size_t rec = (size_t)e->cfg.nb * EU_PART * sizeof(double);
  return sizeof *k + (k->part_cap + k->mine_cap + k->all_cap + k->scr_cap) * rec +
         2 * k->node_cap * sizeof(int);
}

size_t euler_sample_bytes(int nb, int ncol) {
  return (size_t)ncol * (size_t)nb * EU_PART * sizeof(double);
}

/* a := a merged with b, bin by bin (node records of nb bins). */
static void node_merge(double *restrict a, const double *restrict b, size_t nb) {
  for (size_t i = 0; i < nb; i++) {
    double *x = a + i * EU_PART;
    const double *y = b + i * EU_PART;
    mom_merge(x, y);
    for (int k = EU_PART_U; k < EU_PART; k++) x[k] += y[k];
  }
}

/* The maximal tree nodes inside [c0, c1), left to right, appended to k->node (n of them). */
static void subtrees(struct euler_work *k, size_t *n, int lo, int hi, int c0, int c1) {
  if (hi <= c0 || lo >= c1 || lo >= hi) return;
  if (c0 <= lo && hi <= c1) {
    if (*n == k->node_cap) {
      k->node_cap = k->node_cap ? 2 * k->node_cap : 64;
      k->node = mem_realloc(k->node, 2 * k->node_cap, sizeof(int), "Eulerian statistics");
    }
    k->node[2 * *n] = lo, k->node[2 * *n + 1] = hi, (*n)++;
    return;
  }
  const int mid = lo + (hi - lo) / 2;
  subtrees(k, n, lo, mid, c0, c1);
  subtrees(k, n, mid, hi, c0, c1);
}

/* Record of node [lo, hi) into out: a gathered subtree record if one is that node (nodes
   sorted by lo), else a leaf (column partial), else the merge of the two children. */
static void node_record(struct euler_work *k, size_t nb, int lo, int hi, const double *rec,
                        size_t nn, int depth, double *out) {
  const size_t len = nb * EU_PART;
  size_t a = 0, b = nn;
  while (a < b) { /* first node with node lo >= lo */
    const size_t m = a + (b - a) / 2;
    if (k->node[2 * m] < lo)
      a = m + 1;
    else
      b = m;
  }
  if (a < nn && k->node[2 * a] == lo && k->node[2 * a + 1] == hi) {
    memcpy(out, rec + a * len, len * sizeof(double));
    return;
  }
  if (hi - lo == 1) {
    memcpy(out, k->part + (size_t)lo * len, len * sizeof(double));
    return;
  }
  const int mid = lo + (hi - lo) / 2;
  double *right = k->scr + (size_t)depth * len;
  node_record(k, nb, lo, mid, rec, nn, depth + 1, out);
  node_record(k, nb, mid, hi, rec, nn, depth + 1, right);
  node_merge(out, right, nb);
}

/* The width of the planes through the bin from ya of width w: w, except folded in the bin that
   holds the centre, whose planes reach only to delta. */
static double plane_width(const struct euler_config *c, double ya, double w) {
  return c->fold && ya < c->delta && ya + w > c->delta ? c->delta - ya : w;
}

/* The momentum budget of one snapshot from its merged per-bin sums (snap: one EU_PART record
   per bin), added to the window's plane sums pl (docs/theory.md, "Momentum budget"). The
   planes are the bin edges, where no particle layer of the initial lattice lies (with
   output.n_bins = 0 the layers are the bin centres). A bin gets the average over the planes
   through it: the mean of its two edges, plus its own particles weighted by their offset
   from the bin centre, phi = (y - y_c) / w (a particle at y lies on the centre side of the
   fraction 1/2 + phi of those planes in the lower half, 1/2 - phi in the upper). With that weight
   the budget is an identity for the bin's kinetic flux, the bin mean of m u v / w: a particle that
   oscillates within a layer carries u'v' but crosses no edge, and the first moment of its forces
   balances it. The flux through a plane is what the fluid between it and the centre receives across
   it: minus the net pair force on that fluid, by term, and the pull of the wall on it (below the
   centre, or folded: the fluid of y < delta above the plane and the wall y = 0; above the
   centre: the fluid of y > delta below the plane, the wall y = 2 delta, and the signs of the
   stress convention, force on the fluid below). In a steady state they balance the body force
   on that fluid. The net pair force on a whole side (zero for a momentum-conserving scheme)
   is the momentum source. */
static void budget_planes(const struct euler_config *c, const double *snap, int off, double fx,
                          double t, double dt, double *pl, double *kin) {
  const int nb = c->nb;
  double tot[2][HB_LEN] = {{0}}, below[2][HB_LEN] = {{0}}, prev[PL_LEN] = {0}, mu0_prev = 0.0;
  for (int b = 0; b < nb; b++)
    for (int k = 0; k < 2 * HB_LEN; k++)
      tot[k / HB_LEN][k % HB_LEN] += snap[(size_t)b * EU_PART + (size_t)off + k];
  const double norm = c->rho0 * c->area * (c->fold ? 2.0 : 1.0), w = (c->y1 - c->y0) / nb;
  for (int e = 0; e <= nb; e++) { /* edge e: the bins below it are in `below` */
    double at[PL_LEN] = {0}, mu0_at = 0.0;
    const int lower = c->fold || c->y0 + e * w <= c->delta;
    /* the centre side of the plane: sums over it (-1 in the lower half: above the plane) */
    for (int k = 0; k < HB_LEN; k++) {
      const double centre = lower ? tot[0][k] - below[0][k] : below[1][k];
      const double sum = lower ? -centre : centre; /* stress convention */
      if (k < STATS_PART_WALL) {
        at[PL_PRESSURE + k] = sum / norm;
        at[PL_SOURCE] += (lower ? tot[0][k] : -tot[1][k]) / norm;
      } else if (k == STATS_PART_WALL) {
        at[PL_WALL] = sum / norm;
      } else if (k == HB_MASS) {
        at[PL_DRIVE] = (lower ? fx : -fx) * centre / norm;
      } else if (k == HB_MU) {
        at[PL_MU_LAST] = (lower ? centre : -centre) / norm;
      } else if (k == HB_MU0) {
        mu0_at = (lower ? centre : -centre) / norm;
      }
    }
    if (e > 0) {
      /* the first moments of bin e - 1, both sides (one is empty unless the bin holds the
         centre): in the stress convention the same sign on either side */
      const double *m1 = snap + (size_t)(e - 1) * EU_PART + (size_t)off + 2 * HB_LEN;
      double corr[PL_LEN] = {0}, mu0_corr = 0.0;
      for (int s = 0; s < 2; s++, m1 += HB_LEN) {
        for (int k = 0; k < STATS_PARTS; k++) corr[PL_PRESSURE + k] -= m1[k] / norm;
        corr[PL_DRIVE] += fx * m1[HB_MASS] / norm, corr[PL_MU_LAST] += m1[HB_MU] / norm;
        mu0_corr += m1[HB_MU0] / norm;
      }
      /* the kinetic flux: with the step dt, minus the change of the bin's momentum (as
         PL_MU_LAST) that the step's displacements alone made, over dt, which makes the budget
         of every step an identity; without it -(sum of m u v over the bin) / (rho0 A w),
         either side, w the width of the planes through the bin (budget_bin) */
      const double *hb = snap + (size_t)(e - 1) * EU_PART + (size_t)off;
      const double wb = plane_width(c, c->y0 + e * w - w, w);
      const double mu_now = 0.5 * (prev[PL_MU_LAST] + at[PL_MU_LAST]) + corr[PL_MU_LAST];
      const double mu_before = 0.5 * (mu0_prev + mu0_at) + mu0_corr;
      const double kinetic =
          dt > 0.0 ? -(mu_now - mu_before) / dt : -(hb[HB_UV] + hb[HB_LEN + HB_UV]) / (norm * wb);
      double *K = kin + (size_t)(e - 1) * KN_LEN, *P = pl + (size_t)(e - 1) * PL_LEN;
      if (K[KN_N] == 0.0) { /* the window's first snapshot, kept apart */
        K[KN_FIRST] = 1.0, K[KN_F_KINETIC] = kinetic;
        for (int k = PL_PRESSURE; k <= PL_DRIVE; k++)
          K[KN_F + k - PL_PRESSURE] = 0.5 * (prev[k] + at[k]) + corr[k];
      }
      K[KN_SUM] += kinetic, K[KN_N] += 1.0;
      for (int k = PL_PRESSURE; k <= PL_SOURCE; k++) P[k] += 0.5 * (prev[k] + at[k]) + corr[k];
      P[PL_MU_LAST] = mu_now;
      P[PL_T_LAST] = t;
      if (P[PL_N] == 0.0) P[PL_MU_FIRST] = P[PL_MU_LAST], P[PL_T_FIRST] = t;
      P[PL_N] += 1.0;
    }
    for (int k = 0; k < PL_LEN; k++) prev[k] = at[k];
    mu0_prev = mu0_at;
    if (e < nb)
      for (int k = 0; k < 2 * HB_LEN; k++)
        below[k / HB_LEN][k % HB_LEN] += snap[(size_t)e * EU_PART + (size_t)off + k];
  }
}

/* Close the open window when the snapshot at time t lies past its end; an empty open window
   moves forward to the interval holding the snapshot. */
static void advance_window(struct euler *e, double t) {
  const double len = e->cfg.window;
  for (double *w = e->win + e->nwin * WIN_LEN; t >= w[WIN_T1]; w = e->win + e->nwin * WIN_LEN) {
    if (w[WIN_NSNAP] > 0.0) {
      e->nwin++;
      open_row(e, w[WIN_T1]);
    } else {
      w[WIN_T0] += floor((t - w[WIN_T0]) / len) * len;
      w[WIN_T1] = w[WIN_T0] + len;
      if (t >= w[WIN_T1]) w[WIN_T0] = w[WIN_T1], w[WIN_T1] += len; /* rounding */
    }
  }
}

/* The budget sums of the bin and side of a particle at y (folded if the statistics fold) in
   the per-bin partials P (from the record on: EU_PART_PL or EU_PART_TL), and its phi: the
   fraction of the planes through the bin that have it on their centre side, less 1/2
   (budget_planes); folded, the bin that holds the centre has planes only up to delta. */
static double *budget_bin(const struct euler_config *c, double *P, double y, int upper,
                          double *phi) {
  const double scale = c->nb / (c->y1 - c->y0);
  int hb = (int)floor((y - c->y0) * scale);
  hb = hb < 0 ? 0 : hb >= c->nb ? c->nb - 1 : hb;
  const double ya = c->y0 + hb / scale;
  *phi = (y - ya) / plane_width(c, ya, 1.0 / scale) - 0.5;
  return P + (size_t)hb * EU_PART + (size_t)(!c->fold && upper) * HB_LEN;
}

/* Particle a's momentum budget into the per-bin partials P (EU_PART a bin, from the record
   on: EU_PART_PL, the parts of its x-acceleration f[0 .. np); EU_PART_TL, the whole one,
   np = 1): m times each at the position before the step yf, with its mass and momentum
   there (HB_MU0), and its momentum and m u v at the sampled position, each with its offset
   weight phi (budget_planes). The momentum is that of the sampled state. The half of the
   channel each goes to (folded: mirrored into the lower one): a particle within 1e-9 delta of
   the centre counts half in each, so that the centre layer of a mirror-symmetric flow, whose v
   is 0 up to rounding, is not sent to one side or the other by that rounding (its momentum and
   forces are on the centre side of every plane). */
static void budget_add(const struct euler_config *c, const struct stats_snapshot *s, size_t a,
                       double yf, const double *f, int np, double *P) {
  const double ma = s->m ? s->m[a] : 1.0, mu = ma * s->u[a];
  for (int side = 0; side < 2; side++) {
    const double wf = euler_side_weight(yf, c->delta, side);
    if (wf > 0.0) {
      double phi_f;
      const double yb = c->fold && side ? 2.0 * c->delta - yf : yf;
      double *Hf = budget_bin(c, P, yb, side, &phi_f), *Hf1 = Hf + 2 * HB_LEN;
      for (int k = 0; k < np; k++) {
        const double fk = wf * ma * f[k];
        Hf[k] += fk, Hf1[k] += fk * phi_f;
      }
      const double mf = wf * ma, muf = wf * mu;
      Hf[HB_MASS] += mf, Hf1[HB_MASS] += mf * phi_f, Hf[HB_MU0] += muf, Hf1[HB_MU0] += muf * phi_f;
    }
    const double wh = euler_side_weight(s->y[a], c->delta, side);
    if (wh > 0.0) {
      double phi;
      const double yb = c->fold && side ? 2.0 * c->delta - s->y[a] : s->y[a];
      const double vb = c->fold && side ? -s->v[a] : s->v[a], muh = wh * mu;
      double *H = budget_bin(c, P, yb, side, &phi), *H1 = H + 2 * HB_LEN;
      H[HB_MU] += muh, H1[HB_MU] += muh * phi, H[HB_UV] += muh * vb;
    }
  }
}

/* Particle a of the snapshot into its column's per-bin partials P (EU_PART a bin). */
static void add_particle(const struct euler *e, const struct stats_snapshot *s, size_t a,
                         double *P) {
  const struct euler_config *c = &e->cfg;
  const double scale = c->nb / (c->y1 - c->y0);
  double y = s->y[a], v = s->v[a];
  const int upper = y > c->delta;
  if (c->fold && upper) y = 2.0 * c->delta - y, v = -v;
  const double smp[MOM_NQ] = {s->u[a],
                              v,
                              s->w[a],
                              s->p[a],
                              s->rho[a],
                              y,
                              s->nu_t ? s->nu_t[a] : 0.0,
                              s->k_r ? s->k_r[a] : 0.0};
  if (s->sx || s->ax) { /* the momentum budget: its parts, its total */
    /* the forces and the body force acted at the positions before the step: y - dt v, less
       the shift (symplectic Euler, docs/theory.md) */
    const double yf =
        s->dt > 0.0 ? s->y[a] - s->dt * s->v[a] - (s->shift_dy ? s->shift_dy[a] : 0.0) : s->y[a];
    if (s->sx) budget_add(c, s, a, yf, s->sx + a * STATS_ACC, STATS_PARTS, P + EU_PART_PL);
    if (s->ax) budget_add(c, s, a, yf, s->ax + a, 1, P + EU_PART_TL);
    if (s->sx && s->dt > 0.0) euler_rs_add(c, s, a, yf, P, EU_PART, EU_PART_RS);
  }
  if (c->method == EULER_SPH) {
    /* Eq. 5.56 averaged over the plane y = y_i: every profile point within 2h takes the
       sample with weight V_a W1(|y_a - y_i| / h) (a weighted one-sample merge) */
    const double vol = s->m ? s->m[a] / s->rho[a] : 1.0, h2 = 2.0 * c->h;
    int lo = (int)ceil((y - h2 - c->y0) * scale - 0.5),
        hi = (int)floor((y + h2 - c->y0) * scale - 0.5);
    lo = lo < 0 ? 0 : lo, hi = hi >= c->nb ? c->nb - 1 : hi;
    for (int b = lo; b <= hi; b++) {
      const double wt = vol * w1_at(e, fabs(y - euler_centre(c, b)) / c->h);
      if (wt <= 0.0) continue;
      double one[MOM_LEN] = {0};
      one[MOM_N] = wt;
      for (int q = 0; q < MOM_NQ; q++) one[MOM_MEAN + q] = smp[q];
      double *Pb = P + (size_t)b * EU_PART;
      mom_merge(Pb, one);
      Pb[EU_PART_U] += wt * s->u[a], Pb[EU_PART_N] += wt;
    }
    return;
  }
  int b = (int)floor((y - c->y0) * scale);
  b = b < 0 ? 0 : b >= c->nb ? c->nb - 1 : b; /* samples outside [y0, y1]: end bins */
  double *Pb = P + (size_t)b * EU_PART;
  mom_add(Pb, smp);
  Pb[EU_PART_U] += s->u[a], Pb[EU_PART_N] += 1.0;
}

/* The partials of this rank's columns merged over the column tree on every rank: returns the
   root record (EU_PART a bin) of the snapshot, identical on every rank. */
static double *merge_columns(struct euler *e, struct spar *par) {
  struct euler_work *k = e->work;
  const size_t nb = (size_t)e->cfg.nb, ncol = (size_t)par->ncol, len = nb * EU_PART;
  /* 2. this rank's subtrees of the column tree, merged locally */
  int depth = 1;
  while ((1 << (depth - 1)) < par->ncol) depth++;
  if ((size_t)depth > k->scr_cap) {
    k->scr = mem_realloc(k->scr, (size_t)depth * len, sizeof(double), "Eulerian statistics");
    k->scr_cap = (size_t)depth;
  }
  size_t nmine = 0;
  subtrees(k, &nmine, 0, par->ncol, par->col0, par->col1);
  if (nmine + 1 > k->mine_cap) { /* + 1: the root record below */
    k->mine = mem_realloc(k->mine, (nmine + 1) * len, sizeof(double), "Eulerian statistics");
    k->mine_cap = nmine + 1;
  }
  for (size_t i = 0; i < nmine; i++)
    node_record(k, nb, k->node[2 * i], k->node[2 * i + 1], NULL, 0, 0, k->mine + i * len);
  /* 3. all subtrees on every rank of the block row (rank order is column order), merged up to
     the root */
  const size_t nall = spar_gather_row(par, k->mine, nmine, len, &k->all, &k->all_cap);
  size_t nn = 0;
  for (int r = 0; r < par->xsize; r++)
    subtrees(k, &nn, 0, par->ncol, par->range[2 * r], par->range[2 * r + 1]);
  if (nn != nall) die("statistics: %zu column subtrees gathered, %zu expected", nall, nn);
  node_record(k, nb, 0, (int)ncol, k->all, nn, 0, k->mine);
  e->nsub = nn;
  return k->mine;
}

/* Whether the merged snapshot holds the total's sums (some rank's particles carried their
   accelerations): the same answer on every rank, whether or not this rank had any. */
static int total_sampled(const double *snap, size_t nb) {
  double mass = 0.0;
  for (size_t b = 0; b < nb; b++)
    for (int side = 0; side < 2; side++)
      mass += snap[b * EU_PART + EU_PART_TL + side * HB_LEN + HB_MASS];
  return mass > 0.0;
}

void euler_close(struct euler *e, double t) {
  if (t >= e->cfg.t_start) advance_window(e, t);
}

void euler_sample(struct euler *e, const struct stats_snapshot *s) {
  const struct euler_config *c = &e->cfg;
  if (s->t < c->t_start) return;
  advance_window(e, s->t);
  const size_t nb = (size_t)c->nb;
  double *row = e->mom + e->nwin * nb * MOM_LEN;
  double *srow = e->snp + e->nwin * nb * SCAL_LEN;
  double *win = e->win + e->nwin * WIN_LEN;
  /* 1. per-(column, bin) partials of this rank's columns, particles in memory order (within a
     column the same order on any decomposition) */
  struct spar par;
  spar_open(&par, s);
  if (!e->work) {
    e->work = mem_alloc(1, sizeof(struct euler_work), "Eulerian statistics");
    memset(e->work, 0, sizeof(struct euler_work));
  }
  struct euler_work *k = e->work;
  const size_t ncol = (size_t)par.ncol, len = nb * EU_PART;
  if (ncol > k->part_cap) {
    k->part = mem_realloc(k->part, ncol * len, sizeof(double), "Eulerian statistics");
    k->part_cap = ncol;
  }
  double *mine = k->part + (size_t)par.col0 * len;
  const size_t nmine = (size_t)(par.col1 - par.col0) * len;
  memset(mine, 0, nmine * sizeof(double));
  spar_chain_begin(&par, mine, nmine); /* planes cut: the columns' partials from below */
  for (size_t a = 0; a < s->n; a++)
    if (!s->skip || !s->skip[a]) add_particle(e, s, a, mine + (size_t)spar_lcol(&par, s, a) * len);
  spar_chain_end(&par, mine, nmine);
  const double *snap = merge_columns(e, &par); /* 2, 3: every bin of the snapshot */
  spar_close(&par);
  for (size_t b = 0; b < nb; b++) {
    const double *R = snap + b * EU_PART;
    mom_merge(row + b * MOM_LEN, R);
    if (R[EU_PART_N] > 0.0) scal_add(srow + b * SCAL_LEN, R[EU_PART_U] / R[EU_PART_N]);
  }
  if (s->sx)
    budget_planes(c, snap, EU_PART_PL, s->fx, s->t, s->dt, e->pln + e->nwin * nb * PL_LEN,
                  e->kin + e->nwin * nb * KN_LEN);
  if (total_sampled(snap, nb)) /* the total, every snapshot with accelerations */
    budget_planes(c, snap, EU_PART_TL, s->fx, s->t, s->dt, e->tpl + e->nwin * nb * PL_LEN,
                  e->tkn + e->nwin * nb * KN_LEN);
  if (s->sx && s->dt > 0.0)
    euler_rs_snapshot(c, snap, EU_PART, EU_PART_RS, s->t, s->dt,
                      euler_rs_last_time(c, e->rsb, e->nwin), e->rsb + e->nwin * nb * RW_LEN);
  win[WIN_NSNAP] += 1.0;
  win[WIN_SUM_FX] += s->fx;
  /* wall shear stress over density: minus the wall force on the fluid per unit area (the wall
     terms and the non-conservative rest of the pair forces, sph_budget_pairs), plus the body
     force on the layer of fluid the wall vertices stand for, which stays at rest and so passes
     its body force to the wall (docs/theory.md, "Momentum at the walls") */
  if (!s->sx || !isfinite(s->wall_fx[0]) || !isfinite(s->wall_fx[1]))
    return; /* the wall stress comes with the budget samples only (counted by the planes) */
  win[WIN_SUM_TW0] += -s->wall_fx[0] / (c->rho0 * c->area) + s->fx * c->wall_layer;
  win[WIN_SUM_TW1] += -s->wall_fx[1] / (c->rho0 * c->area) + s->fx * c->wall_layer;
}

double euler_n_eff(double n, double window, double tau) {
  if (!(tau > 0.0) || !(window > 0.0) || !(n >= 1.0)) return NAN;
  const double x = tau / window;
  /* the variance of a mean over a span s of an exponentially correlated signal is
     2 tau / s sigma^2 a(tau / s), a(x) = 1 - x (1 - e^(-1/x)) */
  const double a1 = 1.0 + x * expm1(-1.0 / x), an = 1.0 + x / n * expm1(-n / x);
  return an > 0.0 ? n * a1 / an : NAN;
}

/* The derivative of f at point i: 3-point central (euler_deriv) between two neighbours with ok
   set; at an end, of the parabola through i and its next two neighbours (a linear one-sided
   difference is first order: in the wall bin it would leave (dU/dy error)^2 var(y) in the
   stresses about the local mean); euler_deriv's two points where only one neighbour exists. */
static double local_slope(const double *x, const double *f, const int *ok, int n, int i) {
  int l = i - 1, r = i + 1;
  while (l >= 0 && !ok[l]) l--;
  while (r < n && !ok[r]) r++;
  if ((l >= 0) == (r < n)) return euler_deriv(x, f, ok, n, i);
  const int step = l < 0 ? 1 : -1;
  int j1 = l < 0 ? r : l, j2 = j1 + step;
  while (j2 >= 0 && j2 < n && !ok[j2]) j2 += step;
  if (j2 < 0 || j2 >= n) return euler_deriv(x, f, ok, n, i);
  const double x0 = x[i], x1 = x[j1], x2 = x[j2];
  return f[i] * (2.0 * x0 - x1 - x2) / ((x0 - x1) * (x0 - x2)) +
         f[j1] * (x0 - x2) / ((x1 - x0) * (x1 - x2)) + f[j2] * (x0 - x1) / ((x2 - x0) * (x2 - x1));
}

/* The covariance c (MOM_UU .. MOM_VW) of a moment record m about the local mean
   U_i(y) = U_i + g_i (y - <y>) of the bin: C_ij - g_i C_jy - g_j C_iy + g_i g_j C_yy over n
   (the bin mean's covariance if the record has no co-moments with y: NaN there). */
static double local_cov(const double *m, const double *g, int c) {
  const int i = mom_pair[c][0], j = mom_pair[c][1];
  const double n = m[MOM_N];
  const double l =
      m[MOM_C2 + c] - g[i] * m[MOM_CY + j] - g[j] * m[MOM_CY + i] + g[i] * g[j] * m[MOM_CYY];
  return (isfinite(l) ? l : m[MOM_C2 + c]) / n;
}

/* The stresses of every bin about the local mean (EP_UU .. EP_VW, their standard errors from
   the complete windows' own, about the same U(y)) where the range's records have the
   co-moments with y, the bin-mean ones kept in EP_UU_BIN ..; the gradients of U, V, W at each
   bin's mean position (local_slope; zero where a bin has no neighbour) in grad. */
static void local_stresses(const struct euler_config *cfg, const double *mom, const int *complete,
                           size_t r0, size_t r1, const double *tot, const int *ok, double *grad,
                           struct euler_result *res) {
  const int nb = cfg->nb;
  double *const *pr = res->prof;
  res->local_mean = 1;
  for (int b = 0; b < nb; b++) {
    double *g = grad + 3 * b;
    for (int i = 0; i < 3; i++) {
      g[i] = ok[b] ? local_slope(pr[EP_Y_MEAN], pr[EP_U + i], ok, nb, b) : 0.0;
      if (!isfinite(g[i])) g[i] = 0.0;
    }
    for (int c = 0; c < MOM_NC; c++) pr[EP_UU_BIN + c][b] = pr[EP_UU + c][b];
    const double *M = tot + (size_t)b * MOM_LEN;
    const int local = ok[b] && isfinite(M[MOM_CYY]) && isfinite(M[MOM_CY]) &&
                      isfinite(M[MOM_CY + 1]) && isfinite(M[MOM_CY + 2]);
    pr[EP_LOCAL][b] = ok[b] ? local : NAN;
    if (!local) {
      if (ok[b]) res->local_mean = 0;
      continue;
    }
    double batch[MOM_NC][SCAL_LEN] = {{0}};
    for (size_t r = r0; r < r1; r++) {
      const double *m = mom + (r * (size_t)nb + (size_t)b) * MOM_LEN;
      if (!complete[r] || m[MOM_N] <= 0.0) continue;
      for (int c = 0; c < MOM_NC; c++) scal_add(batch[c], local_cov(m, g, c));
    }
    for (int c = 0; c < MOM_NC; c++) {
      pr[EP_UU + c][b] = local_cov(M, g, c);
      pr[EP_SE_U + 5 + c][b] =
          batch[c][SCAL_N] >= 2.0
              ? sqrt(batch[c][SCAL_M2] / (batch[c][SCAL_N] - 1.0) / batch[c][SCAL_N])
              : NAN;
    }
  }
}

/* The sums of bin b's plane records pln and kinetic records kin (NULL or short in files of
   earlier versions) over rows [r0, r1): sum (PL_LEN: the sums, and the momentum and time of
   the range's first and last snapshot) and ksum (KN_N, KN_SUM); with the kinetic records of
   every row, the range's fluxes without its first snapshot, which the momentum change starts
   from. Returns whether the kinetic records were complete (the advective part is known). */
static int range_sums(int nb, int b, const double *pln, const double *kin, size_t r0, size_t r1,
                      double *sum, double *ksum) {
  const double *K0 = NULL; /* the kinetic record of the range's first row with snapshots */
  int first = 0, has_kin = kin != NULL;
  memset(sum, 0, PL_LEN * sizeof *sum), ksum[KN_N] = ksum[KN_SUM] = 0.0;
  for (size_t r = r0; r < r1; r++) {
    const double *p = pln + (r * (size_t)nb + (size_t)b) * PL_LEN;
    const double *K = kin ? kin + (r * (size_t)nb + (size_t)b) * KN_LEN : NULL;
    for (int k = 0; k <= PL_SOURCE; k++) sum[k] += p[k];
    if (K && K[KN_N] == p[PL_N] && (K[KN_FIRST] == 1.0 || p[PL_N] == 0.0))
      ksum[KN_N] += K[KN_N], ksum[KN_SUM] += K[KN_SUM];
    else
      has_kin = 0;
    if (p[PL_N] > 0.0) { /* the unsteady term: first and last snapshots of the range */
      if (!first)
        sum[PL_MU_FIRST] = p[PL_MU_FIRST], sum[PL_T_FIRST] = p[PL_T_FIRST], first = 1, K0 = K;
      sum[PL_MU_LAST] = p[PL_MU_LAST], sum[PL_T_LAST] = p[PL_T_LAST];
    }
  }
  /* with the kinetic records: the range's fluxes without its first snapshot, the balance of
     the momentum change from that snapshot to the last */
  if (has_kin && K0 && K0[KN_FIRST] == 1.0 && sum[PL_N] >= 2.0) {
    for (int k = PL_PRESSURE; k <= PL_DRIVE; k++) sum[k] -= K0[KN_F + k - PL_PRESSURE];
    sum[PL_N] -= 1.0, ksum[KN_SUM] -= K0[KN_F_KINETIC], ksum[KN_N] -= 1.0;
  }
  return has_kin;
}

/* The standard error of a batch-mean record (NaN below two batches). */
static double batch_stderr(const double *w) {
  return w[SCAL_N] >= 2.0 ? sqrt(w[SCAL_M2] / (w[SCAL_N] - 1.0) / w[SCAL_N]) : NAN;
}

/* Profiles of the momentum budget over rows [r0, r1) (pln: the plane sums; kin: the kinetic
   flux, NULL or short in files of earlier versions): the mean of each part, the Reynolds part
   -<u'v'>, the rest of the particles' kinetic flux as the advective part (NaN, and left out
   of the total, where a row lacks it), their sum as total_stress and the drive as its
   expected value, with batch-means standard errors over the complete windows. Returns 0 if no
   snapshot of the range carried the forces (the profiles stay as they are). */
static int budget_profiles(const struct euler_config *cfg, const double *mom, const double *pln,
                           const double *kin, const int *complete, size_t r0, size_t r1,
                           const double *grad, struct euler_result *res) {
  const int nb = cfg->nb;
  int any = 0;
  for (int b = 0; b < nb; b++) {
    double sum[PL_LEN], ksum[KN_LEN], batch[7][SCAL_LEN] = {{0}};
    const int has_kin = range_sums(nb, b, pln, kin, r0, r1, sum, ksum);
    for (size_t r = r0; r < r1; r++) {
      const double *p = pln + (r * (size_t)nb + (size_t)b) * PL_LEN;
      const double *K = kin ? kin + (r * (size_t)nb + (size_t)b) * KN_LEN : NULL;
      const double *m = mom + (r * (size_t)nb + (size_t)b) * MOM_LEN;
      if (!complete[r] || p[PL_N] <= 0.0 || m[MOM_N] <= 0.0) continue;
      /* in the order of EP_TAU_*: Reynolds, viscous, model, pair, wall, advective; the total */
      const double uv = res->prof[EP_LOCAL][b] == 1.0 ? local_cov(m, grad + 3 * b, MOM_UV)
                                                      : m[MOM_C2 + MOM_UV] / m[MOM_N];
      double w[7] = {-uv, p[PL_VISCOUS] / p[PL_N], p[PL_MODEL] / p[PL_N], p[PL_PRESSURE] / p[PL_N],
                     p[PL_WALL] / p[PL_N]};
      w[5] = K && K[KN_N] == p[PL_N] ? K[KN_SUM] / K[KN_N] - w[0] : 0.0;
      w[6] = w[0] + w[1] + w[2] + w[3] + w[4] + w[5];
      for (int k = 0; k < 7; k++) scal_add(batch[k], w[k]);
    }
    if (sum[PL_N] <= 0.0) {
      for (int k = EP_TAU_REYNOLDS; k < EP_SE_TAU_END; k++) res->prof[k][b] = NAN;
      continue;
    }
    any = 1;
    const double n = sum[PL_N];
    double *const *pr = res->prof;
    pr[EP_TAU_REYNOLDS][b] = -pr[EP_UV][b];
    pr[EP_TAU_VISCOUS][b] = sum[PL_VISCOUS] / n, pr[EP_TAU_MODEL][b] = sum[PL_MODEL] / n;
    pr[EP_TAU_PAIR][b] = sum[PL_PRESSURE] / n, pr[EP_TAU_WALL][b] = sum[PL_WALL] / n;
    pr[EP_TAU_ADVECT][b] = has_kin ? ksum[KN_SUM] / ksum[KN_N] - pr[EP_TAU_REYNOLDS][b] : NAN;
    pr[EP_TOTAL][b] = pr[EP_TAU_REYNOLDS][b] + pr[EP_TAU_VISCOUS][b] + pr[EP_TAU_MODEL][b] +
                      pr[EP_TAU_PAIR][b] + pr[EP_TAU_WALL][b] +
                      (has_kin ? pr[EP_TAU_ADVECT][b] : 0.0);
    pr[EP_TOTAL_EXPECTED][b] = sum[PL_DRIVE] / n;
    pr[EP_TAU_SOURCE][b] = sum[PL_SOURCE] / n;
    const double span = sum[PL_T_LAST] - sum[PL_T_FIRST];
    pr[EP_TAU_INERTIA][b] = span > 0.0 ? (sum[PL_MU_LAST] - sum[PL_MU_FIRST]) / span : NAN;
    for (int k = 0; k < 7; k++)
      pr[EP_SE_TAU + k][b] = k != 5 || has_kin ? batch_stderr(batch[k]) : NAN;
  }
  return any;
}

/* The total of the momentum budget from every snapshot (tpl, tkn: euler.h, TL_FORCES) over
   rows [r0, r1), where the range has them with the kinetic flux in every row (else NaN): the
   total (the kinetic flux and the flux of all forces), its expected value, the momentum change
   over the same snapshots and the total's standard error. */
static void total_profiles(const struct euler_config *cfg, const double *tpl, const double *tkn,
                           const int *complete, size_t r0, size_t r1, struct euler_result *res) {
  const int nb = cfg->nb;
  for (int b = 0; b < nb; b++) {
    double sum[PL_LEN], ksum[KN_LEN], batch[SCAL_LEN] = {0};
    double *const *pr = res->prof;
    pr[EP_ALL_TOTAL][b] = pr[EP_ALL_EXPECTED][b] = pr[EP_ALL_INERTIA][b] = pr[EP_ALL_SE][b] = NAN;
    if (!tpl || !tkn || !range_sums(nb, b, tpl, tkn, r0, r1, sum, ksum) || sum[PL_N] <= 0.0)
      continue;
    for (size_t r = r0; r < r1; r++) {
      const double *p = tpl + (r * (size_t)nb + (size_t)b) * PL_LEN;
      const double *K = tkn + (r * (size_t)nb + (size_t)b) * KN_LEN;
      if (complete[r] && p[PL_N] > 0.0) scal_add(batch, (K[KN_SUM] + p[TL_FORCES]) / p[PL_N]);
    }
    const double n = sum[PL_N], span = sum[PL_T_LAST] - sum[PL_T_FIRST];
    pr[EP_ALL_TOTAL][b] = ksum[KN_SUM] / ksum[KN_N] + sum[TL_FORCES] / n;
    pr[EP_ALL_EXPECTED][b] = sum[PL_DRIVE] / n;
    pr[EP_ALL_INERTIA][b] = span > 0.0 ? (sum[PL_MU_LAST] - sum[PL_MU_FIRST]) / span : NAN;
    pr[EP_ALL_SE][b] = batch_stderr(batch);
  }
}

/* Batch moments per bin: 5 means, 6 stresses, the skewness and flatness of u, v, w. */
enum { BM_SKEW = 11, BM_FLAT = 14, BM_LEN = 17 };

/* Add the skewness and flatness of u, v, w of one window's moment record m (n > 0) to the
   batch moments B (windows where a component has no variance are left out). */
static void window_shape(const double *m, double *B) {
  for (int i = 0; i < 3; i++) {
    const double m2 = m[MOM_C2 + i] / m[MOM_N];
    if (!(m2 > 0.0)) continue;
    scal_add(B + (BM_SKEW + i) * SCAL_LEN, m[MOM_M3 + i] / m[MOM_N] / pow(m2, 1.5));
    scal_add(B + (BM_FLAT + i) * SCAL_LEN, m[MOM_M4 + i] / m[MOM_N] / (m2 * m2));
  }
}

/* The profiles of bin b from its merged moment record m and the batch moments B (BM_LEN);
   returns 1 if the bin has samples. */
static int bin_profiles(const struct euler_config *cfg, int b, const double *m, const double *B,
                        struct euler_result *res) {
  const double n = m[MOM_N], nan = NAN;
  res->prof[EP_Y][b] = euler_centre(cfg, b);
  res->prof[EP_N][b] = n;
  res->prof[EP_Y_MEAN][b] = n > 0.0 ? m[MOM_MEAN + MOM_Y] : res->prof[EP_Y][b];
  for (int q = 0; q < 5; q++) res->prof[EP_U + q][b] = n > 0.0 ? m[MOM_MEAN + q] : nan;
  res->prof[EP_NUT][b] = n > 0.0 ? m[MOM_MEAN + MOM_NUT] : nan;
  res->prof[EP_KR][b] = n > 0.0 ? m[MOM_MEAN + MOM_KR] : nan;
  for (int c = 0; c < MOM_NC; c++) res->prof[EP_UU + c][b] = n > 0.0 ? m[MOM_C2 + c] / n : nan;
  for (int i = 0; i < 3; i++) {
    const double m2 = m[MOM_C2 + i] / n;
    res->prof[EP_SKEW_U + i][b] = n > 0.0 && m2 > 0.0 ? m[MOM_M3 + i] / n / pow(m2, 1.5) : nan;
    res->prof[EP_FLAT_U + i][b] = n > 0.0 && m2 > 0.0 ? m[MOM_M4 + i] / n / (m2 * m2) : nan;
  }
  for (int k = 0; k < BM_LEN; k++) {
    const double *s = B + k * SCAL_LEN;
    res->prof[k < BM_SKEW ? EP_SE_U + k : EP_SE_SF + k - BM_SKEW][b] =
        s[SCAL_N] >= 2.0 ? sqrt(s[SCAL_M2] / (s[SCAL_N] - 1.0) / s[SCAL_N]) : nan;
  }
  return n > 0.0;
}

/* The shear-stress balance (Eq. 5.11-5.13; the momentum budget where the snapshots carried
   the forces) and its largest error over the interior bins. */
static void stress_balance(const struct euler_config *cfg, const double *mom, const double *pln,
                           const double *kin, const double *tpl, const double *tkn,
                           const int *complete, size_t r0, size_t r1, const int *ok,
                           const double *grad, double tw_force, struct euler_result *res) {
  const int nb = cfg->nb;
  const double nan = NAN;
  /* shear-stress balance (Eq. 5.11-5.13): nu dU/dy - <u'v'> = tau_w/rho (1 - y/delta) */
  res->balance_error = 0.0;
  for (int b = 0; b < nb; b++) {
    const double dudy = ok[b] ? euler_deriv(res->prof[EP_Y_MEAN], res->prof[EP_U], ok, nb, b) : nan;
    const double yb = res->prof[EP_Y_MEAN][b];
    /* with LES the modelled stress <nu_t> dU/dy joins the viscous one (Eq. 5.45) */
    const double nu_eff = cfg->nu + (cfg->les && ok[b] ? res->prof[EP_NUT][b] : 0.0);
    res->prof[EP_VISC][b] = nu_eff * dudy;
    res->prof[EP_TOTAL][b] = nu_eff * dudy - res->prof[EP_UV][b];
    res->prof[EP_TOTAL_EXPECTED][b] = tw_force * (1.0 - yb / cfg->delta);
  }
  res->budget = pln && budget_profiles(cfg, mom, pln, kin, complete, r0, r1, grad, res);
  if (!res->budget)
    for (int k = EP_TAU_REYNOLDS; k < EP_SE_TAU_END; k++)
      for (int b = 0; b < nb; b++) res->prof[k][b] = nan;
  total_profiles(cfg, tpl, tkn, complete, r0, r1, res);
  for (int b = 0; b < nb; b++) {
    if (b > 0 && b < nb - 1 && ok[b] && tw_force > 0.0) {
      const double err = fabs(res->prof[EP_TOTAL][b] - res->prof[EP_TOTAL_EXPECTED][b]) / tw_force;
      if (err > res->balance_error) res->balance_error = err;
    }
  }
}

/* The samples of row r that carry the wall shear stress: the budget samples (every
   stats.budget_every-th), which the planes count in each bin; every sample in files without
   the planes (format 1.1, when each sample carried it). */
static double wall_samples(const struct euler_config *cfg, const double *win, const double *pln,
                           size_t r) {
  return pln ? pln[r * (size_t)cfg->nb * PL_LEN + PL_N] : win[r * WIN_LEN + WIN_NSNAP];
}

/* The correlation time of each bin (EP_CORR_TIME) and their mean over the bins: the
   statistical inefficiency s of the per-snapshot bin means (batch variance sn times the batch
   size over the variance within the batches), correlation time = s dt_sample / 2. */
static void corr_times(int nb, const double *sn, const double *within, double per_batch,
                       double dt_s, struct euler_result *res) {
  double tau_sum = 0.0;
  int tau_n = 0;
  for (int b = 0; b < nb; b++) {
    const double *s = sn + (size_t)b * SCAL_LEN;
    res->prof[EP_CORR_TIME][b] = NAN;
    if (s[SCAL_N] >= 2.0 && within[2 * b + 1] > 0.0 && within[2 * b] > 0.0 && per_batch > 0.0) {
      const double var_b = s[SCAL_M2] / (s[SCAL_N] - 1.0);
      const double var_w = within[2 * b] / within[2 * b + 1];
      const double ineff = fmax(1.0, per_batch * var_b / var_w);
      res->prof[EP_CORR_TIME][b] = 0.5 * ineff * dt_s;
      tau_sum += 0.5 * ineff * dt_s, tau_n++;
    }
  }
  res->corr_time = tau_n ? tau_sum / tau_n : NAN;
}

void euler_finalise(const struct euler_config *cfg, const double *win, const double *mom,
                    const double *snp, const double *pln, const double *kin, const double *rsb,
                    const double *tpl, const double *tkn, const int *complete, size_t r0, size_t r1,
                    struct euler_result *res) {
  const int nb = cfg->nb;
  memset(res, 0, sizeof *res);
  res->nb = nb;
  for (int k = 0; k < EP_NPROF; k++)
    res->prof[k] = mem_alloc((size_t)nb, sizeof(double), "Eulerian statistics");
  const char *lbl = "Eulerian statistics";
  double *tot = mem_calloc((size_t)nb * MOM_LEN, sizeof(double), lbl);
  double *bm = mem_calloc((size_t)nb * BM_LEN * SCAL_LEN, sizeof(double), lbl); /* batches */
  double *sn = mem_calloc((size_t)nb * SCAL_LEN, sizeof(double), lbl);
  double *within = mem_calloc((size_t)nb * 2, sizeof(double), lbl);
  double snaps = 0.0, walls = 0.0, sum_fx = 0.0, sum_tw = 0.0, tw_batch[SCAL_LEN] = {0, 0, 0};
  double batch_len = 0.0;
  res->t0 = r1 > r0 ? win[r0 * WIN_LEN + WIN_T0] : NAN;
  res->t1 = r1 > r0 ? win[(r1 - 1) * WIN_LEN + WIN_T1] : NAN;
  for (size_t r = r0; r < r1; r++) {
    const double *w = win + r * WIN_LEN;
    snaps += w[WIN_NSNAP], sum_fx += w[WIN_SUM_FX];
    const double nw = wall_samples(cfg, win, pln, r);
    walls += nw, sum_tw += 0.5 * (w[WIN_SUM_TW0] + w[WIN_SUM_TW1]);
    for (int b = 0; b < nb; b++) {
      const double *m = mom + (r * (size_t)nb + (size_t)b) * MOM_LEN;
      mom_merge(tot + (size_t)b * MOM_LEN, m);
      const double *s = snp + (r * (size_t)nb + (size_t)b) * SCAL_LEN;
      if (s[SCAL_N] > 0.0) {
        within[2 * b] += s[SCAL_M2], within[2 * b + 1] += s[SCAL_N] - 1.0;
      }
      if (!complete[r] || m[MOM_N] <= 0.0) continue;
      double *B = bm + (size_t)b * BM_LEN * SCAL_LEN;
      for (int q = 0; q < 5; q++) scal_add(B + q * SCAL_LEN, m[MOM_MEAN + q]);
      for (int c = 0; c < MOM_NC; c++) scal_add(B + (5 + c) * SCAL_LEN, m[MOM_C2 + c] / m[MOM_N]);
      window_shape(m, B);
      if (s[SCAL_N] > 0.0) scal_add(sn + (size_t)b * SCAL_LEN, s[SCAL_MEAN]);
    }
    if (complete[r] && w[WIN_NSNAP] > 0.0) {
      if (nw > 0.0) scal_add(tw_batch, 0.5 * (w[WIN_SUM_TW0] + w[WIN_SUM_TW1]) / nw);
      batch_len += w[WIN_T1] - w[WIN_T0];
      res->n_batches++;
    }
  }
  res->snapshots = snaps;
  const double nan = NAN;
  int *ok = mem_alloc((size_t)nb, sizeof(int), "Eulerian statistics");
  double *grad = mem_alloc(3 * (size_t)nb, sizeof(double), "Eulerian statistics");
  for (int b = 0; b < nb; b++)
    ok[b] =
        bin_profiles(cfg, b, tot + (size_t)b * MOM_LEN, bm + (size_t)b * BM_LEN * SCAL_LEN, res);
  local_stresses(cfg, mom, complete, r0, r1, tot, ok, grad, res);
  const double per_batch = r1 > r0 ? snaps / (double)(r1 - r0) : 0.0;
  const double len = res->n_batches ? batch_len / res->n_batches : nan;
  corr_times(nb, sn, within, per_batch, len / per_batch, res);
  res->n_eff = euler_n_eff(res->n_batches, len, res->corr_time);
  for (int b = 0; b < nb; b++) {
    const double tau = res->prof[EP_CORR_TIME][b];
    res->prof[EP_NEFF][b] = euler_n_eff(res->n_batches, len, tau);
    res->prof[EP_SHORT][b] = isfinite(tau) ? (double)(len < tau) : nan;
  }
  const double tw_force = snaps > 0.0 ? cfg->delta * sum_fx / snaps : nan;
  const double tw_wall = walls > 0.0 ? sum_tw / walls : nan;
  res->u_tau_force = tw_force >= 0.0 ? sqrt(tw_force) : nan;
  res->u_tau_wall = tw_wall >= 0.0 ? sqrt(tw_wall) : nan;
  res->u_tau =
      isfinite(res->u_tau_wall) && res->u_tau_wall > 0.0 ? res->u_tau_wall : res->u_tau_force;
  res->u_tau_stderr = tw_batch[SCAL_N] >= 2.0 && res->u_tau_wall > 0.0
                          ? sqrt(tw_batch[SCAL_M2] / (tw_batch[SCAL_N] - 1.0) / tw_batch[SCAL_N]) /
                                (2.0 * res->u_tau_wall)
                          : nan;
  res->re_tau = res->u_tau * cfg->delta / cfg->nu;
  stress_balance(cfg, mom, pln, kin, tpl, tkn, complete, r0, r1, ok, grad, tw_force, res);
  res->rs_budget = euler_rs_profiles(cfg, rsb, complete, r0, r1, res);
  if (!(tw_force > 0.0)) res->balance_error = nan;
  free(ok), free(grad), free(tot), free(bm), free(sn), free(within);
}

void euler_result_free(struct euler_result *res) {
  for (int k = 0; k < EP_NPROF; k++) free(res->prof[k]);
  memset(res, 0, sizeof *res);
}

/* The checkpoint reader's callback of every per-window array (state.h): checks the stored
   shape (rows, bins, record width) and makes room for the rows it says the run had; the
   windows' record also gives the closed windows. */
static void *reserve_array(void *owner, int rank, const size_t *dims) {
  const struct euler_array_owner *o = owner;
  const struct euler_array *A = &euler_arrays[o->a];
  struct euler *e = o->e;
  if (rank != (A->per_bin ? 3 : 2) || (!A->per_bin && dims[0] < 1)) return NULL;
  if (A->per_bin && dims[1] != (size_t)e->cfg.nb) return NULL;
  const size_t width = dims[rank - 1];
  if (width != A->len && !(A->len_old && width == A->len_old)) return NULL;
  reserve_rows(e, dims[0]);
  if (!A->per_bin) e->nwin = dims[0] - 1;
  return *array_of(e, o->a);
}

void euler_widen_moments(double *mom, size_t records, size_t width) {
  if (width >= MOM_LEN) return;
  for (size_t i = records; i-- > 0;) { /* from the end: the wide records end later */
    double *dst = mom + i * MOM_LEN;
    memmove(dst, mom + i * width, width * sizeof(double));
    for (size_t k = width; k < MOM_LEN; k++) dst[k] = dst[MOM_N] > 0.0 ? NAN : 0.0;
  }
}

static void widen_mom(void *owner, int rank, const size_t *dims) {
  const struct euler_array_owner *o = owner;
  if (rank == 3) euler_widen_moments(o->e->mom, dims[0] * dims[1], dims[2]);
}

void euler_state(struct euler *e, struct state_list *L) {
  const size_t rows = e->nwin + 1, nb = (size_t)e->cfg.nb;
  for (int a = 0; a < EULER_ARRAYS; a++) {
    const struct euler_array *A = &euler_arrays[a];
    const size_t dims[3] = {rows, A->per_bin ? nb : A->len, A->len};
    e->owners[a] = (struct euler_array_owner){.e = e, .a = a};
    struct state_field *f =
        state_add(L, A->name, STATE_F64, A->per_bin ? 3 : 2, dims, *array_of(e, a), NULL);
    f->reserve = reserve_array, f->after_read = A->after_read, f->owner = &e->owners[a];
    f->optional = A->optional;
  }
}

void euler_running_result(const struct euler *e, struct euler_result *res) {
  const size_t rows = euler_rows(e);
  int *complete = mem_calloc(rows ? rows : 1, sizeof *complete, "Eulerian statistics");
  for (size_t r = 0; r < rows; r++) complete[r] = r < e->nwin;
  euler_finalise(&e->cfg, e->win, e->mom, e->snp, e->pln, e->kin, e->rsb, e->tpl, e->tkn, complete,
                 0, rows, res);
  free(complete);
}
