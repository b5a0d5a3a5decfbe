/** @file sim.c @brief Implementation of sim.h. */
#include "sim.h"
#include "alloc.h"

#include <Random123/philox.h>
#include <float.h>
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "error.h"
#include "euler.h"
#include "init.h"
#include "output.h"
#include "records.h"
#include "reduce.h"
#include "shift.h"
#include "term_diffusion.h"
#include "term_viscous.h"
#include "timers.h"
#include "turb.h"

double sim_viscosity(const struct scene *sc, double t) {
  if (!(sc->nu_start > 0.0) || t >= sc->nu_ramp_end) return sc->nu;
  if (t <= sc->nu_ramp_begin) return sc->nu_start;
  const double f = (t - sc->nu_ramp_begin) / (sc->nu_ramp_end - sc->nu_ramp_begin);
  return sc->nu_start + f * (sc->nu - sc->nu_start);
}

/* Model terms of the current state, at the viscosity of the schedule (turb.h), with the ghosts'
   copies refreshed after each pass whose results the next one reads at neighbours. */
static void model_update(struct sim *S) {
  const struct model *M = &S->M;
  struct particles *P = &S->P;
  S->M.nu = sim_viscosity(S->sc, S->t);
  S->nu_max = M->nu;
  if (M->wall_tau) {
    turb_wall_law(M, P, &S->nb, &S->W);
    dd_refresh(&S->dd, P, &S->W, PR_WALL_LAW);
  }
  if (M->les) {
    S->nu_max = turb_eddy_viscosity(M, P, &S->nb, &S->W);
    dd_refresh(&S->dd, P, &S->W, PR_MODEL); /* read by the forces and by sph_kr_pressure */
    if (M->cy > 0.0) {
      sph_kr_pressure(M, P, &S->nb, &S->W);
      dd_refresh(&S->dd, P, &S->W, PR_KR);
    }
  }
  reduce_global_max(&S->nu_max, 1);
}

/* Grow every per-particle array of the simulation to n slots (dd_reserve_fn). */
static void sim_reserve(void *ctx, size_t n) {
  struct sim *S = ctx;
  part_reserve(&S->P, n);
  nbr_reserve(&S->nb, S->P.cap);
  if (S->cap >= S->P.cap) return;
  S->cap = S->P.cap;
  const size_t bytes = S->cap * sizeof(double);
  for (int k = 0; k < 5; k++)
    part_free(S->scratch[k]), S->scratch[k] = part_alloc("diag_scratch", bytes);
  part_free(S->ksum_new), S->ksum_new = part_alloc("kernel_sum_new", bytes);
  if (S->wall_ax) part_free(S->wall_ax), S->wall_ax = part_alloc("wall_ax", bytes);
}

/* Neighbours, density, wall values and model terms of the current positions: sort the owned
   particles, build the ghosts, and refresh the ghosts' copies after each pass whose results
   the next pass reads at neighbours. restored: after a checkpoint was read, density from the
   stored state and kernel sums (dt = 0). */
static void update_state(struct sim *S, int restored, double dt) {
  struct particles *P = &S->P;
  nbr_sort(&S->nb, P);
  dd_halo(&S->dd, P, &S->nb);
  nbr_build(&S->nb, P, &S->M.k, S->ksum_new);
  /* the arrays may have moved (grown for the ghosts): take the pointers only now */
  sph_density(&S->M, P, restored ? P->ksum : S->ksum_new, dt);
  dd_refresh(&S->dd, P, &S->W, PR_DENSITY); /* fluid ghosts: what sph_walls reads */
  for (int k = 1; dt > 0.0 && k < S->M.diff_substeps; k++) { /* sph.diffusion_substeps */
    sph_diffusion_substep(&S->M, P, &S->nb, dt / S->M.diff_substeps);
    dd_refresh(&S->dd, P, &S->W, PR_DENSITY);
  }
  sph_walls(&S->M, P, &S->nb, &S->W);
  dd_refresh(&S->dd, P, &S->W, PR_WALLS); /* vertex ghosts and wall values */
  model_update(S);
  if (S->M.pgrad == PGRAD_KGC) { /* the correction matrices the kgc pressure gradient reads */
    sph_kgc_matrices(&S->M, P, &S->nb);
    dd_refresh(&S->dd, P, &S->W, PR_KGC);
  }
  if (records_fast()) records_pack(P, P->n + P->n_ghost); /* what the force pass gathers */
}

