/**
 * @file error.h
 * @brief Error reporting in strict ISO C11: die(), warn(), msg() and the status-code helpers.
 *
 * Two tiers (STYLE item 13): code that touches user input or files returns an int status and
 * propagates it with TRY(); inner numerical kernels never return errors, health.c checks them.
 */
#ifndef CHANSPH_ERROR_H
#define CHANSPH_ERROR_H

#include <stdnoreturn.h>

/** Status codes returned by input/output functions. */
enum { CHANSPH_OK = 0, CHANSPH_ERR = 1 };

/**
 * @brief Print "[rank] file:line func(): message" to stderr, flush and abort all ranks.
 * @param[in] file,line,func location of the failure
 * @param[in] fmt printf-style message
 */
noreturn void error_die(const char *file, int line, const char *func, const char *fmt, ...);

/** @brief Print a warning to stderr (every rank). */
void error_warn(const char *fmt, ...);

/** @brief Print a timestamped message from rank 0 to stdout. */
void error_msg(const char *fmt, ...);

/** @brief Print an input error (file:line: message) to stderr, without aborting. */
void error_input(const char *fmt, ...);

#define die(...) error_die(__FILE__, __LINE__, __func__, __VA_ARGS__)
#define warn(...) error_warn(__VA_ARGS__)
#define msg(...) error_msg(__VA_ARGS__)

/** Propagate a non-zero status from an I/O or input function to the caller. */
#define TRY(call)                \
  do {                           \
    const int try_rc_ = (call);  \
    if (try_rc_) return try_rc_; \
  } while (0)

#endif
