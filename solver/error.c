/** @file error.c @brief Implementation of error.h. */
#include "error.h"

#include <mpi.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static int my_rank(void) {
  int init = 0, rank = 0;
  MPI_Initialized(&init);
  if (init) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

noreturn void error_die(const char *file, int line, const char *func, const char *fmt, ...) {
  fflush(stdout);
  fprintf(stderr, "[%d] %s:%d %s(): ", my_rank(), file, line, func);
  va_list ap;
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  fflush(stderr);
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  if (init && !fin) MPI_Abort(MPI_COMM_WORLD, 2);
  exit(2);
}

void error_warn(const char *fmt, ...) {
  fflush(stdout);
  fprintf(stderr, "warning: ");
  va_list ap;
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  fflush(stderr);
}

void error_input(const char *fmt, ...) {
  if (my_rank() != 0) return;
  fflush(stdout);
  fprintf(stderr, "error: ");
  va_list ap;
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  fflush(stderr);
}

void error_msg(const char *fmt, ...) {
  if (my_rank() != 0) return;
  char stamp[32];
  const time_t now = time(NULL);
  strftime(stamp, sizeof stamp, "%H:%M:%S", localtime(&now));
  printf("[%s] ", stamp);
  va_list ap;
  va_start(ap, fmt);
  vprintf(fmt, ap);
  va_end(ap);
  putchar('\n');
  fflush(stdout);
}
