/** @file state.c @brief Implementation of state.h. */
#include "state.h"

#include <stdlib.h>
#include <string.h>

#include "error.h"

struct state_field *state_add(struct state_list *L, const char *name, enum state_type type,
                              int rank, const size_t *dims, void *data, const char *units) {
  if (rank < 0 || rank > STATE_MAX_RANK) die("state field %s: rank %d", name, rank);
  if (strlen(name) >= sizeof L->f->name) die("state field name too long: %s", name);
  if (state_find(L, name)) die("state field %s added twice", name);
  if (L->n == L->cap) {
    L->cap = L->cap ? 2 * L->cap : 32;
    L->f = realloc(L->f, (size_t)L->cap * sizeof *L->f);
    if (!L->f) die("out of memory for the state list");
  }
  struct state_field *f = &L->f[L->n++];
  memset(f, 0, sizeof *f);
  strcpy(f->name, name);
  f->type = type, f->rank = rank, f->data = data, f->units = units;
  for (int i = 0; i < rank; i++) f->dims[i] = dims[i];
  return f;
}

size_t state_count(const struct state_field *f) {
  size_t n = 1;
  for (int i = 0; i < f->rank; i++) n *= f->dims[i];
  return n;
}

struct state_field *state_find(const struct state_list *L, const char *name) {
  for (int i = 0; i < L->n; i++)
    if (!strcmp(L->f[i].name, name)) return &L->f[i];
  return NULL;
}

void state_free(struct state_list *L) {
  free(L->f);
  memset(L, 0, sizeof *L);
}
