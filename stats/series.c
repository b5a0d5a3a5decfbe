/** @file series.c @brief Implementation of series.h. */
#include "series.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"

void series_init(struct series *s, int ncol, const char *const *names, const char *const *units,
                 const char *const *long_names) {
  memset(s, 0, sizeof *s);
  s->ncol = ncol, s->names = names, s->units = units, s->long_names = long_names;
}

void series_add(struct series *s, const double *row) {
  if (s->n == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 256;
    s->data = mem_realloc(s->data, s->cap * (size_t)s->ncol, sizeof *s->data, "time series");
  }
  memcpy(s->data + s->n * (size_t)s->ncol, row, (size_t)s->ncol * sizeof *row);
  s->n++;
}

void series_free(struct series *s) {
  free(s->data);
  memset(s, 0, sizeof *s);
}
