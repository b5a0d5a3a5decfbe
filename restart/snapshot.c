/** @file snapshot.c @brief Implementation of snapshot.h. */
#include "snapshot.h"
#include "alloc.h"

#include <dirent.h>
#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ckpt.h"
#include "error.h"
#include "timers.h"

int snapshot_due(const struct sim *S) {
  const double every = S->sc->snap_every;
  if (every <= 0.0 || S->step == 0) return 0;
  return floor(S->t / every) != floor((S->t - S->dt) / every);
}

/* Time attribute of a snapshot file, or NAN. */
static double snap_time(const char *path) {
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  double t = NAN;
  const hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return t;
  const hid_t a = H5Aopen(f, "time", H5P_DEFAULT);
  if (a < 0 || H5Aread(a, H5T_NATIVE_DOUBLE, &t) < 0) t = NAN;
  if (a >= 0) H5Aclose(a);
  H5Fclose(f);
  return t;
}

static int cmp_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static void item(FILE *x, const char *file, const char *ds, size_t n, int cols, const char *type,
                 int prec) {
  fprintf(x,
          "        <DataItem Dimensions=\"%zu%s\" NumberType=\"%s\" Precision=\"%d\" "
          "Format=\"HDF\">%s:/%s</DataItem>\n",
          n, cols == 3 ? " 3" : "", type, prec, file, ds);
}

/* Rewrite DIR/snapshots/particles.xdmf from the snapshot files present. les: the files hold
   the eddy viscosity. */
/** The per-particle scalars of a snapshot after position and velocity: name, units, and the
    particle array (NULL: this run has none, e.g. no eddy viscosity without LES). */
struct snap_scalar {
  const char *name, *units;
  const double *src;
};

