/** @file health.c @brief Implementation of health.h. */
#include "health.h"

#include <limits.h>
#include <math.h>
#include <mpi.h>
#include <stdio.h>

#include "error.h"
#include "timers.h"

enum { OK = 0, NOT_FINITE = 1, THROUGH_WALL = 2, SUPERSONIC = 3 };

/* The PF_HEALTH arrays of the table (part.h) that this run has: what a checkpoint, a snapshot,
   particles.nc or a statistics sample takes from a fluid particle. */
struct checked {
  int n;
  const double *arr[64];
  const char *name[64];
};

static void checked_fields(const struct particles *P, struct checked *c) {
  c->n = 0;
  for (int k = 0; k < part_n_fields && c->n < 64; k++) {
    const struct part_field *f = &part_fields[k];
    if ((f->roles & PF_HEALTH) && part_field_ptr(P, f))
      c->arr[c->n] = part_field_ptr(P, f), c->name[c->n++] = f->name;
  }
}

/* The first of them that is not finite at particle a, or -1. */
static int non_finite(const struct checked *c, size_t a) {
  for (int k = 0; k < c->n; k++)
    if (!isfinite(c->arr[k][a])) return k;
  return -1;
}

static int classify(const struct model *M, const struct particles *P, const struct checked *c,
                    size_t a) {
  if (non_finite(c, a) >= 0) return NOT_FINITE;
  if (sph_at_wall(P->y[a], M->ly)) return THROUGH_WALL;
  const double s2 = P->u[a] * P->u[a] + P->v[a] * P->v[a] + P->w[a] * P->w[a];
  if (s2 >= M->e.c0 * M->e.c0) return SUPERSONIC;
  return OK;
}

int health_check(const struct model *M, const struct particles *P, long step, double t,
                 struct health_report *rep) {
  timer_push("health");
  struct checked c;
  checked_fields(P, &c);
  long long worst = LLONG_MAX;
#pragma omp parallel for schedule(static) reduction(min : worst)
  for (size_t a = 0; a < P->n; a++) {
    if (P->kind[a] != KIND_FLUID || classify(M, P, &c, a) == OK) continue;
    if (P->id[a] < worst) worst = P->id[a];
  }
  /* the failing particle of lowest id over all ranks; its owner writes the report */
  long long mine = worst;
  CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD));
  int rc = OK;
  for (size_t a = 0; worst != LLONG_MAX && mine == worst && a < P->n; a++) {
    if (P->id[a] != worst || P->kind[a] != KIND_FLUID) continue;
    rc = classify(M, P, &c, a);
    static const char *names[] = {"", "non-finite value", "particle through a wall",
                                  "particle faster than the speed of sound c0"};
    char field[32] = "";
    if (rc == NOT_FINITE) snprintf(field, sizeof field, " (%s)", c.name[non_finite(&c, a)]);
    snprintf(rep->what, sizeof rep->what,
             "%s at step %ld (t = %.9g): particle id %lld at (%.9g, %.9g, %.9g), velocity "
             "(%.6g, %.6g, %.6g), density %.6g%s",
             names[rc], step, t, (long long)P->id[a], P->x[a], P->y[a], P->z[a], P->u[a], P->v[a],
             P->w[a], P->rho[a], field);
    break;
  }
  if (worst != LLONG_MAX) { /* share the owner's report */
    int owner[2] = {rc, 0}, rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    owner[1] = rc != OK ? rank : -1;
    CHECK_MPI(MPI_Allreduce(MPI_IN_PLACE, owner, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD));
    rc = owner[0];
    CHECK_MPI(MPI_Bcast(rep->what, (int)sizeof rep->what, MPI_CHAR, owner[1], MPI_COMM_WORLD));
  }
  timer_pop();
  return rc;
}
