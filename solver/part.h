/**
 * @file part.h
 * @brief Particles (fluid and wall vertices) as structure-of-arrays, and the wall lattice.
 *
 * Hot fields are separate arrays; every array is allocated through part_alloc() with a label,
 * so part_memory_report() gives the memory per array. After each neighbour sort the arrays are
 * ordered by cell, and by id within a cell.
 */
#ifndef CHANSPH_PART_H
#define CHANSPH_PART_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "contract.h"
#include "scene.h"

enum part_kind { KIND_FLUID = 0, KIND_VERTEX = 1 };

/**
 * All particles of this rank. Vertex particles sit on the walls and never move.
 * Slots 0 .. n-1 hold the particles this rank owns (every pass computes them); with several
 * MPI ranks, slots n .. n+n_ghost-1 hold copies of the neighbouring ranks' particles within the
 * kernel support (ghosts, dd.h), which passes only read.
 */
struct particles {
  size_t n;        /*!< owned fluid + vertex particles of this rank */
  size_t n_ghost;  /*!< ghost particles after the owned ones (0 on one rank) */
  size_t cap;      /*!< slots every per-particle array holds (>= n + n_ghost) */
  size_t n_fluid;  /*!< fluid particles of the whole run (ids 0 .. n_fluid-1) */
  size_t n_vertex; /*!< vertex particles of the whole run, both walls (ids from n_fluid) */
  /* hot, permuted with the particles */
  double *x, *y, *z; /*!< position [m] */
  double *u, *v, *w; /*!< velocity [m/s] */
  double *rho;       /*!< density [kg/m^3] */
  double *m;         /*!< mass [kg] */
  double *gam;       /*!< renormalisation gamma [-] (fluid) */
  double *ksum;      /*!< kernel sum S_a = sum_b m_b w_ab at the current positions [kg/m^dim] */
  double *ddiff;     /*!< volume-diffusion sum D_a of thesis Eq. 3.64 [kg/m^dim/s] */
  double *drate;     /*!< (1/rho) D rho/Dt of the last step without the diffusion [1/s]; NULL
                          without the acoustic damper (term_damper.h) */
  int64_t *id;       /*!< global particle id */
  uint8_t *kind;     /*!< enum part_kind */
  /* recomputed every step, not permuted */
  double *p;            /*!< pressure [Pa] */
  double *c;            /*!< local speed of sound [m/s] */
  double *pr2;          /*!< p / rho^2 [m^5/(kg s^2)] */
  double *vol;          /*!< volume m / rho [m^dim] */
  double *rec;          /*!< pair records, REC_LEN doubles a slot (records.h) */
  double *ax, *ay, *az; /*!< acceleration without the driving force at the start of the last
                             step [m/s^2]; permuted (and migrated) with the particles */
  /** Acceleration of the last sampled force pass split by what exerts it, SX_STRIDE per
      particle: the SX_LEN parts of x, then of y, then of z (enum part_sx) [m/s^2]: the budgets
      of the statistics (stats/contract.h).
     NULL without Eulerian statistics; permuted and migrated with the particles while sx_live. */
  double *sx;
  /** The configurational part of sx's pressure part (3 per particle, x y z): the pressure pair
      forces' 2 p_a / rho_a^2 sum_b m_b grad W_ab, which vanishes for a uniform arrangement (the
      scheme's pressure noise; sph.pressure_gradient = kgc: p_a sum_b V_b (B_a + B_b) grad W_ab /
      rho_a with the gamma weights, sph_budget_pairs); NULL without Eulerian statistics. */
  double *sxn;
  int sx_live; /*!< 1: sx holds the values of the last force pass (a sampled step) */
  /** The viscous prefactor of each component (vis k_x, vis kappa, vis k_z of term_viscous.h) of
      the last sampled force pass, which the conservative split of the budget reads at the
      neighbours (sph_budget_pairs); NULL without Eulerian statistics; not permuted */
  double *vfx, *vfy, *vfz;
  /* turbulence model (turb.h), allocated only when used, NULL otherwise; recomputed from the
     state after every step and not permuted, unless nur_live */
  double *nur; /*!< eddy viscosity nu_r [m^2/s] */
  double *kr;  /*!< residual kinetic energy k_r [m^2/s^2] */
  /** les.strain_lag: the force loop writes the nu_r and k_r of the next step here (turb.h) */
  double *nur_next, *kr_next;
  /** 1: nur and kr hold the values of the last force pass (les.strain_lag), which the next
      step applies: permuted, migrated and checkpointed with the particles */
  int nur_live;
  double *twx, *twz; /*!< wall-law stress rho u_tau^2 e_t of the nearest wall [Pa] */
  /** particle shifting (shift.h), allocated only when used, NULL otherwise: the wall-normal
      shift of the last step [m] (shift_dy: the y-part of the wall-normal momentum flux
      m u delta y that shifting adds, docs/theory.md; all three: the neighbours' shifts that
      the conservative transport reads, ghosts refreshed at PR_SHIFT); computed before the
      re-sort, so permuted and migrated with the particles; not checkpointed (every step sets
      them before anything reads them) */
  double *shift_dx, *shift_dy, *shift_dz;
  /** output.q_criterion: Q = (|Omega|^2 - |S|^2)/2 of the corrected velocity gradient, set just
      before particles.nc is written (turb_q_criterion) [1/s^2]; NULL otherwise */
  double *qcrit;
  /** sph.pressure_gradient = kgc: the correction matrix B of each fluid and vertex particle
      (sph_kgc_matrices, term_pressure.h), one array per entry {xx, xy, xz, yy, yz, zz}; set from
      the positions and volumes before every force pass (ghosts: PR_KGC), so neither permuted
      nor checkpointed; NULL otherwise [-] */
  double *kgc_xx, *kgc_xy, *kgc_xz, *kgc_yy, *kgc_yz, *kgc_zz;
  /* sort scratch */
  double *tmp;
  int64_t *tmp_i;
};

