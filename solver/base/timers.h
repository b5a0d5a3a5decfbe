/**
 * @file timers.h
 * @brief Named phase timers: timer_push("neighbours") ... timer_pop(), and a per-phase report.
 */
#ifndef CHANSPH_TIMERS_H
#define CHANSPH_TIMERS_H

#include <stdio.h>

/** @brief Start timing a named phase (nesting allowed; time is charged to the innermost). */
void timer_push(const char *name);

/** @brief Stop the innermost phase. */
void timer_pop(void);

/** @brief Wall-clock seconds since an arbitrary origin. */
double timer_now(void);

/** @brief Reset all phase totals. */
void timer_reset(void);

/**
 * @brief Print the per-phase table: seconds, share of the total and calls.
 * @param[in] f stream
 * @param[in] total total wall seconds the shares refer to
 */
void timer_report(FILE *f, double total);

#endif
