/**
 * @file synthetic.h
 * @brief The counter-based random numbers of the statistics tests' synthetic fields (the same
 *        key gives the same number on every run, rank and thread: no hidden state, no rand()).
 */
#ifndef CHANSPH_TEST_SYNTHETIC_H
#define CHANSPH_TEST_SYNTHETIC_H

#include <math.h>
#include <stdint.h>

/** @brief splitmix64 of a key. */
static inline uint64_t mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/** @brief A uniform number in (0, 1) from a key. */
static inline double uniform(uint64_t key) {
  return ((double)(mix(key) >> 11) + 0.5) / 9007199254740992.0;
}

/** @brief A standard normal number from a key (Box-Muller on keys 2 key, 2 key + 1). */
static inline double gauss(uint64_t key) {
  return sqrt(-2.0 * log(uniform(2 * key))) * cos(6.283185307179586 * uniform(2 * key + 1));
}

#endif
