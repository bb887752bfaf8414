/** @file motion.h
 * Moving instances: the transform of an instance at a time across the
 * shutter (scene.h's fr_inst_motion).
 *
 * Render path: only + - * / sqrt and fmath.h's sine, so the same bits on
 * every host.  The compiler uses the same function to bound an instance
 * over the shutter, so its bounds hold what the renderer places.
 */
#ifndef FRANJA_MOTION_H
#define FRANJA_MOTION_H

#include "scene.h"

/** Below this angle between the two quaternions (radians in 4-space) the
 * rotation blends linearly and is renormalised (nlerp): there it differs
 * from the slerp by under 1e-7 of a radian, and sin(angle) would lose
 * digits. */
#define MOTION_SLERP_MIN 1e-3f

/** The transform of moving instance m at time u in [0, 1] (0: shutter
 * open): xf maps object to world (row-major 3x4, as fr_instance.xf), inv
 * is its inverse (by cofactors; not finite when the blended stretch is
 * singular, which the compiler refuses).  Either may be NULL. */
void motion_at(const fr_inst_motion *m, float u, float xf[3][4], float inv[3][4]);

/** A moving instance's transform at one time (motion_at's xf and inv). */
typedef struct {
    float xf[3][4], inv[3][4];
} motion_pose;

/** motion_at's transform and inverse of moving instance m (slot: its
 * index in the scene's inst_motions) at time u, through a small cache of
 * the calling thread: every ray of a camera sample has the sample's time,
 * so the rays of one sample blend each instance they meet once.  A cached
 * pose is used only when the motion's bytes and u's bits are those it was
 * made from, so the result is bit for bit motion_at's, whatever scene m
 * belongs to.  The pose returned is the thread's own and holds until the
 * thread's next call. */
const motion_pose *motion_at_cached(const fr_inst_motion *m, uint32_t slot, float u);

#endif
