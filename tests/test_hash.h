/**
 * @file test_hash.h
 * @brief A deterministic pseudo-random number per particle id and component for the tests
 *        that perturb a lattice (test_shift, test_kgc): the same on any rank and thread count.
 */
#ifndef CHANSPH_TEST_HASH_H
#define CHANSPH_TEST_HASH_H

#include <stdint.h>

/** A number in [-1, 1) from (id, component): splitmix64. */
static inline double hash_unit(int64_t id, int c) {
  uint64_t z = (uint64_t)id * 4 + (uint64_t)c + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return (double)(z >> 11) / 4503599627370496.0 - 1.0;
}

#endif