/** The MPI ranks of this node (they share its memory). */
static int ranks_on_node(void) {
  MPI_Comm node;
  int n = 1;
  CHECK_MPI(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node));
  CHECK_MPI(MPI_Comm_size(node, &n));
  CHECK_MPI(MPI_Comm_free(&node));
  return n;
}

/** Before any allocation: refuse a scene whose large allocations (lower bounds) on the ranks of
    this node need more than 80% of the machine's memory (sysconf physical pages), naming the
    keys of the largest and the sizes; a clear refusal, not the OOM killer of a shared node.
    Every rank builds the particles of its block (sim_share: with its halo and the room the
    arrays grow by) and its own statistics engines, so a node's need is its ranks' sum. The
    rest is for the system, MPI and what the bounds leave out: the peak resident memory measured
    was 1.0 (2-D, dr = 0.002) to 1.25 (3-D, dr = 0.00625) times the bound (docs/performance.md,
    "Memory check of a scene"). */
static int check_memory(const struct scene *sc, const struct dd *d) {
  enum { M_PARTS, M_EULER, M_CORR, M_LAGR, M_EDDIES, M_SOURCE, M_N };
  double n = 0.0, src = 0.0, bytes[M_N];
  bytes[M_PARTS] = part_bytes(sc, &n) * dd_share(d), bytes[M_EDDIES] = init_bytes(sc);
  output_stats_bytes(sc, &bytes[M_EULER], &bytes[M_CORR], &bytes[M_LAGR]);
  bytes[M_SOURCE] = init_source_bytes(sc, d->size, &src);
  char what[M_N][160];
  if (d->size > 1)
    snprintf(what[M_PARTS], sizeof what[0], "%.4g particles (this rank's block and halo of %.4g)",
             n * dd_share(d), n);
  else
    snprintf(what[M_PARTS], sizeof what[0], "%.4g particles", n);
  snprintf(what[M_EULER], sizeof what[0],
           "the Eulerian statistics of %d bins (x %d cell columns, per window with the "
           "Reynolds-stress budgets)",
           sc->n_bins > 0 ? sc->n_bins : scene_bins(sc), nbr_columns(sc));
  snprintf(what[M_CORR], sizeof what[0], "the correlation grids");
  snprintf(what[M_LAGR], sizeof what[0], "the Lagrangian records (levels x lags x release slots)");
  snprintf(what[M_EDDIES], sizeof what[0], "%.4g synthetic eddies", init_sem_count(sc));
  snprintf(what[M_SOURCE], sizeof what[0], "this rank's share of the %.4g particles of %.100s", src,
           sc->init_from);
  static const char *const keys[M_N] = {
      "keys 'domain.lx', 'domain.delta', 'domain.lz', 'domain.dr'",
      "keys 'output.n_bins', 'domain.lx', 'stats.window'",
      "keys 'correlations.nx', 'correlations.nz', 'correlations.y_plus'",
      "keys 'lagrangian.y_plus', 'lagrangian.n_lags', 'lagrangian.horizon', "
      "'lagrangian.release_every'",
      "keys 'init.eddies', 'init.eddy_size'",
      "key 'init.from'"};
  static const char *const remedy[M_N] = {"use a smaller domain or a larger dr, or more ranks",
                                          "use fewer bins or longer windows",
                                          "use fewer grid points or levels",
                                          "use fewer levels or lags, or release less often",
                                          "use fewer or larger eddies",
                                          "a state of the scene's size (its dimension 'particle')"};
  double total = 0.0;
  int k = 0;
  for (int i = 0; i < M_N; i++) {
    total += bytes[i];
    if (bytes[i] > bytes[k]) k = i;
  }
  const int ranks = ranks_on_node();
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  const double have = pages > 0 && page > 0 ? (double)pages * (double)page : INFINITY;
  if (total * ranks <= 0.8 * have) return CHANSPH_OK;
  error_input(
      "%s: %s: %s need at least %.3g GB per MPI rank (every rank builds its block of the "
      "particles and its statistics; %.3g GB in all, %.3g GB for the %d rank%s on this "
      "node), more than the %.3g GB (80%%) of the %.3g GB of memory of this machine: %s",
      sc->path[0] ? sc->path : "(scene)", keys[k], what[k], bytes[k] / 1e9, total / 1e9,
      total * ranks / 1e9, ranks, ranks > 1 ? "s" : "", 0.8 * have / 1e9, have / 1e9,
      ranks > 1 && total <= 0.8 * have ? "use fewer ranks per node (more threads each)"
                                       : remedy[k]);
  return CHANSPH_ERR;
}

