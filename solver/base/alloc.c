/** @file alloc.c @brief Implementation of alloc.h. */
#include "alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/resource.h>

#include "error.h"

static size_t bytes_of(size_t n, size_t size, const char *label) {
  if (size && n > SIZE_MAX / size) die("out of memory: %s (%zu x %zu bytes)", label, n, size);
  const size_t bytes = n * size;
  return bytes ? bytes : 1;
}

void *mem_alloc(size_t n, size_t size, const char *label) {
  const size_t bytes = bytes_of(n, size, label);
  void *p = malloc(bytes);
  if (!p) die("out of memory: %s (%zu bytes)", label, bytes);
  return p;
}

void *mem_calloc(size_t n, size_t size, const char *label) {
  const size_t bytes = bytes_of(n, size, label);
  void *p = calloc(1, bytes);
  if (!p) die("out of memory: %s (%zu bytes)", label, bytes);
  return p;
}

void *mem_calloc_resident(size_t n, size_t size, const char *label) {
  char *p = mem_calloc(n, size, label);
  volatile char *v = p; /* a store the compiler cannot drop after calloc */
  const size_t bytes = n * size;
  for (size_t i = 0; i < bytes; i += 4096) v[i] = 0;
  return p;
}

void *mem_realloc(void *p, size_t n, size_t size, const char *label) {
  const size_t bytes = bytes_of(n, size, label);
  void *q = realloc(p, bytes);
  if (!q) die("out of memory: %s (%zu bytes)", label, bytes);
  return q;
}

double mem_peak_resident(void) {
  struct rusage u;
  if (getrusage(RUSAGE_SELF, &u)) return 0.0;
  return (double)u.ru_maxrss * 1024.0; /* kilobytes on Linux */
}
