/** @file builder_motion.h
 * Instances that move while the shutter is open, at compile time.
 *
 * A reader places a mesh with bld_instance() by its transform at shutter
 * open, then gives the transform at shutter close with
 * bld_instance_motion(): the instance then moves between the two as
 * scene.h's fr_inst_motion says (translation and stretch blended
 * linearly, rotation along the shortest arc), and the scene's motion
 * flags say instances move, so every sample draws a time.
 */
#ifndef FRANJA_BUILDER_MOTION_H
#define FRANJA_BUILDER_MOTION_H

#include "compile/builder.h"

/** Instance `inst` (an index into b->instances, its xf the pose at
 * shutter open) reaches transform `close` (row-major 3x4, as
 * bld_instance's xf) at shutter close.  Both transforms are split into
 * translation, rotation and stretch (polar decomposition, in double); a
 * close transform equal to the open one adds nothing.  Returns 0, or -1
 * with *err set when `close` is not finite, or the blend between the two
 * would pass through a flat (singular) transform, or on memory
 * exhaustion. */
int bld_instance_motion(fr_builder *b, uint32_t inst, const float close[3][4], fr_error *err);

/** Grows lo..hi to bound the object box blo..bhi moved by m over the
 * whole shutter: the box placed by motion_at (motion.h) at
 * BLD_MOTION_SAMPLES + 1 evenly spread times, then widened on every axis
 * by half the gap between two times times a bound on how fast any point
 * of the box moves, |t1 - t0| + (2 angle |S| + |S1 - S0|) r (|S| the
 * larger Frobenius norm of the two stretches, r the distance from the
 * object's origin to the box's farthest corner): between two sampled
 * times a point strays at most that far from where it was at the nearer
 * one. */
void bld_motion_bounds(const fr_inst_motion *m, vec3 blo, vec3 bhi, vec3 *lo, vec3 *hi);

/** Grows the box lo..hi to hold the box blo..bhi placed by xf (its eight
 * corners, rounded: callers widen it). */
void bld_box_placed(const float xf[3][4], vec3 blo, vec3 bhi, vec3 *lo, vec3 *hi);

/** Times at which bld_motion_bounds places the box (plus one). */
#define BLD_MOTION_SAMPLES 32

#endif
