/** @file durable.c @brief Implementation of durable.h. */
#include "durable.h"

#include <errno.h>
#include <fcntl.h>
#include <mpi.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "error.h"

int durable_sync(const char *path, int dir) {
  const int fd = open(path, dir ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) return -1;
  const int rc = fsync(fd);
  close(fd);
  return rc;
}

int durable_sync_dir(const char *path, char *err, size_t errlen) {
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = '\0';
  if (durable_sync(slash ? dir : ".", 1)) {
    snprintf(err, errlen, "cannot fsync directory %s: %s", slash ? dir : ".", strerror(errno));
    return 1;
  }
  return 0;
}

int durable_agree(int rc, char *err, size_t errlen) {
  int me = 0, size = 1, first = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int mine = rc ? me : size;
  CHECK_MPI(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD));
  if (first == size) return 0;
  if (errlen > 0 && me != first) err[0] = '\0';
  CHECK_MPI(MPI_Bcast(err, (int)errlen, MPI_CHAR, first, MPI_COMM_WORLD));
  return 1;
}

int durable_probe(const char *tmp, size_t bytes, const char *noun, char *err, size_t errlen) {
  const int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  int e = fd < 0 ? errno : posix_fallocate(fd, 0, (off_t)bytes);
  if (fd >= 0 && close(fd) && !e) e = errno;
  if (!e) return 0;
  snprintf(err, errlen, "cannot write %s%s%s (%s; %zu bytes needed)", noun, noun[0] ? " " : "", tmp,
           strerror(e), bytes);
  remove(tmp);
  return 1;
}
