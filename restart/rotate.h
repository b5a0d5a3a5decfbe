/**
 * @file rotate.h
 * @brief Internal to restart/: names and listing of the checkpoint files of a run directory.
 */
#ifndef CHANSPH_ROTATE_H
#define CHANSPH_ROTATE_H

#include <stddef.h>

/** @brief DIR/checkpoints/ckpt_<step, 10 digits>.h5 */
void rotate_path(char *buf, size_t n, const char *dir, long step);

/**
 * @brief Steps of the checkpoint files in DIR/checkpoints, ascending.
 * @param[in] dir run directory
 * @param[out] steps malloc'd array (free it; NULL if none)
 * @return number of files
 */
int rotate_list(const char *dir, long **steps);

/** @brief Remove temporary files of interrupted writes (never valid); returns how many. */
int rotate_remove_tmp(const char *dir);

#endif
