/**
 * @file expect.h
 * @brief The check of the serial statistics tests (test_stats, test_pdf): EXPECT(cond, fmt,
 *        ...) prints "FAIL: " and the message and counts the failure in `failures`, which the
 *        test's main() turns into its exit status (test_stats_mpi has its own, naming the rank).
 */
#ifndef CHANSPH_TEST_EXPECT_H
#define CHANSPH_TEST_EXPECT_H

#include <stdio.h>

/** Failed checks of the test program. */
static int failures = 0;

/** Check cond; if it fails, print "FAIL: " and the message (printf arguments) and count it. */
#define EXPECT(cond, ...)           \
  do {                              \
    if (!(cond)) {                  \
      printf("FAIL: " __VA_ARGS__); \
      printf("\n");                 \
      failures++;                   \
    }                               \
  } while (0)

#endif
