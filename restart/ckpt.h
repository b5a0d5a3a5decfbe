/**
 * @file ckpt.h
 * @brief The checkpoint file: a state list (solver/base/state.h) as one HDF5 dataset per field,
 *        with a format version, a completion mark and a Fletcher32 checksum on every dataset
 *        (docs/checkpoint-format.md).
 *
 * Files are written to NAME.tmp, flushed, fsync'ed and renamed, and the directory is fsync'ed:
 * a crash at any moment leaves either the previous files or the complete new one. Readers
 * verify everything they read and name the file, the dataset and the check that failed.
 */
#ifndef CHANSPH_CKPT_H
#define CHANSPH_CKPT_H

#include <stddef.h>

#include "error.h"
#include "state.h"

/** Run an HDF5 call whose failure is a bug, not an input or disk error (property lists, types):
    a negative result dies naming the call, file and line. The writer and reader paths that a
    full disk or a corrupt file can fail return a status instead (CKPT errors). */
#define CHECK_H5(call)                                  \
  do {                                                  \
    if ((call) < 0) die("HDF5 call failed: %s", #call); \
  } while (0)

/** Value of the root attribute "format". */
#define CKPT_FORMAT "chansph-checkpoint"

/** Format version: a reader refuses a newer major version; minor versions only add
    (1.1: root attribute run_id). */
enum { CKPT_VERSION_MAJOR = 1, CKPT_VERSION_MINOR = 15 };

/** Room for a run identity (a UUID has 36 characters; restart.h: rundir_*). */
enum { CKPT_RUN_ID_MAX = 64 };

/** What ckpt_info() reads from a file without reading the state. */
struct ckpt_info {
  long step;                    /*!< step of the state */
  double time;                  /*!< simulated time of the state [s] */
  int major;                    /*!< format version of the file */
  int minor;                    /*!< format version of the file */
  char *scene;                  /*!< resolved scene text (malloc'd; free it) */
  size_t n_bytes;               /*!< file size [bytes] */
  char run_id[CKPT_RUN_ID_MAX]; /*!< identity of the run that wrote it ("" before format 1.1) */
};

/**
 * @brief The identity of the run, written as root attribute run_id into every following file
 *        (checkpoints, snapshots); "" writes none. Call with the same text on every rank.
 */
void ckpt_set_run_id(const char *id);

/**
 * @brief Write a checkpoint atomically.
 * @param[in] path final file name (PATH.tmp is used while writing)
 * @param[in] L fields to write, each as a dataset at its name
 * @param[in] scene resolved scene text (dataset /scene)
 * @param[in] step,time state's step and time (root attributes)
 * @param[out] err message on failure (names the file and dataset, and the system error)
 * @param[in] errlen size of err
 * @return 0, or nonzero on failure (the temporary file is removed; existing files untouched)
 */
int ckpt_write(const char *path, const struct state_list *L, const char *scene, long step,
               double time, char *err, size_t errlen);

/**
 * @brief Write a checkpoint collectively: every rank of MPI_COMM_WORLD calls it with the same
 *        fields, each distributed field (state.h: offset, total) holding this rank's rows and
 *        every other field the same on all ranks. On one rank this is ckpt_write(); on several,
 *        parallel HDF5 (MPI-IO driver) writes PATH.tmp, each rank its own rows, rank 0 the
 *        replicated fields, and rank 0 then fsyncs and renames it. Every rank returns the same
 *        result and message (docs/checkpoint-format.md).
 */
int ckpt_write_all(const char *path, const struct state_list *L, const char *scene, long step,
                   double time, char *err, size_t errlen);

/**
 * @brief Agree on an outcome over MPI_COMM_WORLD: returns 1 on every rank if rc was nonzero on
 *        any, with err (size errlen) replaced by the lowest failing rank's message. Collective.
 *        (durable_agree, solver/base/durable.h, which the netCDF writers share.)
 */
int ckpt_agree(int rc, char *err, size_t errlen);

/**
 * @brief The writer behind ckpt_write(), for other HDF5 files of the same rules (particle
 *        snapshots): root attribute "format" = format, version, step, time, completion mark.
 * @param[in] scene scene text for dataset /scene, or NULL for none
 */
int ckpt_write_fields(const char *path, const char *format, const struct state_list *L,
                      const char *scene, long step, double time, char *err, size_t errlen);

/**
 * @brief ckpt_write_fields() collectively, as ckpt_write_all() writes a checkpoint: every rank
 *        of MPI_COMM_WORLD calls it, each distributed field holding this rank's rows; on one
 *        rank the serial writer (the same bytes as ckpt_write_fields()), on several parallel
 *        HDF5. Every rank returns the same result and message (particle snapshots).
 */
int ckpt_write_fields_all(const char *path, const char *format, const struct state_list *L,
                          const char *scene, long step, double time, char *err, size_t errlen);

/**
 * @brief Open a checkpoint and check it: HDF5 structure, format name, version (a newer major
 *        version is refused), completion mark; read step, time, run identity and scene text.
 * @param[in] path file
 * @param[out] info what was read (info->scene must be freed)
 * @param[out] err,errlen message on failure
 * @return 0 or nonzero
 */
int ckpt_info(const char *path, struct ckpt_info *info, char *err, size_t errlen);

/**
 * @brief Read every field of a list from a checkpoint into its memory, verifying presence,
 *        type, shape and checksum. Fields with a reserve() callback take the stored shape.
 *        Of a distributed field (state.h) only this rank's rows are read (a hyperslab; the
 *        stored shape must have total rows). Not collective: each rank opens the file with the
 *        default driver and reads independently (callers agree on the outcome: ckpt_agree).
 * @param[in] path file
 * @param[in,out] L fields (data and dims of reserved fields are updated)
 * @param[out] err,errlen message on failure
 * @return 0 or nonzero
 */
int ckpt_read(const char *path, struct state_list *L, char *err, size_t errlen);

/** @brief Bytes of a checkpoint's data for a list: every field in whole chunks with their
    checksums, as write_field lays it out (the metadata not included). */
size_t ckpt_state_bytes(const struct state_list *L);

#endif
