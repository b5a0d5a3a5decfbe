/** @file timers.c @brief Implementation of timers.h (single-threaded callers only). */
#include "timers.h"

#include <string.h>
#include <time.h>

#include "error.h"

enum { MAX_PHASES = 32, MAX_DEPTH = 8 };

static struct {
  const char *name;
  double seconds;
  long calls;
} phases[MAX_PHASES];
static int n_phases;
static int stack[MAX_DEPTH];
static double started[MAX_DEPTH];
static int depth;

double timer_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int find(const char *name) {
  for (int i = 0; i < n_phases; i++)
    if (!strcmp(phases[i].name, name)) return i;
  if (n_phases == MAX_PHASES) die("too many timer phases");
  phases[n_phases].name = name;
  return n_phases++;
}

void timer_push(const char *name) {
  if (depth == MAX_DEPTH) die("timer stack overflow at %s", name);
  const double now = timer_now();
  if (depth > 0) phases[stack[depth - 1]].seconds += now - started[depth - 1];
  stack[depth] = find(name);
  started[depth] = now;
  depth++;
}

void timer_pop(void) {
  if (depth == 0) die("timer_pop without timer_push");
  const double now = timer_now();
  depth--;
  phases[stack[depth]].seconds += now - started[depth];
  phases[stack[depth]].calls++;
  if (depth > 0) started[depth - 1] = now;
}

void timer_reset(void) {
  for (int i = 0; i < n_phases; i++) phases[i].seconds = 0.0, phases[i].calls = 0;
}

void timer_report(FILE *f, double total) {
  double sum = 0.0;
  fprintf(f, "%-14s %10s %7s %8s\n", "phase", "seconds", "share", "calls");
  for (int i = 0; i < n_phases; i++) {
    sum += phases[i].seconds;
    fprintf(f, "%-14s %10.3f %6.1f%% %8ld\n", phases[i].name, phases[i].seconds,
            total > 0 ? 100.0 * phases[i].seconds / total : 0.0, phases[i].calls);
  }
  fprintf(f, "%-14s %10.3f %6.1f%%\n", "(other)", total - sum,
          total > 0 ? 100.0 * (total - sum) / total : 0.0);
}