/** The memory estimate of a scene on one rank of one (what check_memory adds up) [bytes]. */
double sim_memory_estimate(const struct scene *sc) {
  double n, src, e, c, l;
  output_stats_bytes(sc, &e, &c, &l);
  return part_bytes(sc, &n) + init_bytes(sc) + init_source_bytes(sc, 1, &src) + e + c + l;
}

/* The rank that owns the cell column of a position (init_owner). */
static int owner_of_position(const void *ctx, double x, double z) {
  const struct sim *S = ctx;
  nbr_wrap_position(&S->nb, &x, &z);
  return dd_owner(&S->dd, nbr_column(&S->nb, x), nbr_plane(&S->nb, z));
}

/* Whether this rank owns the cell column of a position (part_select). */
static int owns_position(const void *ctx, double x, double z) {
  return owner_of_position(ctx, x, z) == ((const struct sim *)ctx)->dd.rank;
}

int sim_create(struct sim *S, const struct scene *sc, int resume) {
  memset(S, 0, sizeof *S);
  S->sc = sc;
  S->rss_before = mem_peak_resident(); /* the log's start-up memory (output.c) */
  /* the blocks and the grid first: each rank builds only its part of the particles */
  if (dd_init(&S->dd, sc, sim_reserve, S)) return CHANSPH_ERR;
  if (check_memory(sc, &S->dd)) { /* before the grid, whose cells a huge scene cannot hold */
    dd_free(&S->dd);
    return CHANSPH_ERR;
  }
  const struct nbr_range r = dd_range(&S->dd);
  nbr_init(&S->nb, sc, 0, &r); /* sized in sim_distribute, for this rank's part */
  S->grid = 1;
  sph_model_init(&S->M, sc);
  /* a fresh start: the lattice particles of this rank's block; a resume: the slots of its
     checkpoint id block (sim_state reads them; sim_restored migrates them to their owners) */
  struct part_select sel = {0, SIZE_MAX, owns_position, S};
  if (resume) {
    double n;
    part_bytes(sc, &n);
    sim_id_block(S->dd.rank, S->dd.size, (size_t)n, &sel.lo, &sel.hi);
    sel.keep = NULL;
  }
  part_create_part(&S->P, &S->W, sc, S->dd.size > 1 ? &sel : NULL);
  part_alloc_optional(&S->P, &S->W, sc); /* the arrays of the modules the scene turns on */
  const struct init_owner own = {owner_of_position, S, S->dd.rank, S->dd.size};
  if (init_fields(sc, &S->P, &own)) {
    sim_free(S);
    return CHANSPH_ERR;
  }
  if (scene_stats_num(sc, &euler_key_eulerian)) S->wall_ax = part_alloc("wall_ax", sizeof(double));
  init_origin(sc->init_from, &S->init_run_id, &S->init_time);
  S->qcrit_step = -1;
  S->wall_fx[0] = S->wall_fx[1] = NAN;
  drive_init(&S->drive, sc);
  S->fx = S->drive.force;
  return CHANSPH_OK;
}

/* Keep this rank's particles and size the arrays and the grid for them. From a checkpoint read
   on several ranks (block = 1), this rank holds the slots of its id block (sim_state), which
   migrate to their owners. */
static int sim_distribute(struct sim *S, int block) {
  if (block && S->dd.size > 1)
    dd_take_block(&S->dd, &S->P, &S->nb, 0, S->P.n);
  else
    dd_keep_owned(&S->dd, &S->P, &S->nb); /* built as owned: wraps the positions */
  /* several ranks: room for the ghosts and the particles that arrive (the arrays grow by half
     again when needed) */
  if (S->dd.size > 1) part_resize(&S->P, S->P.n + S->P.n / 2);
  sim_reserve(S, S->P.n);
  S->distributed = 1;
  return CHANSPH_OK;
}