/** Parts of the x-acceleration in part.sx: the pair forces of the fluid neighbours (pressure,
    molecular viscous, eddy-viscous) and everything the walls exert (vertex neighbours, wall
    shear or wall law); their sum is ax. One definition: the statistics contract's parts
    (enum stats_part, stats/contract.h), which the snapshot hands the engines as they are. */
enum part_sx {
  SX_PRESSURE = STATS_PART_PRESSURE, /*!< pressure pair force of the fluid neighbours */
  SX_VISCOUS = STATS_PART_VISCOUS,   /*!< molecular viscous pair force */
  SX_MODEL = STATS_PART_MODEL,       /*!< eddy-viscous pair force */
  SX_WALL = STATS_PART_WALL,         /*!< everything the walls exert */
  SX_LEN = STATS_PARTS,              /*!< parts per component */
  SX_STRIDE = STATS_ACC              /*!< values per particle: x parts, y parts, z parts */
};
_Static_assert((int)SX_LEN == (int)STATS_PARTS && SX_WALL == SX_LEN - 1,
               "part.sx must hold the statistics contract's parts (stats/contract.h)");

/** Wall values on the vertex lattice: index (wall * nx + i) * nz + k, wall 0 at y = 0. */
struct walls {
  int nx, nz;      /*!< vertices per wall along x and z */
  double *rho;     /*!< wall density [kg/m^3] */
  double *p;       /*!< wall pressure [Pa] */
  double *tx, *tz; /*!< wall stress rho_s u_tau u_tau (Ferrand Eq. 38) [Pa]; NULL unless used */
};

/**
 * @brief Allocate zeroed, 64-byte aligned memory and record it under a label.
 * @param[in] label name in the memory report
 * @param[in] bytes size
 * @return the memory (dies on failure, naming the label)
 */
/** What a per-particle field takes part in (struct part_field.roles). */
enum part_role {
  PF_PERMUTE = 1, /*!< moves with its particle when the particles are re-sorted */
  PF_MIGRATE = 2, /*!< travels with its particle to another MPI rank */
  PF_CKPT = 4,    /*!< in the checkpoint as particles/NAME (by id; docs/checkpoint-format.md) */
  PF_WRITE = 8,   /*!< in particles.nc */
  PF_HEALTH = 16, /*!< must be finite: health.c checks it before a state is written or sampled */
  PF_GHOST = 32,  /*!< sent with a ghost when the halo is built (dd_halo): what the passes read
                       at a neighbour before the first refresh (dd_refresh) */
  PF_PAIR = 64    /*!< read by the pair loops at a neighbour: packed into slot `rec` of the pair
                       records (records.h) */
};

