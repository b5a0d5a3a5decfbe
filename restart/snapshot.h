/**
 * @file snapshot.h
 * @brief Particle snapshots for visualisation: DIR/snapshots/snap_<step>.h5 (fluid particles
 *        sorted by id: position, velocity, pressure, density) and DIR/snapshots/particles.xdmf,
 *        a temporal collection that ParaView opens (docs/formats.md). Separate from checkpoints.
 */
#ifndef CHANSPH_SNAPSHOT_H
#define CHANSPH_SNAPSHOT_H

#include "sim.h"

/**
 * @brief Is a snapshot due after this step? True when the step crossed a multiple of
 *        snapshots.every: a function of t and dt only, so a resumed run writes the same ones.
 */
int snapshot_due(const struct sim *S);

/**
 * @brief Write the snapshot of the current step atomically and rewrite the XDMF index. Every
 *        rank sends its fluid particles to the owners of their id blocks (dd_block_fluid) and
 *        the ranks write the file together (ckpt_write_fields_all), each its block; rank 0 then
 *        rewrites the index. Collective.
 * @param[in] dir run directory
 * @param[in,out] S simulation (with output.q_criterion the Q criterion is computed first)
 * @return CHANSPH_OK, or CHANSPH_ERR with a message naming the file
 */
int snapshot_write(const char *dir, struct sim *S);

#endif
