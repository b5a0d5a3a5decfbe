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
 * reads contiguously. Which array fills which slot is the field table's (part.h: the role
 * PF_PAIR and the slot `rec`). The records are packed once the state of a step is complete
 * (records_pack), for the owned particles and the ghosts alike, and only where the loops of
 * this processor gather them (records_fast).
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
  REC_NUR,                  /* half 1 */
  REC_FIELDS = REC_NUR + 1, /*!< fields in use */
  REC_LEN = 16              /*!< doubles per record */
};

/** @brief Choose the gather for this processor (AVX-512 or portable); call once, serially. */
void records_init(void);

/** @brief Whether the pair loops should gather records (the AVX-512 transpose) rather than
           read the particle arrays through the index list (the faster choice without it). */
int records_fast(void);

/**
 * @brief Pack the records of slots 0 .. n-1 (owned and ghost particles) from the arrays of P
 *        that the field table gives each slot (an optional array that is not allocated, such
 *        as nu_r without LES: 0 is stored).
 */
void records_pack(struct particles *P, size_t n);

/** @brief The array of P that fills record field k (enum rec_field), or NULL if it is not
           allocated: the field table's entry with role PF_PAIR and slot k. */
const double *records_field_array(const struct particles *P, int k);

/**
 * @brief Copy half `half` (fields 8 half .. 8 half + 7) of the records of the particles
 *        nl[0 .. cnt-1] to out[f * ld + j], f = 0 .. 7, j = 0 .. cnt-1 (of half 1 only the
 *        fields in use, REC_M .. REC_NUR, are guaranteed).
 * @param ld leading dimension of out, a multiple of 8; out 64-byte aligned
 */
void records_gather(const double *rec, const int32_t *nl, int cnt, int half, double *out, int ld);

/**
 * @brief Gather the records of a list of n neighbours, nf of them fluid, into a pair buffer bf
 *        (leading dimension ld, nbr.h pairbuf_ld), each part padded by zero records to a
 *        multiple of 8 entries, so that the loops over the parts run in whole vectors (no
 *        scalar remainder): the fluid part at 0 .. nf8-1, the vertices from nf8 on. Zero
 *        records give exact zeros in every pair term (V_b = m_b = rho_b = 0, finite geometry).
 * @param[out] nf8 the end of the padded fluid part
 * @return the end of the padded vertex part
 */
int records_gather_padded(const double *rec, const int32_t *nl, int nf, int n, double *bf, int ld,
                          int *nf8);

#endif
