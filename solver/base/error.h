/**
 * @file error.h
 * @brief Error reporting in strict ISO C11: die(), warn(), msg() and the status-code helpers.
 *
 * Two tiers (STYLE item 13): code that touches user input or files returns an int status and
 * propagates it with TRY(); inner numerical kernels never return errors, health.c checks them.
 */
#ifndef CHANSPH_ERROR_H
#define CHANSPH_ERROR_H

#include <mpi.h>
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

/**
 * @brief die() for a failed MPI call: the call's text, MPI's message for the code, file and line.
 * @param[in] file,line,func location of the call
 * @param[in] call the call as written
 * @param[in] code its return code
 */
noreturn void error_mpi(const char *file, int line, const char *func, const char *call, int code);

#define die(...) error_die(__FILE__, __LINE__, __func__, __VA_ARGS__)
#define warn(...) error_warn(__VA_ARGS__)
#define msg(...) error_msg(__VA_ARGS__)

/** Run an MPI call; a failure dies naming the call, file and line (MPI_Error_string). The
    program sets MPI_ERRORS_RETURN on MPI_COMM_WORLD so failures reach this check. (HDF5 calls:
    CHECK_H5 in restart/ckpt.h; netCDF calls: CHECK_NC in stats/ncutil.h.) */
#define CHECK_MPI(call)                                              \
  do {                                                               \
    const int check_mpi_rc_ = (call);                                \
    if (check_mpi_rc_ != MPI_SUCCESS)                                \
      error_mpi(__FILE__, __LINE__, __func__, #call, check_mpi_rc_); \
  } while (0)

/** Propagate a non-zero status from an I/O or input function to the caller. */
#define TRY(call)                \
  do {                           \
    const int try_rc_ = (call);  \
    if (try_rc_) return try_rc_; \
  } while (0)

#endif
