/**
 * @file pair_loop.h
 * @brief What every loop over a neighbour list shares: the frame of the pair geometry (kernel
 *        and periodic lengths of the model), the view of the neighbours' fields, and the padded
 *        gather of a list's records into a thread's pair buffer.
 *
 * A loop over the neighbours of particle a reads field k of neighbour j as
 * `V.f[k][pair_index(gathered, V.nl, j)]`: from the records the list's neighbours were gathered
 * into (records.h; `gathered`, index j) or from the particle arrays through the list (index
 * nl[j]). `gathered` is a constant of each specialised loop, so the index costs nothing per pair.
 * The loops copy the pointers they read into `restrict` locals before the loop, which is what
 * lets them vectorise.
 */
#ifndef CHANSPH_PAIR_LOOP_H
#define CHANSPH_PAIR_LOOP_H

#include <omp.h>
#include <stdint.h>

#include "nbr.h"
#include "pair.h"
#include "records.h"
#include "sph.h"

/** The constants of pair_geom() for one model, copied into a loop's registers. */
struct pair_frame {
  struct kernel K; /*!< the kernel */
  double lx, lz;   /*!< periodic lengths [m] */
  int d3;          /*!< 1 in 3-D */
};

/** The frame of model M. */
static inline struct pair_frame pair_frame_of(const struct model *M) {
  return (struct pair_frame){M->k, M->lx, M->lz, M->dim == 3};
}

/** Geometry of the pair whose separation before the periodic wrap is (dx, dy, dz). */
static inline struct pair pair_at(const struct pair_frame *F, double dx, double dy, double dz) {
  return pair_geom(&F->K, F->lx, F->lz, F->d3, dx, dy, dz);
}

/** pair_at() for a loop specialised on the kernel shape (a compile-time constant: pair.h). */
static inline struct pair pair_at_shape(const struct pair_frame *F, const int shape, double dx,
                                        double dy, double dz) {
  return pair_geom_shape(&F->K, shape, F->lx, F->lz, F->d3, dx, dy, dz);
}

/** The neighbours of one particle as a pair loop reads them (see the file comment). */
struct pair_view {
  const double *f[REC_FIELDS]; /*!< field k (enum rec_field) of the neighbours */
  const int32_t *nl;           /*!< the list (arrays) or NULL (gathered) */
};

/** The index of neighbour j in the view's arrays. */
static inline int32_t pair_index(const int gathered, const int32_t *nl, int j) {
  return gathered ? j : nl[j];
}

/** The view of the particle arrays of P through the list nl (records_field_array). */
static inline struct pair_view pair_view_arrays(const struct particles *P, const int32_t *nl) {
  struct pair_view V = {.nl = nl};
  for (int k = 0; k < REC_FIELDS; k++) V.f[k] = records_field_array(P, k);
  return V;
}

/** The view of a pair buffer bf whose field k holds the gathered records at bf + k ld. */
static inline struct pair_view pair_view_gathered(const double *bf, int ld) {
  struct pair_view V = {.nl = NULL};
  for (int k = 0; k < REC_FIELDS; k++) V.f[k] = bf + (size_t)k * ld;
  return V;
}

/** The view of the neighbours of particle a: gathered into the pair buffer bf (the records
    gather_padded or records_gather put there) or the arrays through a's list. */
static inline struct pair_view pair_view_of(const struct particles *P, const struct nbr *nb,
                                            size_t a, const double *bf, const int gathered) {
  return gathered ? pair_view_gathered(bf, nb->pairbuf_ld)
                  : pair_view_arrays(P, nb->list + a * (size_t)nb->stride);
}

/** The list of particle a. */
static inline const int32_t *pair_list(const struct nbr *nb, size_t a) {
  return nb->list + a * (size_t)nb->stride;
}

/** The pair buffer of the calling thread (nbr.h pairbuf). */
static inline double *pair_buffer(const struct nbr *nb) {
  return nb->pairbuf[omp_get_thread_num()];
}

#endif