int sim_init(struct sim *S, const struct scene *sc) {
  TRY(sim_create(S, sc, 0));
  if (sim_distribute(S, 0)) {
    sim_free(S);
    return CHANSPH_ERR;
  }
  update_state(S, 0, 0.0);
  return CHANSPH_OK;
}

void sim_free(struct sim *S) {
  if (S->grid) nbr_free(&S->nb), dd_free(&S->dd);
  for (int k = 0; k < SIM_GATHER; k++) free(S->gather[k]);
  for (int k = 0; k < 5; k++) part_free(S->scratch[k]);
  part_free(S->ksum_new);
  if (S->wall_ax) part_free(S->wall_ax);
  free(S->init_run_id), S->init_run_id = NULL;
  part_destroy(&S->P, &S->W);
}

/* A fixed time step above a stability limit is a numerical failure: name the limit and the
   particle that sets it (largest acceleration, or fastest particle for the acoustic limit). */
static void check_fixed_dt(struct sim *S, double dt) {
  static const char *const names[SIM_DT_LIMITS] = {"acoustic (Eq. 2.160)", "viscous (Eq. 2.161)",
                                                   "force (Eq. 2.162)", "wall (Eq. 2.163)",
                                                   "volume diffusion (time.c_diffusion)"};
  int worst = -1;
  for (int k = 0; k < SIM_DT_LIMITS; k++)
    if (dt > S->dt_limits[k] * (1.0 + 1e-12) &&
        (worst < 0 || S->dt_limits[k] < S->dt_limits[worst]))
      worst = k;
  if (worst < 0) return;
  const struct particles *P = &S->P;
  size_t who = 0;
  double best = -1.0;
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    const double ax = P->ax[a] + S->fx,
                 v2 = P->u[a] * P->u[a] + P->v[a] * P->v[a] + P->w[a] * P->w[a];
    const double key = worst == 0 ? v2 : ax * ax + P->ay[a] * P->ay[a] + P->az[a] * P->az[a];
    if (key > best || (key == best && P->id[a] < P->id[who])) best = key, who = a;
  }
  /* the particle over all ranks: largest key, then lowest id */
  double mine[5] = {best, best >= 0.0 ? (double)P->id[who] : 0.0, 0, 0, 0};
  if (best >= 0.0) mine[2] = P->x[who], mine[3] = P->y[who], mine[4] = P->z[who];
  double *all = part_alloc("cfl_report", 5 * (size_t)S->dd.size * sizeof(double));
  CHECK_MPI(MPI_Allgather(mine, 5, MPI_DOUBLE, all, 5, MPI_DOUBLE, MPI_COMM_WORLD));
  const double *w = all;
  for (int r = 1; r < S->dd.size; r++) {
    const double *c = all + 5 * r;
    if (c[0] > w[0] || (c[0] == w[0] && c[0] >= 0.0 && c[1] < w[1])) w = c;
  }
  snprintf(S->violation, sizeof S->violation,
           "CFL violation at step %ld (t = %.9g): fixed dt = %.6g s exceeds the %s limit "
           "%.6g s; particle id %lld at (%.9g, %.9g, %.9g) with %s %.6g",
           S->step, S->t, dt, names[worst], S->dt_limits[worst], (long long)w[1], w[2], w[3], w[4],
           worst == 0 ? "speed" : "acceleration", sqrt(w[0]));
  part_free(all);
}

