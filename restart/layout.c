/**
 * @file layout.c
 * @brief The checkpoint layout of a simulation (sim_state, restart.h): the datasets a
 *        continuation needs, and their id blocks over the ranks.
 *
 * The particle datasets hold the ids 0 .. N-1 in order, so a checkpoint does not depend on the
 * number of ranks that wrote it or will read it. Rank r names the ids of its block
 * (sim_id_block, sim.h). A running simulation first sends every owned particle to the rank
 * whose block holds it (dd_exchange) and places what arrives by id; before the particles are
 * distributed (a resume), the block is read straight into the slots sim_create() built for it
 * and sim_restored() migrates the particles to their owners.
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "restart.h"

/* The checkpoint's particle datasets: id and kind, then the allocated PF_CKPT fields of the
   table (part.h) in its order; S->gather holds them in that order (G_FIELDS onwards), then the
   wall values. Returns the number of fields, their table indices in idx. */
enum { G_ID, G_KIND, G_FIELDS };

static int ckpt_fields(const struct particles *P, int idx[SIM_GATHER]) {
  int n = 0;
  for (int i = 0; i < part_n_fields; i++)
    if ((part_fields[i].roles & PF_CKPT) && part_field_ptr(P, &part_fields[i])) {
      if (G_FIELDS + n + 1 >= SIM_GATHER) die("more checkpointed particle fields than SIM_GATHER");
      idx[n++] = i;
    }
  return n;
}

/* Send every owned particle (with the wall values of a vertex) to the rank whose id block holds
   it (MPI_Alltoallv) and place what arrives by id into S->gather: rank r then holds the ids
   lo .. hi-1 in order, and the wall values of the vertex slots among them (walls/ rows
   max(lo, n_fluid) - n_fluid onwards). Collective. */
static void block_state(struct sim *S, size_t lo, size_t hi) {
  const struct particles *P = &S->P;
  int idx[SIM_GATHER];
  const int nf = ckpt_fields(P, idx), wall_col = G_FIELDS + nf;
  const size_t n = P->n, N = P->n_fluid + P->n_vertex, nb = hi - lo, R = (size_t)wall_col + 2;
  const int size = S->dd.size;
  int *dest = mem_alloc(n ? n : 1, sizeof(int), "checkpoint state");
  double *rec = part_alloc("ckpt_send", (n ? n : 1) * R * sizeof(double));
  const double *f[SIM_GATHER];
  for (int c = 0; c < nf; c++) f[c] = part_field_ptr(P, &part_fields[idx[c]]);
  for (size_t a = 0; a < n; a++) {
    dest[a] = dd_id_owner(P->id[a], size, N);
    double *r = rec + a * R;
    memcpy(&r[G_ID], &P->id[a], sizeof(double));
    r[G_KIND] = P->kind[a];
    for (int c = 0; c < nf; c++) r[G_FIELDS + c] = f[c][a];
    r[wall_col] = r[wall_col + 1] = 0.0;
    if (P->kind[a] == KIND_VERTEX) {
      const size_t slot = part_vertex_slot(P, P->id[a]);
      r[wall_col] = S->W.rho[slot], r[wall_col + 1] = S->W.p[slot];
    }
  }
  size_t got;
  double *buf = dd_exchange(size, dest, n, rec, R, &got);
  if (got != nb) die("checkpoint blocks: %zu particles arrived for the %zu ids %zu..", got, nb, lo);
  part_free(rec), free(dest);
  for (int k = 0; k < SIM_GATHER; k++) free(S->gather[k]), S->gather[k] = NULL;
  const size_t w0 = lo > P->n_fluid ? lo : P->n_fluid, nw = hi > w0 ? hi - w0 : 0;
  int64_t *id = mem_alloc(1, (nb ? nb : 1) * sizeof *id, "checkpoint state");
  uint8_t *kind = mem_alloc(1, nb ? nb : 1, "checkpoint state");
  double *wr = mem_alloc(1, 2 * (nw ? nw : 1) * sizeof(double), "checkpoint state");
  S->gather[G_ID] = id, S->gather[G_KIND] = kind, S->gather[wall_col] = wr;
  for (int c = G_FIELDS; c < wall_col; c++)
    if (!(S->gather[c] = mem_alloc(1, (nb ? nb : 1) * sizeof(double), "checkpoint state")))
      die("out of memory redistributing the checkpoint state");
  for (size_t i = 0; i < nb; i++) { /* by id: the same file on any rank count */
    const double *r = buf + i * R;
    int64_t pid;
    memcpy(&pid, &r[G_ID], sizeof(double));
    if (pid < (int64_t)lo || pid >= (int64_t)hi)
      die("checkpoint blocks: particle id %lld outside the block %zu..%zu", (long long)pid, lo,
          hi - 1);
    const size_t k = (size_t)pid - lo;
    id[k] = pid, kind[k] = (uint8_t)r[G_KIND];
    for (int c = G_FIELDS; c < wall_col; c++) ((double *)S->gather[c])[k] = r[c];
    if (r[G_KIND] == KIND_VERTEX)
      wr[(size_t)pid - w0] = r[wall_col], wr[nw + (size_t)pid - w0] = r[wall_col + 1];
  }
  part_free(buf);
}