enum part_type { PT_F64, PT_I64, PT_U8 };

/** When an array is allocated (struct part_field.need, struct wall_field.need): for every run
    (PN_CORE: part_create), or for the scenes that switch its module on (part_alloc_optional). */
enum part_need {
  PN_CORE,       /*!< every run */
  PN_LES,        /*!< les.model != none */
  PN_STRAIN_LAG, /*!< the LES force loop forms the next step's eddy viscosity (les.strain_lag) */
  PN_WALL_TAU,   /*!< wall stresses at the vertices: LES or a turbulent wall law */
  PN_EULERIAN,   /*!< Eulerian statistics (the momentum budget's parts) */
  PN_SHIFTING,   /*!< particle shifting */
  PN_QCRIT,      /*!< output.q_criterion */
  PN_DAMPER,     /*!< sph.acoustic_damper > 0 */
  PN_KGC         /*!< sph.pressure_gradient = kgc */
};

/** The refreshes of the ghosts' copies within a step (dd_refresh): after the pass that sets a
    field, because a later pass reads it at a neighbour (struct part_field.refresh, struct
    wall_field.refresh). A field read by several passes may be refreshed at several stages. */
enum part_refresh {
  PR_DENSITY = 1,  /*!< after sph_density: the fluid values sph_walls reads */
  PR_WALLS = 2,    /*!< after sph_walls: the vertex and wall values the forces read */
  PR_WALL_LAW = 4, /*!< after turb_wall_law: the wall stresses at the vertices */
  PR_MODEL = 8,    /*!< after turb_eddy_viscosity: nu_r and k_r */
  PR_KR = 16,      /*!< after sph_kr_pressure: p/rho^2 and the wall pressure with 2/3 rho k_r */
  PR_BUDGET = 32,  /*!< after a sampled force pass: gamma and the viscous prefactors that the
                        conservative split of the budget reads (sph_budget_pairs) */
  PR_SHIFT = 64,   /*!< after shift_compute: the shifts that shift_velocity_conservative reads */
  PR_KGC = 128     /*!< after sph_kgc_matrices: the correction matrices the kgc pressure gradient
                        reads at the neighbours */
};

/** One per-particle array of struct particles. Adding a field: the member in struct particles
    and one line in part_fields (part.c); allocation (need), growth, sort, migration,
    checkpoint, particles.nc, the health check, the pair records and the halo refreshes follow
    from the line. */
struct part_field {
  size_t off;            /*!< offsetof(struct particles, the pointer member) */
  const char *label;     /*!< in the memory report */
  const char *name;      /*!< in files and messages (PF_CKPT, PF_WRITE, PF_HEALTH) */
  enum part_type type;   /*!< element type */
  int width;             /*!< values per particle */
  int roles;             /*!< enum part_role */
  enum part_need need;   /*!< when it is allocated */
  size_t live;           /*!< offsetof an int of struct particles that must be set for the
                              array to hold particle values (permute, migrate), or 0 */
  int optional;          /*!< PF_CKPT: added in a later checkpoint format (may be absent) */
  const char *units;     /*!< PF_CKPT, PF_WRITE */
  const char *long_name; /*!< PF_WRITE */
  int rec;               /*!< PF_PAIR: its slot in the pair records (enum rec_field) */
  int refresh;           /*!< enum part_refresh: when the ghosts' copies are refreshed */
};

extern const struct part_field part_fields[]; /*!< every per-particle array (part.c) */
extern const int part_n_fields;

/** One array of struct walls (indexed by vertex slot): allocation and halo refreshes. */
struct wall_field {
  size_t off;          /*!< offsetof(struct walls, the pointer member) */
  const char *label;   /*!< in the memory report */
  enum part_need need; /*!< when it is allocated */
  int refresh;         /*!< enum part_refresh: when the ghost vertices' values are refreshed */
};

extern const struct wall_field wall_fields[]; /*!< every wall array (part.c) */
extern const int wall_n_fields;