/* Time step of thesis Eq. 2.160-2.164, or the fixed one. */
static double time_step(struct sim *S, const struct force_info *fi) {
  const struct scene *sc = S->sc;
  const double h = S->M.h;
  S->dt_limits[0] = sc->cfl * h / sc->c0;
  /* nu + nu_r, and the acoustic damper's bulk viscosity (term_damper.h) */
  S->dt_limits[1] = viscous_dt_limit(sc->c_visc, h, S->nu_max + S->M.damper_zeta / sc->rho0);
  S->dt_limits[2] = fi->amax > 0.0 ? sc->c_force * sqrt(h / fi->amax) : INFINITY;
  S->dt_limits[3] = sc->c_gamma > 0.0 && fi->gvmax > 0.0 ? sc->c_gamma / fi->gvmax : INFINITY;
  S->dt_limits[4] = diffusion_dt_limit(&S->M, sc->c_diffusion);
  if (sc->dt_fixed > 0.0) {
    check_fixed_dt(S, sc->dt_fixed);
    return sc->dt_fixed;
  }
  int k = 0;
  for (int j = 1; j < SIM_DT_LIMITS; j++)
    if (S->dt_limits[j] < S->dt_limits[k]) k = j;
  const double dt = S->dt_limits[k];
  /* a zero or subnormal step, or one too small to advance t, never reaches t_end: a numerical
     failure (the step is taken; the run stops after it, exit 3) */
  if (!(dt >= DBL_MIN) || S->t + dt == S->t) {
    static const char *const names[SIM_DT_LIMITS] = {
        "acoustic cfl h / c0 (Eq. 2.160)", "viscous (Eq. 2.161) with nu + nu_r %.6g m^2/s",
        "force c_force sqrt(h / |a|) (Eq. 2.162) with |a| %.6g m/s^2",
        "wall (Eq. 2.163) with a wall rate %.6g 1/s",
        "volume diffusion c_diffusion h^2 / D with D %.6g m^2/s"};
    const double arg[SIM_DT_LIMITS] = {0.0, S->nu_max, fi->amax, fi->gvmax,
                                       diffusion_diffusivity(&S->M)};
    char limit[160];
    snprintf(limit, sizeof limit, names[k], arg[k]);
    snprintf(S->violation, sizeof S->violation,
             "time step %.3g s at step %ld (t = %.9g) is zero, subnormal or too small to advance "
             "t: the %.150s limit (check drive.force, fluid.nu, c0)",
             dt, S->step, S->t, limit);
  }
  return dt;
}

static double bulk_velocity(struct sim *S) {
  const struct particles *P = &S->P;
  double *vu = S->scratch[0], *vol = S->scratch[1];
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    const double V = P->kind[a] == KIND_FLUID ? P->m[a] / P->rho[a] : 0.0;
    vu[a] = V * P->u[a], vol[a] = V;
  }
  double s[2];
  const double *arrs[2] = {vu, vol};
  dd_sum(&S->dd, &S->nb, 2, arrs, s);
  return s[0] / s[1];
}

/* x-force of each wall on the fluid from the per-particle wall accelerations (deterministic). */
static void wall_force(struct sim *S) {
  const struct particles *P = &S->P;
  double *lo = S->scratch[2], *hi = S->scratch[3];
  const double delta = S->sc->delta;
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    const double f = P->kind[a] == KIND_FLUID ? P->m[a] * S->wall_ax[a] : 0.0;
    lo[a] = P->y[a] < delta ? f : 0.0, hi[a] = P->y[a] < delta ? 0.0 : f;
  }
  const double *arrs[2] = {lo, hi};
  dd_sum(&S->dd, &S->nb, 2, arrs, S->wall_fx);
}

int sim_budget_sample(const struct scene *sc, long step) {
  const long every = sc->stats_every;
  const long k = (long)scene_stats_num(sc, &euler_key_budget_every);
  if (step % every != 0) return 0;
  if (k <= 1) return 1;
  const long n = step / every; /* the statistics sample's number */
  /* one budget sample in each block of k samples, at a position drawn from the block number:
     regularly spaced samples would alias a coherent oscillation (a standing acoustic mode)
     whose period is near a multiple of their interval into a bias */
  philox2x64_ctr_t c = {{(uint64_t)(n / k), 0x627564676574u}}; /* "budget" */
  philox2x64_key_t key = {{0x6368616e737068u}};                /* "chansph" */
  const philox2x64_ctr_t r = philox2x64(c, key);
  return n % k == (long)(r.v[0] % (uint64_t)k);
}

/* sph.wall_collision = reflect: a fluid particle that has reached a wall in this step is
   reflected specularly (its position mirrored in the wall, its wall-normal velocity turned
   into the fluid; u, w kept, so the streamwise momentum is untouched), named on stderr and
   counted; otherwise the health check stops the run on it. Per particle: independent of
   threads and ranks. */
