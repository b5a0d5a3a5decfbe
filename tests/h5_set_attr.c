/**
 * @file h5_set_attr.c
 * @brief Test helper: overwrite an integer attribute of the root group of an HDF5 file, e.g.
 *        to make a checkpoint look like one of a future format version.
 *        usage: h5_set_attr FILE NAME VALUE
 */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: h5_set_attr FILE NAME VALUE\n");
    return 1;
  }
  const int value = atoi(argv[3]);
  const hid_t f = H5Fopen(argv[1], H5F_ACC_RDWR, H5P_DEFAULT);
  if (f < 0) return 1;
  const hid_t a = H5Aopen(f, argv[2], H5P_DEFAULT);
  const int rc = a < 0 || H5Awrite(a, H5T_NATIVE_INT, &value) < 0;
  if (a >= 0) H5Aclose(a);
  H5Fclose(f);
  if (!rc) printf("%s: %s = %d\n", argv[1], argv[2], value);
  return rc;
}