static int write_xdmf(const char *sdir, size_t n, const struct snap_scalar *sc, int ns) {
  DIR *d = opendir(sdir);
  if (!d) return -1;
  char **names = NULL;
  size_t nn = 0, cap = 0;
  for (struct dirent *e; (e = readdir(d));) {
    const size_t len = strlen(e->d_name);
    if (strncmp(e->d_name, "snap_", 5) || len < 9 || strcmp(e->d_name + len - 3, ".h5")) continue;
    if (nn == cap) {
      cap = cap ? 2 * cap : 64;
      char **t = mem_realloc(names, cap, sizeof *t, "snapshot list");
      names = t;
    }
    names[nn++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, nn, sizeof *names, cmp_name);
  char path[4200], tmp[4300];
  snprintf(path, sizeof path, "%s/particles.xdmf", sdir);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE *x = fopen(tmp, "w");
  int rc = x ? 0 : -1;
  if (x) {
    fprintf(x,
            "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
            "<Xdmf Version=\"3.0\">\n  <Domain>\n"
            "    <Grid Name=\"particles\" GridType=\"Collection\" "
            "CollectionType=\"Temporal\">\n");
    for (size_t i = 0; i < nn; i++) {
      char file[4400];
      snprintf(file, sizeof file, "%s/%s", sdir, names[i]);
      const double t = snap_time(file);
      if (isnan(t)) continue;
      /* one vertex cell per particle; the connectivity is the id dataset (0 .. n-1, the
         rows in order): ParaView's Xdmf3 readers build no cells without it */
      fprintf(x,
              "      <Grid Name=\"%.*s\" GridType=\"Uniform\">\n"
              "        <Time Value=\"%.17g\"/>\n"
              "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
              "NodesPerElement=\"1\">\n",
              (int)(strlen(names[i]) - 3), names[i], t, n);
      item(x, names[i], "id", n, 1, "Int", 8);
      fprintf(x, "        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n");
      item(x, names[i], "position", n, 3, "Float", 8);
      fprintf(x, "        </Geometry>\n");
      /* velocity, the scalars in their order with id after the first two (the order of
         earlier files), each an attribute of the points */
      for (int k = -1; k <= ns; k++) {
        const int id = k == 2, vec = k == -1, j = k > 2 ? k - 1 : k;
        const char *name = vec ? "velocity" : id ? "id" : sc[j].name;
        fprintf(x, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", name,
                vec ? "Vector" : "Scalar");
        item(x, names[i], name, n, vec ? 3 : 1, id ? "Int" : "Float", 8);
        fprintf(x, "        </Attribute>\n");
      }
      fprintf(x, "      </Grid>\n");
    }
    fprintf(x, "    </Grid>\n  </Domain>\n</Xdmf>\n");
    if (fclose(x) || rename(tmp, path)) rc = -1;
  }
  for (size_t i = 0; i < nn; i++) free(names[i]);
  free(names);
  if (rc) remove(tmp);
  return rc;
}

/* Make the snapshot directory (rank 0); every rank returns the outcome. */
static int snap_dir(const char *sdir, int root) {
  int rc = CHANSPH_OK;
  if (root && mkdir(sdir, 0777) && errno != EEXIST) {
    error_input("%s: cannot create the snapshot directory (%s)", sdir, strerror(errno));
    rc = CHANSPH_ERR;
  }
  CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
  return rc;
}

int snapshot_write(const char *dir, struct sim *S) {
  timer_push("snapshot");
  const struct particles *P = &S->P;
  const size_t n = P->n_fluid;
  const int root = S->dd.rank == 0;
  sim_output_fields(S); /* output.q_criterion */
  /* the scalars this run has (every rank has the same arrays) */
  const struct snap_scalar all[] = {{"pressure", "Pa", P->p},
                                    {"density", "kg/m^3", P->rho},
                                    {"eddy_viscosity", "m^2/s", P->nur},
                                    {"q_criterion", "1/s^2", P->qcrit}};
  enum { NS_MAX = sizeof all / sizeof all[0], NC_MAX = 6 + NS_MAX };
  struct snap_scalar sc[NS_MAX];
  int ns = 0;
  for (int k = 0; k < NS_MAX; k++)
    if (all[k].src) sc[ns++] = all[k];
  /* each rank the rows of its id block, by id; the ranks write the file together (no gather) */
  const int NC = 6 + ns;
  const double *src[NC_MAX] = {P->x, P->y, P->z, P->u, P->v, P->w};
  for (int k = 0; k < ns; k++) src[6 + k] = sc[k].src;
  size_t lo, hi;
  dd_id_block(S->dd.rank, S->dd.size, n, &lo, &hi);
  const size_t nb = hi - lo, m = nb ? nb : 1;
  double *g = mem_alloc(1, (size_t)NC * m * sizeof *g, "particle snapshot");
  dd_block_fluid(&S->dd, P, NC, src, lo, hi, g);
  double *pos = mem_alloc(1, 3 * m * sizeof *pos, "particle snapshot"),
         *vel = mem_alloc(1, 3 * m * sizeof *vel, "particle snapshot");
  int64_t *id = mem_alloc(1, m * sizeof *id, "particle snapshot");
  for (size_t r = 0; r < nb; r++) {
    for (int k = 0; k < 3; k++)
      pos[3 * r + k] = g[k * nb + r], vel[3 * r + k] = g[(3 + k) * nb + r];
    id[r] = (int64_t)(lo + r);
  }
  struct state_list L = {0};
  const size_t d1[1] = {nb}, d2[2] = {nb, 3};
  state_add(&L, "id", STATE_I64, 1, d1, id, NULL);
  state_add(&L, "position", STATE_F64, 2, d2, pos, "m");
  state_add(&L, "velocity", STATE_F64, 2, d2, vel, "m/s");
  for (int k = 0; k < ns; k++)
    state_add(&L, sc[k].name, STATE_F64, 1, d1, g + (size_t)(6 + k) * nb, sc[k].units);
  for (int i = 0; i < L.n; i++) L.f[i].offset = lo, L.f[i].total = n; /* rows lo .. hi-1 */
  char sdir[4096], path[4200], err[2048];
  snprintf(sdir, sizeof sdir, "%s/snapshots", dir);
  snprintf(path, sizeof path, "%s/snap_%010ld.h5", sdir, S->step);
  int rc = snap_dir(sdir, root);
  if (!rc &&
      ckpt_write_fields_all(path, "chansph-snapshot", &L, NULL, S->step, S->t, err, sizeof err)) {
    if (root) error_input("%s", err);
    rc = CHANSPH_ERR;
  }
  if (!rc && root && write_xdmf(sdir, n, sc, ns)) {
    error_input("%s/particles.xdmf: cannot write (%s)", sdir, strerror(errno));
    rc = CHANSPH_ERR;
  }
  state_free(&L);
  free(pos), free(vel), free(id), free(g);
  CHECK_MPI(MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD));
  timer_pop();
  return rc;
}