static void wall_reflect(struct sim *S) {
  struct particles *P = &S->P;
  const double ly = S->M.ly, floor_y = 1e-9 * ly;
  long n = 0;
#pragma omp parallel for schedule(static) reduction(+ : n)
  for (size_t a = 0; a < P->n; a++)
    if (P->kind[a] == KIND_FLUID && sph_at_wall(P->y[a], ly)) n++;
  if (n == 0) return;
  for (size_t a = 0; a < P->n; a++) { /* rare: serial, in index order */
    if (P->kind[a] != KIND_FLUID || !sph_at_wall(P->y[a], ly)) continue;
    const int upper = P->y[a] >= ly;
    fprintf(stderr,
            "warning: step %ld (t = %.9g): particle id %lld reached the %s wall at (%.9g, %.9g, "
            "%.9g) with velocity (%.6g, %.6g, %.6g); reflected (sph.wall_collision = reflect)\n",
            S->step, S->t, (long long)P->id[a], upper ? "upper" : "lower", P->x[a], P->y[a],
            P->z[a], P->u[a], P->v[a], P->w[a]);
    P->y[a] = upper ? fmin(2.0 * ly - P->y[a], ly - floor_y) : fmax(-P->y[a], floor_y);
    P->v[a] = upper ? -fabs(P->v[a]) : fabs(P->v[a]);
  }
  S->reflections += n;
}

void sim_step(struct sim *S) {
  struct particles *P = &S->P;
  /* the wall shear stress is gathered only on steps whose end state a budget sample of the
     statistics takes (sim_budget_sample) */
  const int wall_sample = S->wall_ax && sim_budget_sample(S->sc, S->step + 1);
  /* and so are the parts of the x-acceleration of the momentum budget, which then travel with
     their particles through the sort and the migration until the sample */
  P->sx_live = wall_sample && P->sx;
  struct force_info fi = {.wall_ax = wall_sample ? S->wall_ax : NULL,
                          .sx = P->sx_live ? P->sx : NULL};
  const double ub = S->drive.mode == DRIVE_FLUX ? bulk_velocity(S) : 0.0;
  sph_forces(&S->M, P, &S->nb, &S->W, S->fx, &fi);
  if (P->sx_live) { /* the budget's conservative split, with the neighbours' factors */
    dd_refresh(&S->dd, P, &S->W, PR_BUDGET);
    sph_budget_pairs(&S->M, P, &S->nb, S->wall_ax);
  }
  if (S->M.strain_lag) turb_advance(P); /* nu_r, k_r of the next step (les.strain_lag) */
  if (wall_sample) wall_force(S);
  double maxima[2] = {fi.amax, fi.gvmax};
  reduce_global_max(maxima, 2);
  fi.amax = maxima[0], fi.gvmax = maxima[1];
  const double dt = time_step(S, &fi);
  const double fx = drive_force(&S->drive, ub, dt);
  /* particle shifting at the positions of the neighbour list */
  const int shifting = S->M.shifting != SHIFT_NONE;
  double *sx = P->shift_dx, *sy = P->shift_dy, *sz = P->shift_dz;
  if (shifting) shift_compute(&S->M, P, &S->nb, sx, sy, sz);
  /* and the velocity change that carries each velocity with its shift (scratch 2-4) */
  double *du = S->scratch[2], *dv = S->scratch[3], *dw = S->scratch[4];
  const int carry = shifting ? S->M.shift_velocity : SHIFT_KEEP;
  if (carry == SHIFT_TAYLOR) shift_velocity(&S->M, P, &S->nb, sx, sy, sz, du, dv, dw);
  if (carry == SHIFT_CONSERVATIVE) { /* it reads the neighbours' shifts */
    dd_refresh(&S->dd, P, &S->W, PR_SHIFT);
    shift_velocity_conservative(&S->M, P, &S->nb, du, dv, dw);
  }
  timer_push("integrate");
#pragma omp parallel for schedule(static)
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) continue;
    P->u[a] += dt * (P->ax[a] + fx);
    P->v[a] += dt * P->ay[a];
    P->w[a] += dt * P->az[a];
    P->x[a] += dt * P->u[a];
    P->y[a] += dt * P->v[a];
    P->z[a] += dt * P->w[a];
  }
  if (shifting) shift_apply(P, sx, sy, sz);
  if (carry != SHIFT_KEEP) {
#pragma omp parallel for schedule(static)
    for (size_t a = 0; a < P->n; a++) P->u[a] += du[a], P->v[a] += dv[a], P->w[a] += dw[a];
  }
  timer_pop();
  S->t += dt, S->dt = dt, S->fx = fx, S->step++;
  if (S->M.wall_reflect) wall_reflect(S);
  if (S->dd.size > 1 && S->sc->balance_every > 0 && S->step % S->sc->balance_every == 0)
    dd_balance(&S->dd, &S->nb, S->sc->balance_threshold);
  dd_migrate(&S->dd, P, &S->nb);
  update_state(S, 0, dt);
  if (S->sc->check_ids) dd_check_ids(&S->dd, P, P->n_fluid + P->n_vertex, S->step);
}

