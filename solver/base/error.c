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

/* One message line, formatted whole and written with one call: under mpirun a rank's stdout
   and stderr reach the terminal through separate pipes, and a line written in pieces can be
   split by a line of the other stream (seen: "error: " + a log line + the message). */
static void emit(FILE *to, const char *prefix, const char *fmt, va_list ap) {
  char buf[4096];
  int n = snprintf(buf, sizeof buf, "%s", prefix);
  if (n < 0) n = 0;
  const int m = vsnprintf(buf + n, sizeof buf - (size_t)n - 1, fmt, ap);
  size_t len = (size_t)n + (m > 0 ? (size_t)m : 0);
  if (len > sizeof buf - 2) len = sizeof buf - 2;
  buf[len++] = '\n';
  fwrite(buf, 1, len, to);
  fflush(to);
}

noreturn void error_die(const char *file, int line, const char *func, const char *fmt, ...) {
  fflush(stdout);
  char prefix[512];
  snprintf(prefix, sizeof prefix, "[%d] %s:%d %s(): ", my_rank(), file, line, func);
  va_list ap;
  va_start(ap, fmt);
  emit(stderr, prefix, fmt, ap);
  va_end(ap);
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  if (init && !fin) MPI_Abort(MPI_COMM_WORLD, 2);
  exit(2);
}

noreturn void error_mpi(const char *file, int line, const char *func, const char *call, int code) {
  char text[MPI_MAX_ERROR_STRING] = "";
  int len = 0;
  if (MPI_Error_string(code, text, &len) != MPI_SUCCESS)
    snprintf(text, sizeof text, "code %d", code);
  error_die(file, line, func, "MPI call failed: %s: %s", call, text);
}

void error_warn(const char *fmt, ...) {
  fflush(stdout);
  va_list ap;
  va_start(ap, fmt);
  emit(stderr, "warning: ", fmt, ap);
  va_end(ap);
}

void error_input(const char *fmt, ...) {
  if (my_rank() != 0) return;
  fflush(stdout);
  va_list ap;
  va_start(ap, fmt);
  emit(stderr, "error: ", fmt, ap);
  va_end(ap);
}

void error_msg(const char *fmt, ...) {
  if (my_rank() != 0) return;
  char stamp[32];
  const time_t now = time(NULL);
  strftime(stamp, sizeof stamp, "%H:%M:%S", localtime(&now));
  char prefix[40];
  snprintf(prefix, sizeof prefix, "[%s] ", stamp);
  va_list ap;
  va_start(ap, fmt);
  emit(stdout, prefix, fmt, ap);
  va_end(ap);
}
