/**
 * @file rundir.c
 * @brief The run directory's identity (DIR/run_id, written at the first start and stored in
 *        every checkpoint and output) and its lock (DIR/.lock, held for the life of the run).
 */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "alloc.h"
#include "ckpt.h"
#include "error.h"
#include "restart.h"

static int rank0(void) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank == 0;
}

/* Every rank takes rank 0's result (and text). */
static int agree(int rc, char *text, int n) {
  CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
  if (text) CHECK_MPI(MPI_Bcast(text, n, MPI_CHAR, 0, MPI_COMM_WORLD));
  return rc;
}

int rundir_valid_id(const char *id) {
  const size_t n = strlen(id);
  if (n == 0 || n > 36) return 0;
  for (size_t i = 0; i < n; i++)
    if (!isalnum((unsigned char)id[i]) && !strchr("._-", id[i])) return 0;
  return 1;
}

/* A random (version 4) UUID from /dev/urandom; the clock and the process id if it cannot be
   read. */
static void random_uuid(char *id, size_t n) {
  unsigned char b[16];
  FILE *f = fopen("/dev/urandom", "rb");
  const size_t got = f ? fread(b, 1, sizeof b, f) : 0;
  if (f) fclose(f);
  if (got != sizeof b) {
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t x = (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
    x ^= (uint64_t)getpid() << 32;
    for (int i = 0; i < 16; i++) { /* splitmix64 */
      uint64_t z = (x += 0x9e3779b97f4a7c15u);
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
      b[i] = (unsigned char)(z ^ (z >> 31));
    }
  }
  b[6] = (unsigned char)((b[6] & 0x0f) | 0x40), b[8] = (unsigned char)((b[8] & 0x3f) | 0x80);
  snprintf(id, n, "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", b[0],
           b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12], b[13], b[14],
           b[15]);
}

