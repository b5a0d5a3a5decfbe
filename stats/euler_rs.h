/**
 * @file euler_rs.h
 * @brief The Reynolds-stress budgets of the Eulerian engine's bins, an identity of the discrete
 *        scheme (docs/theory.md, "Reynolds-stress budgets"). Internal to the engine (euler.c,
 *        euler_nc.c); the finished profiles are the EP_RSB rows of euler.h.
 *
 * The step u^{n+1} = u^n + dt A (A: every part of the acceleration and the body force) changes
 * m u_i u_j by exactly dt m (ub_i A_j + ub_j A_i), ub = u^{n+1} - dt A / 2 the midpoint
 * velocity. The fluctuation of a particle at y is u - U(y), U(y) the local mean velocity:
 * linear between the bin centres (nodes), extrapolated linearly from the two end nodes towards
 * a wall, constant beyond the last node of a folded profile. A bin's E = sum phi_b m (u_i -
 * U_i)(u_j - U_j) (phi_b: the bin's hat function) then holds no spread of the mean across the bin.
 * Per bin and sampled step the engine sums, for each part k of A (pressure, viscous, model, wall
 * pair parts and the body force), m ub_i A^k_j and the node-weighted m A^k_j psi_c (psi_c: the
 * weight of node c = b - 1, b, b + 1 in U(y)), at the particles' positions before the step, and the
 * quantities q = m (1, u_i u_j, u_i psi_c, psi_c psi_d) of the new state once by the new and
 * once by the old positions: their difference is what the step's displacements carried into
 * the bin. E then changes by exactly the sum of the parts' terms dt sum phi_b m ((ub_i - U_i)
 * A^k_j + (ub_j - U_j) A^k_i) and the transfer of the displacements; the node values of U
 * enter only at the end (euler_rs_profiles), so any range of windows can be re-averaged. The
 * budget's bins are hat functions on the bin centres (cloud in cell, euler_rs.c), so that the
 * transfer of one step is a smooth function of the positions. Sampled every step the budget
 * closes to round-off; sampled every N steps each sample stands for the time since the one
 * before.
 */
#ifndef CHANSPH_EULER_RS_H
#define CHANSPH_EULER_RS_H

#include <stddef.h>

#include "contract.h"
#include "euler.h"

/** Parts of the acceleration in the budget: the snapshot's STATS_PARTS, then the body force,
    then the configurational part of the pressure part (the pressure noise: inside the
    pressure part, reported apart, not a term of the closure). */
enum { RS_BODY = STATS_PARTS, RS_NOISE, RS_NPART };

/** Velocity products of the sums: ub_x A_x, ub_y A_y, ub_z A_z, ub_x A_y, ub_y A_x. */
enum { RS_XX, RS_YY, RS_ZZ, RS_XY, RS_YX, RS_NPROD };

/** Nodes of the local mean seen from bin b (b - 1, b, b + 1), and their products
    psi_c psi_d, c <= d adjacent or equal: (b-1, b-1), (b-1, b), (b, b), (b, b+1), (b+1, b+1). */
enum { RS_NODE = 3, RS_NPAIR = 5 };

/** The quantities carried by the particles: m, m uu, m vv, m ww, m uv, m u_i psi_c
    [node][component], m psi_c psi_d [pair]. */
enum {
  RQ_M,
  RQ_UU,
  RQ_VV,
  RQ_WW,
  RQ_UV,
  RQ_MU,
  RQ_PP = RQ_MU + 3 * RS_NODE,
  RS_NQ = RQ_PP + RS_NPAIR
};

/** Per-(column, bin) partial of one snapshot (RSP_LEN values; euler.c adds it to its
    per-column records): the product sums m ub_i A^k_j [part][product], the node-weighted part
    sums m A^k_j psi_c [part][node][component], the quantities by the new and by the old
    positions. */
enum {
  RSP_S = 0,
  RSP_F = RSP_S + RS_NPART * RS_NPROD,
  RSP_NEW = RSP_F + RS_NPART * RS_NODE * 3,
  RSP_OLD = RSP_NEW + RS_NQ,
  RSP_LEN = RSP_OLD + RS_NQ
};

/** A block of time-weighted sums (tau: time since the previous sampled step): samples, sum of
    tau, of tau M, of tau m ub_i A^k_j, of tau m A^k_j psi_c, and of tau / dt times the
    quantities the displacements carried in. */
enum {
  RB_N,
  RB_TAU,
  RB_MASS,
  RB_S,
  RB_F = RB_S + RS_NPART * RS_NPROD,
  RB_K = RB_F + RS_NPART * RS_NODE * 3,
  RB_LEN = RB_K + RS_NQ
};

/** Per window and bin (format 1.7): the block of all the window's samples, the block of its
    first sample alone (a range leaves its first sample's terms out), the quantities of the
    first and the last sample's state and their times. */
enum {
  RW_SUM = 0,
  RW_FIRST = RB_LEN,
  RW_Q_FIRST = 2 * RB_LEN,
  RW_Q_LAST = RW_Q_FIRST + RS_NQ,
  RW_T_FIRST = RW_Q_LAST + RS_NQ,
  RW_T_LAST,
  RW_LEN
};

/** @brief The share of a particle at y in the upper (side 1) or lower (side 0) half of the
           channel: all of it, or half within 1e-9 delta of the centre (euler.c). */
double euler_side_weight(double y, double delta, int side);

/** @brief Derivative of f at point i from its neighbours with ok set (3-point Lagrange on
           uneven points; euler.c). */
double euler_deriv(const double *x, const double *f, const int *ok, int n, int i);

/** @brief Name of field k of the window records (for the raw records of stats.nc). */
const char *euler_rs_field_name(int k);

/**
 * @brief Add particle a of the snapshot (s->sx and s->dt > 0) to the partials of its column:
 *        the RSP record of bin b is P + b stride + offset.
 * @param[in] yf position before the step (the forces' and the old membership's)
 */
void euler_rs_add(const struct euler_config *c, const struct stats_snapshot *s, size_t a, double yf,
                  double *P, size_t stride, size_t offset);

/**
 * @brief One snapshot's merged partials (the RSP record of bin b at snap + b stride + offset)
 *        into the window row's RW records; t_prev: the time of the previous sample with the
 *        budget (NaN: none; the sample then stands for its own step dt).
 */
void euler_rs_snapshot(const struct euler_config *c, const double *snap, size_t stride,
                       size_t offset, double t, double dt, double t_prev, double *row);

/** @brief Time of the last sample with the budget in rows 0..last (NaN: none). */
double euler_rs_last_time(const struct euler_config *c, const double *rsb, size_t last);

/**
 * @brief The budget profiles (EP_RSB ..) of rows [r0, r1) of rsb, with the means and stresses
 *        of res already filled; returns 1 if any bin has a budget (else all NaN).
 */
int euler_rs_profiles(const struct euler_config *c, const double *rsb, const int *complete,
                      size_t r0, size_t r1, struct euler_result *res);

#endif