/** The array of wall field f (NULL if not allocated). */
static inline double *wall_field_ptr(const struct walls *W, const struct wall_field *f) {
  return *(double *const *)((const char *)W + f->off);
}

/** @brief Whether a scene needs the arrays of `need` (enum part_need). */
int part_needed(enum part_need need, const struct scene *s);

/**
 * @brief Allocate the optional arrays of particles and walls the scene needs (part_needed),
 *        P->cap slots each (walls: one per vertex), zeroed; after part_create.
 */
void part_alloc_optional(struct particles *P, struct walls *W, const struct scene *s);

/** The array of field f (NULL if not allocated). */
static inline void *part_field_ptr(const struct particles *P, const struct part_field *f) {
  return *(void *const *)((const char *)P + f->off);
}

/** 1 if field f is allocated and holds particle values (its live flag, if any, is set). */
static inline int part_field_live(const struct particles *P, const struct part_field *f) {
  return part_field_ptr(P, f) && (!f->live || *(const int *)((const char *)P + f->live));
}

void *part_alloc(const char *label, size_t bytes);

/** @brief Free memory from part_alloc(). */
void part_free(void *ptr);

/** @brief Print memory per label and the total. */
void part_memory_report(FILE *f);

/**
 * @brief Memory the particles of a whole scene need (on one rank; several ranks need their
 *        share of it, dd_share), before anything is allocated: a lower bound from the
 *        per-particle arrays, the step's scratch, the neighbour lists and the checkpoint's copies.
 * @param[out] count number of particles (fluid and wall vertices)
 * @return bytes
 */
double part_bytes(const struct scene *s, double *count);

/**
 * @brief Create the fluid lattice (x = (i+1/2) dr, y = j dr for j = 1..2delta/dr-1,
 *        z = (k+1/2) dr) and the vertex particles on both walls (volume dr^dim / 2).
 * @param[out] P particles
 * @param[out] W wall lattice
 * @param[in] s scene
 */
void part_create(struct particles *P, struct walls *W, const struct scene *s);

/** Which particles of the lattice a rank builds (part_create_part): the ids lo .. hi-1 that
    keep(ctx, x, z) accepts (keep NULL: all of them). */
struct part_select {
  size_t lo, hi;
  int (*keep)(const void *ctx, double x, double z);
  const void *ctx;
};

/**
 * @brief part_create() for the particles of sel only, in id order (fluid, then vertices):
 *        a rank builds its block of the decomposition (keep: the owner of the position's
 *        cell column), or the slots of its checkpoint id block (lo, hi) before a resume reads
 *        them. n_fluid and n_vertex stay the whole run's; the wall arrays hold every vertex.
 */
void part_create_part(struct particles *P, struct walls *W, const struct scene *s,
                      const struct part_select *sel);

/**
 * @brief Make every per-particle array hold at least n slots (grows by half again; keeps the
 *        contents of slots 0 .. P->n + P->n_ghost - 1).
 */
void part_reserve(struct particles *P, size_t n);

/**
 * @brief Make every per-particle array hold exactly cap slots (at least the ones in use),
 *        e.g. to give back the memory of the full initial lattice once a rank kept its part.
 */
void part_resize(struct particles *P, size_t cap);

/** @brief Move the n slots from .. from+n-1 of every allocated array to to .. to+n-1 (the
           ranges may overlap; the slots must fit the capacity). */
void part_move(struct particles *P, size_t to, size_t from, size_t n);

/** @brief Free everything part_create() and part_alloc_optional() allocated. */
void part_destroy(struct particles *P, struct walls *W);

/**
 * @brief Reorder the permuted arrays in slots [i0, i0 + n): new slot i0 + i takes old slot
 *        i0 + perm[i].
 * @param[in,out] P particles
 * @param[in] i0 first slot
 * @param[in] n slots
 * @param[in] perm permutation of 0..n-1
 */
void part_permute(struct particles *P, size_t i0, size_t n, const size_t *perm);

/** @brief Wall-lattice index of a vertex particle from its id. */
static inline size_t part_vertex_slot(const struct particles *P, int64_t id) {
  return (size_t)(id - (int64_t)P->n_fluid);
}

#endif
