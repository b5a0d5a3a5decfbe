/**
 * @file state.h
 * @brief The run state as a list of named arrays: what a checkpoint must hold.
 *
 * Every module that carries state across steps (particles, wall values, the flux
 * controller, statistics accumulators, ...) describes it by appending fields to a
 * state_list: a name that reads like a path ("stats/profile/sum_u"), a type, a shape and
 * the live memory. The checkpoint writer stores each field as one dataset under that path;
 * the reader fills the same memory back. A module adds state by adding fields, without
 * touching the checkpoint code (docs/checkpoint-format.md).
 *
 * Particle arrays of a run on several MPI ranks are distributed: each rank names its block
 * of rows (offset, total), and the collective writer and the block reader (restart/ckpt.h)
 * touch only those rows of the dataset.
 *
 * Arrays whose length is only known when reading (time series that grow during the run)
 * give a reserve() callback: the reader calls it with the stored shape and reads into the
 * memory it returns (NULL means "cannot", and the reader reports the field).
 * Fields whose records grew in a later format accept the older shape the same way and give an
 * after_read() callback that converts what was read into the live layout.
 */
#ifndef CHANSPH_STATE_H
#define CHANSPH_STATE_H

#include <stddef.h>
#include <stdint.h>

enum { STATE_MAX_RANK = 3 };

enum state_type {
  STATE_F64,  /*!< double */
  STATE_I64,  /*!< int64_t (also long on LP64 systems) */
  STATE_TEXT, /*!< a string: data is a char ** to a malloc'd string; reading replaces it */
  STATE_I32,  /*!< int32_t (also int) */
  STATE_U8    /*!< uint8_t (flags, particle kinds) */
};

struct state_field {
  char name[96];               /*!< path-like name, '/' separates groups */
  enum state_type type;        /*!< element type */
  int rank;                    /*!< 0 for a scalar */
  size_t dims[STATE_MAX_RANK]; /*!< shape (row-major) */
  void *data;                  /*!< live memory of the module */
  const char *units;           /*!< physical units, or NULL */
  /** For fields sized on reading: return memory for the stored shape (or NULL). */
  void *(*reserve)(void *owner, int rank, const size_t *dims);
  void *owner; /*!< first argument of reserve and after_read */
  /** Called after a field was read into memory reserve() returned (dims: the stored shape):
      converts the layout of an earlier format into the live one in place (or NULL). */
  void (*after_read)(void *owner, int rank, const size_t *dims);
  int optional; /*!< 1: a checkpoint of an earlier format may lack it (reading leaves it) */
  int absent;   /*!< set by the reader: an optional field the checkpoint lacked */
  /** Distributed fields (total > 0): this rank holds rows offset .. offset+dims[0]-1 of a
      dataset of total rows (the other dimensions whole); each rank reads and writes its own
      rows. total = 0: the whole field, the same on every rank. */
  size_t offset, total;
};

struct state_list {
  struct state_field *f; /*!< fields in the order they were added */
  int n, cap;
};

/**
 * @brief Append a field.
 * @param L list
 * @param name path-like name (copied; at most 95 characters)
 * @param type element type
 * @param rank number of dimensions (0: scalar)
 * @param dims shape, rank entries (may be NULL for rank 0)
 * @param data live memory
 * @param units units or NULL
 * @return the new field, for setting reserve/owner
 */
struct state_field *state_add(struct state_list *L, const char *name, enum state_type type,
                              int rank, const size_t *dims, void *data, const char *units);

/** @brief Elements of a field (1 for a scalar). */
size_t state_count(const struct state_field *f);

/** @brief The field of that name, or NULL. */
struct state_field *state_find(const struct state_list *L, const char *name);

/** @brief Free the list (not the data it points to). */
void state_free(struct state_list *L);

#endif
