/**
 * @file sanitize_probe.c
 * @brief Probe of the sanitizer suppressions (issue 26, point 10): MPI_Init and MPI_Finalize
 *        under AddressSanitizer, nothing else; with the argument `leak`, also a leak in this
 *        program's own code, which LeakSanitizer must still report with the suppressions of
 *        tests/sanitize/lsan.supp.
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/** A block that is never freed (the `leak` case). */
static void *probe_lost;

/** @brief Lose a block of n bytes: the pointer is dropped, so LeakSanitizer reports it. */
static void probe_leak(size_t n) {
  probe_lost = malloc(n);
  if (probe_lost) memset(probe_lost, 1, n);
  probe_lost = NULL;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  if (argc > 1 && !strcmp(argv[1], "leak")) probe_leak(4096);
  MPI_Finalize();
  printf("sanitize_probe: done\n");
  return 0;
}
