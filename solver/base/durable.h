/**
 * @file durable.h
 * @brief The rules every output file of chansph is written by, shared by the HDF5 writers
 *        (checkpoints, snapshots: restart/ckpt.h) and the netCDF ones (stats/ncout.h): write
 *        NAME.tmp, fsync it, rename it over NAME, fsync the directory; a collective write first
 *        checks that the file fits and the ranks agree on every outcome, so a failure on one
 *        rank stops them all at the same call with one message.
 */
#ifndef CHANSPH_DURABLE_H
#define CHANSPH_DURABLE_H

#include <stddef.h>

/** @brief fsync a file (dir = 0) or a directory (dir = 1) by name. @return 0, or -1 (errno) */
int durable_sync(const char *path, int dir);

/**
 * @brief fsync the directory of path (".", if path names none), after a rename into it.
 * @return 0, or 1 with a message naming the directory in err (errlen bytes)
 */
int durable_sync_dir(const char *path, char *err, size_t errlen);

/**
 * @brief Agree on an outcome over MPI_COMM_WORLD: returns 1 on every rank if rc was nonzero on
 *        any, with err (size errlen) replaced by the lowest failing rank's message. Collective.
 */
int durable_agree(int rc, char *err, size_t errlen);

/**
 * @brief Before a collective write (rank 0): create tmp and allocate bytes in it, so that a
 *        file-size limit or a full disk fails here, cleanly, and not inside the parallel HDF5
 *        write (HDF5 1.10 cannot fail there cleanly: an I/O error on one rank leaves the others
 *        waiting in its own MPI calls).
 * @param[in] noun what the message calls the file ("checkpoint"; "" for none)
 * @return 0, or 1 with "cannot write NOUN TMP (cause; N bytes needed)" in err, tmp removed
 */
int durable_probe(const char *tmp, size_t bytes, const char *noun, char *err, size_t errlen);

#endif
