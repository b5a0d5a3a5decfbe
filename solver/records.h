/**
 * @file records.h
 * @brief Pair records: what the pair loops read at a neighbour, packed per particle, and their
 *        gather into short structure-of-arrays buffers, one per neighbour list.
 *
 * A pair loop reads about ten values of each neighbour b (position, velocity, volume, density,
 * mass, p/rho^2, sound speed, eddy viscosity). Read from ten separate arrays through the index
 * list, each is a scalar load (the compiler emulates the vector gather). Packed into one
 * 128-byte record per particle, the values of eight neighbours are eight aligned vector loads
 * and a transpose (AVX-512, where the processor has it), written to buffers the loop then
 * reads contiguously. The records are refreshed after every pass that changes a field they
 * hold (records_pack), for the owned particles and the ghosts alike.
 */
#ifndef CHANSPH_RECORDS_H
#define CHANSPH_RECORDS_H

#include <stddef.h>
#include <stdint.h>

#include "part.h"

/** Fields of a record; the two halves of 8 are gathered separately. */
enum rec_field {
  REC_X,
  REC_Y,
  REC_Z,
  REC_U,
  REC_V,
  REC_W,
  REC_VOL,
  REC_RHO, /* half 0 */
  REC_M,
  REC_PR2,
  REC_C,
  REC_NUR,     /* half 1 */
  REC_LEN = 16 /*!< doubles per record */
};

/** @brief Choose the gather for this processor (AVX-512 or portable); call once, serially. */
void records_init(void);

/** @brief Whether the pair loops should gather records (the AVX-512 transpose) rather than
           read the particle arrays through the index list (the faster choice without it). */
int records_fast(void);

/**
 * @brief Pack the records of slots 0 .. n-1 (owned and ghost particles) from the arrays of P
 *        (P->nur may be NULL: 0 is stored).
 */
void records_pack(struct particles *P, size_t n);

/**
 * @brief Copy half `half` (fields 8 half .. 8 half + 7) of the records of the particles
 *        nl[0 .. cnt-1] to out[f * ld + j], f = 0 .. 7, j = 0 .. cnt-1 (of half 1 only the
 *        fields in use, REC_M .. REC_NUR, are guaranteed).
 * @param ld leading dimension of out, a multiple of 8; out 64-byte aligned
 */
void records_gather(const double *rec, const int32_t *nl, int cnt, int half, double *out, int ld);

#endif
