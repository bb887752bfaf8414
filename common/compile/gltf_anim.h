/** @file gltf_anim.h
 * glTF animations at compile time: every channel of every animation of a
 * document evaluated at one time, giving the animated nodes their
 * translation, rotation and scale before the scene is built (gltf_scene.h
 * poses the nodes with them, so cameras, lights and meshes follow).
 *
 * Interpolation as glTF 2.0 defines it: STEP holds a key's value until the
 * next key; LINEAR blends translations and scales linearly and rotations by
 * spherical linear interpolation along the shorter arc (the quaternion
 * normalised); CUBICSPLINE is the cubic Hermite spline through the keys with
 * the file's in- and out-tangents scaled by the interval's length
 * (rotations normalised).  Before the first key a channel holds its first
 * value, after the last its last.  A time equal to a key's gives that key's
 * value exactly as stored (the scene's reader normalises a rotation as it
 * does a node's own), so a frame on a key poses the node as a static file
 * with those values would.
 *
 * Untrusted input: every sampler and node index, accessor type, count and
 * time array is checked (times finite and strictly increasing; outputs
 * finite, one per key, three per key for CUBICSPLINE; morph weights as
 * many per key as the elements divide into, at most GANIM_MAX_WEIGHTS,
 * matched against the mesh's targets by the scene's reader); errors name
 * the file and the JSON pointer.  When two channels animate the
 * same property of a node, the first (in the file's order) wins, with a
 * warning.  Compile time only; + - * / and sqrt alone, as in the render
 * path, so that a pose is the same bits on every host.
 */
#ifndef FRANJA_GLTF_ANIM_H
#define FRANJA_GLTF_ANIM_H

#include <stdint.h>

#include "compile/gltf_doc.h"
#include "compile/scene_hooks.h"

/** Which properties of a node the animations set. */
enum { GANIM_T = 1, GANIM_R = 2, GANIM_S = 4, GANIM_W = 8 };

/** Most morph targets (weights) a mesh may have. */
#define GANIM_MAX_WEIGHTS 64

/** A node's animated properties (those flagged in `set`). */
typedef struct {
    unsigned set;              /**< GANIM_T | GANIM_R | GANIM_S | GANIM_W */
    double t[3];               /**< translation */
    double r[4];               /**< rotation quaternion x y z w (a key's as stored, else unit length) */
    double s[3];               /**< scale */
    double *w;                 /**< morph target weights, n_weights of them (malloc'd; NULL without) */
    uint32_t n_weights;
    uint32_t anim, channel;    /**< where its first animated property comes from (messages) */
} ganim_node;

/** The pose of a document's nodes at one time. */
typedef struct {
    ganim_node *node;          /**< one per node of the document (malloc'd), NULL when it has none */
    uint32_t n;                /**< nodes */
    uint32_t channels;         /**< channels evaluated */
} ganim_pose;

/** The default frame rate, frames per second (Blender's). */
#define GANIM_FPS 24.0

/** The time (seconds) of frame `frame` at `fps` frames per second: frame /
 * fps, the rule Blender's glTF exporter writes key times by (frame f at f
 * / fps, frame 0 at time 0), rounded to single precision as the file
 * stores times, so that a frame lands exactly on its exported key. */
double ganim_frame_time(double frame, double fps);

/** ganim_frame_time of frame `frame` (hooks->frame, or a shutter's end
 * around it) at the hooks' fps (0: GANIM_FPS). */
double ganim_hooks_time(const scene_hooks *h, double frame);

/** 1 when the document has a non-empty `animations` array. */
int ganim_present(const gltf_doc *d);

/** Evaluates every animation of d at time t (seconds) into *p (freed with
 * ganim_free, also after a failure).  Returns 0, or -1 with err naming the
 * file and JSON pointer at fault.  Warnings go through gdoc_warn. */
int ganim_eval(gltf_doc *d, double t, ganim_pose *p, fr_error *err);

void ganim_free(ganim_pose *p);

#endif
