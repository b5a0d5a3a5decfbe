/** @file profile.c @brief Implementation of profile.h. */
#include "profile.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void *xcalloc(size_t n, size_t size) {
  void *p = calloc(n ? n : 1, size);
  if (!p) {
    fprintf(stderr, "error: out of memory in the statistics engine\n");
    abort();
  }
  return p;
}

void profile_init(struct profile *pr, int nb, double y0, double y1) {
  memset(pr, 0, sizeof *pr);
  pr->nb = nb, pr->y0 = y0, pr->y1 = y1;
  pr->sum_u = xcalloc((size_t)nb, sizeof(double));
  pr->sum_v = xcalloc((size_t)nb, sizeof(double));
  pr->sum_w = xcalloc((size_t)nb, sizeof(double));
  pr->sum_y = xcalloc((size_t)nb, sizeof(double));
  pr->count = xcalloc((size_t)nb, sizeof(int64_t));
}

void profile_free(struct profile *pr) {
  free(pr->sum_u), free(pr->sum_v), free(pr->sum_w), free(pr->sum_y), free(pr->count);
  memset(pr, 0, sizeof *pr);
}

void profile_add(struct profile *pr, size_t n, const double *y, const double *u, const double *v,
                 const double *w, const uint8_t *skip) {
  const double scale = pr->nb / (pr->y1 - pr->y0);
  for (size_t i = 0; i < n; i++) {
    if (skip && skip[i]) continue;
    int b = (int)floor((y[i] - pr->y0) * scale);
    b = b < 0 ? 0 : b >= pr->nb ? pr->nb - 1 : b; /* samples outside [y0, y1]: end bins */
    pr->sum_u[b] += u[i], pr->sum_v[b] += v[i], pr->sum_w[b] += w[i], pr->sum_y[b] += y[i];
    pr->count[b]++;
  }
  pr->n_snapshots++;
}

double profile_centre(const struct profile *pr, int i) {
  return pr->y0 + (i + 0.5) * (pr->y1 - pr->y0) / pr->nb;
}

void series_init(struct series *s, int ncol, const char *const *names, const char *const *units) {
  memset(s, 0, sizeof *s);
  s->ncol = ncol, s->names = names, s->units = units;
}

void series_add(struct series *s, const double *row) {
  if (s->n == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 256;
    double *d = realloc(s->data, s->cap * (size_t)s->ncol * sizeof *d);
    if (!d) {
      fprintf(stderr, "error: out of memory in the time series\n");
      abort();
    }
    s->data = d;
  }
  memcpy(s->data + s->n * (size_t)s->ncol, row, (size_t)s->ncol * sizeof *row);
  s->n++;
}

void series_free(struct series *s) {
  free(s->data);
  memset(s, 0, sizeof *s);
}