void sim_output_fields(struct sim *S) {
  if (!S->P.qcrit || S->qcrit_step == S->step) return;
  turb_q_criterion(&S->M, &S->P, &S->nb, S->P.qcrit);
  S->qcrit_step = S->step;
}

void sim_diag(struct sim *S, struct diag *d) {
  const struct particles *P = &S->P;
  double *vu = S->scratch[0], *vol = S->scratch[1], *ke = S->scratch[2], *mass = S->scratch[3];
  double rmin = INFINITY, rmax = -INFINITY, smax = 0.0, gmin = INFINITY;
#pragma omp parallel for schedule(static) reduction(min : rmin, gmin) reduction(max : rmax, smax)
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID) {
      vu[a] = vol[a] = ke[a] = mass[a] = 0.0;
      continue;
    }
    const double V = P->m[a] / P->rho[a];
    const double s2 = P->u[a] * P->u[a] + P->v[a] * P->v[a] + P->w[a] * P->w[a];
    vu[a] = V * P->u[a], vol[a] = V, ke[a] = 0.5 * P->m[a] * s2, mass[a] = P->m[a];
    rmin = fmin(rmin, P->rho[a]), rmax = fmax(rmax, P->rho[a]);
    smax = fmax(smax, s2), gmin = fmin(gmin, P->gam[a]);
  }
  double s[4];
  const double *arrs[4] = {vu, vol, ke, mass};
  dd_sum(&S->dd, &S->nb, 4, arrs, s);
  double mx[2] = {rmax, smax}, mn[2] = {rmin, gmin};
  reduce_global_max(mx, 2);
  reduce_global_min(mn, 2);
  d->u_bulk = s[0] / s[1], d->volume = s[1], d->kinetic_energy = s[2], d->mass = s[3];
  d->rho_min = mn[0], d->rho_max = mx[0], d->max_speed = sqrt(mx[1]), d->min_gamma = mn[1];
  d->reflections = S->reflections;
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &d->reflections, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD));
}

int sim_done(const struct sim *S) {
  if (S->sc->max_steps > 0 && S->step >= S->sc->max_steps) return 1;
  return S->t >= S->sc->t_end * (1.0 - 1e-12);
}

size_t sim_restored(struct sim *S) {
  struct particles *P = &S->P;
  if (!S->distributed && sim_distribute(S, 1)) die("the checkpoint's scene does not fit the ranks");
  const size_t nv = P->n_vertex;
  double *old = part_alloc("restore_check", 2 * nv * sizeof(double));
  memcpy(old, S->W.rho, nv * sizeof(double));
  memcpy(old + nv, S->W.p, nv * sizeof(double));
  /* dt = 0: pressure, sound speed, p/rho^2 and volume from the stored density; the kernel sum
     and gamma are set to the values they already hold */
  update_state(S, 1, 0.0);
  size_t differ = 0;
  for (size_t i = 0; i < nv; i++)
    differ += memcmp(&old[i], &S->W.rho[i], sizeof(double)) != 0 ||
              memcmp(&old[nv + i], &S->W.p[i], sizeof(double)) != 0;
  part_free(old);
  return differ;
}