static int write_id(const char *dir, const char *id) {
  char path[4096], tmp[4200];
  snprintf(path, sizeof path, "%s/run_id", dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE *f = fopen(tmp, "w");
  if (!f || fprintf(f, "%s\n", id) < 0 || fclose(f) || rename(tmp, path)) {
    error_input("%s: cannot write the run identity (%s)", path, strerror(errno));
    remove(tmp);
    return CHANSPH_ERR;
  }
  return CHANSPH_OK;
}

int rundir_new_id(const char *dir, char *id) {
  int rc = CHANSPH_OK;
  if (rank0()) {
    const char *env = getenv("CHANSPH_RUN_ID");
    if (env && !rundir_valid_id(env)) {
      error_input("CHANSPH_RUN_ID=%s: a run identity is 1 to 36 letters, digits, '.', '_' or '-'",
                  env);
      rc = CHANSPH_ERR;
    } else {
      if (env)
        snprintf(id, CKPT_RUN_ID_MAX, "%s", env);
      else
        random_uuid(id, CKPT_RUN_ID_MAX);
      rc = write_id(dir, id);
    }
  }
  rc = agree(rc, id, CKPT_RUN_ID_MAX);
  if (rc == CHANSPH_OK) ckpt_set_run_id(id);
  return rc;
}

int rundir_read_id(const char *dir, char *id) {
  int rc = 1;
  id[0] = '\0';
  if (rank0()) {
    char path[4096], line[128] = "";
    snprintf(path, sizeof path, "%s/run_id", dir);
    FILE *f = fopen(path, "r");
    if (f && fgets(line, sizeof line, f)) {
      line[strcspn(line, "\r\n")] = '\0';
      if (rundir_valid_id(line))
        snprintf(id, CKPT_RUN_ID_MAX, "%s", line), rc = 0;
      else
        warn("%s: not a run identity ('%s'); ignored", path, line);
    }
    if (f) fclose(f);
  }
  return agree(rc, id, CKPT_RUN_ID_MAX);
}

int rundir_set_id(const char *dir, const char *id) {
  const int rc = agree(rank0() ? write_id(dir, id) : CHANSPH_OK, NULL, 0);
  if (rc == CHANSPH_OK) ckpt_set_run_id(id);
  return rc;
}

char *rundir_history(const char *dir, const char *cmdline, int fresh, int ranks, int threads) {
  if (!rank0()) return NULL;
  char path[4096], tmp[4200], stamp[32], entry[8192];
  const time_t now = time(NULL);
  struct tm utc;
  gmtime_r(&now, &utc);
  strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", &utc);
  snprintf(entry, sizeof entry, "%s: %s (%d MPI rank%s x %d thread%s)", stamp,
           cmdline ? cmdline : "chansph", ranks, ranks == 1 ? "" : "s", threads,
           threads == 1 ? "" : "s");
  snprintf(path, sizeof path, "%s/history", dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  char *old = NULL;
  size_t n = 0;
  FILE *f = fresh ? NULL : fopen(path, "r");
  if (f) {
    if (fseek(f, 0, SEEK_END) == 0 && (n = (size_t)ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (old = mem_alloc(1, n + 1, "run directory")))
      n = fread(old, 1, n, f), old[n] = '\0';
    fclose(f);
  }
  while (old && n > 0 && old[n - 1] == '\n') old[--n] = '\0';
  const size_t len = strlen(entry) + (old ? n + 1 : 0) + 1;
  char *text = mem_alloc(1, len, "run directory");
  snprintf(text, len, "%s%s%s", entry, old && n ? "\n" : "", old && n ? old : "");
  free(old);
  FILE *w = fopen(tmp, "w");
  if (!w || fprintf(w, "%s\n", text) < 0 || fclose(w) || rename(tmp, path)) {
    warn("%s: cannot record the command in the history (%s)", path, strerror(errno));
    remove(tmp);
  }
  return text;
}

/* The lock: rank 0 holds a write lock (fcntl) on DIR/.lock until the process ends. */
static int lock_fd = -1;

/* The run directory and lock file this process holds (rank 0), to notice a directory deleted
   and recreated, or moved away, while the run works in it (rundir_check). */
static struct {
  int known;           /*!< 1 once the directory is held */
  dev_t dev, lock_dev; /*!< devices of DIR and DIR/.lock */
  ino_t ino, lock_ino; /*!< inodes of DIR and DIR/.lock (lock_fd < 0: not compared) */
} held;

/* Remember which directory (and lock file) the process holds. */
static void hold(const char *dir, int fd) {
  struct stat d, l;
  if (stat(dir, &d)) return;
  held.dev = d.st_dev, held.ino = d.st_ino, held.known = 1;
  if (fd >= 0 && !fstat(fd, &l)) held.lock_dev = l.st_dev, held.lock_ino = l.st_ino;
}

static int take_lock(const char *dir, int create) {
  struct stat st;
  if (stat(dir, &st)) {
    if (!create) return CHANSPH_OK; /* nothing there to protect; resume says what is missing */
    char buf[2048];
    snprintf(buf, sizeof buf, "%s", dir);
    for (char *p = buf + 1; *p; p++)
      if (*p == '/') {
        *p = '\0';
        if (mkdir(buf, 0777) && errno != EEXIST) break;
        *p = '/';
      }
    if (mkdir(buf, 0777) && errno != EEXIST) {
      error_input("%s: cannot create the output directory (%s)", dir, strerror(errno));
      return CHANSPH_ERR;
    }
  }
  char path[4096];
  snprintf(path, sizeof path, "%s/.lock", dir);
  const int fd = open(path, O_RDWR | O_CREAT, 0644);
  if (fd < 0) {
    error_input("%s: cannot open the lock file of the run directory (%s)", path, strerror(errno));
    return CHANSPH_ERR;
  }
  struct flock fl = {.l_type = F_WRLCK, .l_whence = SEEK_SET, .l_start = 0, .l_len = 0};
  if (fcntl(fd, F_SETLK, &fl) == 0) {
    char pid[32];
    const int n = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
    if (ftruncate(fd, 0) == 0 && write(fd, pid, (size_t)n) != n) {
      /* the pid is for people only */
    }
    lock_fd = fd;
    hold(dir, fd);
    return CHANSPH_OK;
  }
  const int e = errno;
  if (e == EACCES || e == EAGAIN) {
    struct flock who = {.l_type = F_WRLCK, .l_whence = SEEK_SET, .l_start = 0, .l_len = 0};
    const long pid = fcntl(fd, F_GETLK, &who) == 0 && who.l_type != F_UNLCK ? (long)who.l_pid : 0;
    close(fd);
    char by[64] = "";
    if (pid > 0) snprintf(by, sizeof by, " (process %ld)", pid);
    error_input(
        "%s is in use by another chansph run or resume%s holding %s; two processes in one run "
        "directory would both write checkpoints and stats.nc: wait for it to end, or choose "
        "another --out DIR",
        dir, by, path);
    return CHANSPH_ERR;
  }
  close(fd); /* a file system without locks: go on, and say so */
  warn("%s: cannot lock the run directory (%s); make sure no other process uses it", path,
       strerror(e));
  hold(dir, -1);
  return CHANSPH_OK;
}

int rundir_is_held(const char *dir) {
  if (!held.known) return 1;
  char path[4096];
  snprintf(path, sizeof path, "%s/.lock", dir);
  struct stat d, l;
  const int same_dir = !stat(dir, &d) && d.st_dev == held.dev && d.st_ino == held.ino;
  return same_dir && (lock_fd < 0 ||
                      (!stat(path, &l) && l.st_dev == held.lock_dev && l.st_ino == held.lock_ino));
}

/* Rank 0: whether DIR (and DIR/.lock) are still the ones this process holds, or a message. */
static int still_held(const char *dir) {
  if (rundir_is_held(dir)) return CHANSPH_OK;
  error_input(
      "%s is no longer the run directory this process locked (deleted, moved or replaced "
      "while the run was working; another run may use it now): stopping without writing "
      "anything more",
      dir);
  return CHANSPH_ERR;
}

int rundir_check(const char *dir) {
  return agree(rank0() ? still_held(dir) : CHANSPH_OK, NULL, 0);
}

int rundir_lock(const char *dir, int create) {
  return agree(rank0() ? take_lock(dir, create) : CHANSPH_OK, NULL, 0);
}