void sim_state(struct sim *S, struct state_list *L) {
  _Static_assert(sizeof(long) == sizeof(int64_t), "long must be 64-bit");
  _Static_assert(sizeof(int) == sizeof(int32_t), "int must be 32-bit");
  struct particles *P = &S->P;
  state_add(L, "sim/step", STATE_I64, 0, NULL, &S->step, NULL);
  state_add(L, "sim/time", STATE_F64, 0, NULL, &S->t, "s");
  state_add(L, "sim/dt", STATE_F64, 0, NULL, &S->dt, "s");
  state_add(L, "sim/body_force", STATE_F64, 0, NULL, &S->fx, "m/s^2");
  state_add(L, "drive/force", STATE_F64, 0, NULL, &S->drive.force, "m/s^2");
  state_add(L, "drive/ub_prev", STATE_F64, 0, NULL, &S->drive.ub_prev, "m/s");
  state_add(L, "drive/dt_prev", STATE_F64, 0, NULL, &S->drive.dt_prev, "s");
  state_add(L, "drive/started", STATE_I32, 0, NULL, &S->drive.started, NULL);
  /* the state the run started from (since 1.11; an older checkpoint leaves "": unknown) */
  state_add(L, "sim/init_from_run_id", STATE_TEXT, 0, NULL, &S->init_run_id, NULL)->optional = 1;
  state_add(L, "sim/init_from_time", STATE_F64, 0, NULL, &S->init_time, "s")->optional = 1;
  /* the particle datasets hold the ids 0 .. N-1 in order (the file does not depend on the
     number of ranks); each rank names its id block. A running simulation first sends its
     particles to the block owners; before sim_distribute the block is read into the slots
     0 .. hi-lo-1 that sim_create built for it (sim_restored then migrates the particles) */
  const size_t N = P->n_fluid + P->n_vertex, nv = P->n_vertex;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  size_t lo, hi;
  sim_id_block(rank, size, N, &lo, &hi);
  const int blocks = S->distributed;
  if (blocks) block_state(S, lo, hi);
  void *const *g = (void *const *)S->gather;
  const size_t n[1] = {hi - lo};
  struct state_field *fid, *fkind;
  fid = state_add(L, "particles/id", STATE_I64, 1, n, blocks ? g[G_ID] : P->id, NULL);
  fkind = state_add(L, "particles/kind", STATE_U8, 1, n, blocks ? g[G_KIND] : P->kind, NULL);
  fid->offset = fkind->offset = lo, fid->total = fkind->total = N;
  int idx[SIM_GATHER];
  const int nf = ckpt_fields(P, idx);
  for (int c = 0; c < nf; c++) {
    const struct part_field *pf = &part_fields[idx[c]];
    char name[96];
    snprintf(name, sizeof name, "particles/%s", pf->name);
    double *data = part_field_ptr(P, pf);
    struct state_field *fi =
        state_add(L, name, STATE_F64, 1, n, blocks ? g[G_FIELDS + c] : data, pf->units);
    fi->offset = lo, fi->total = N, fi->optional = pf->optional;
  }
  if (S->M.strain_lag) { /* whether nu_r and k_r hold the values the next step applies (format
                            1.3; an older checkpoint leaves it 0 and the first step recomputes) */
    struct state_field *fl = state_add(L, "les/nu_r_live", STATE_I32, 0, NULL, &P->nur_live, NULL);
    fl->optional = 1;
  }
  /* wall values: written by the blocks (the vertex slots of each id block), read whole */
  const size_t w0 = lo > P->n_fluid ? lo - P->n_fluid : 0;
  const size_t nw[1] = {blocks ? (hi > P->n_fluid ? hi - P->n_fluid : 0) - w0 : nv};
  double *wr = blocks ? S->gather[G_FIELDS + nf] : NULL;
  struct state_field *wrho, *wp;
  wrho = state_add(L, "walls/rho", STATE_F64, 1, nw, blocks ? wr : S->W.rho, "kg/m^3");
  wp = state_add(L, "walls/p", STATE_F64, 1, nw, blocks ? wr + nw[0] : S->W.p, "Pa");
  if (blocks) wrho->offset = wp->offset = w0, wrho->total = wp->total = nv;
}
