/**
 * @file alloc.h
 * @brief The one allocator of chansph: malloc, calloc and realloc that die with a label.
 *
 * Running out of memory is not an input error that a caller can handle: every allocation in
 * the solver, the statistics engine and the restart code goes through these helpers, which
 * end the run with "out of memory: LABEL (N bytes)" on every rank (error.h, die()). A request
 * of zero bytes allocates one byte, so a non-NULL pointer always comes back.
 */
#ifndef CHANSPH_ALLOC_H
#define CHANSPH_ALLOC_H

#include <stddef.h>

/**
 * @brief malloc(n * size), or die.
 * @param[in] n,size number and size of the elements
 * @param[in] label what the memory is for (named in the error message)
 * @return the memory (uninitialised)
 */
void *mem_alloc(size_t n, size_t size, const char *label);

/** @brief As mem_alloc(), the memory zeroed (calloc). */
void *mem_calloc(size_t n, size_t size, const char *label);

/**
 * @brief mem_calloc() whose pages are written at once: the memory is resident from the start
 *        (the start-up memory check's estimate is then what the process holds, on any kernel),
 *        not when a long run first reaches it. For buffers that a run fills within its first
 *        horizon anyway (the Lagrangian engine's release slots).
 */
void *mem_calloc_resident(size_t n, size_t size, const char *label);

/**
 * @brief realloc(p, n * size), or die.
 * @param[in] p memory from these helpers, or NULL
 * @return the memory (the first min(old, new) bytes kept)
 */
void *mem_realloc(void *p, size_t n, size_t size, const char *label);

/** @brief The process's peak resident memory so far [bytes] (getrusage ru_maxrss; 0 if unknown). */
double mem_peak_resident(void);

#endif
