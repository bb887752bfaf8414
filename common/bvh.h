/** @file bvh.h
 * The bounding volume hierarchy as a binary scene stores it, and the check
 * that a loaded one is sound.
 *
 * An 8-wide BVH (fr_bvh_node, scene.h): nodes in depth-first order
 * (children after their parent), leaves as blocks of four primitives with
 * their triangle vertices copied in (fr_bvh_leaf); a primitive cut by
 * spatial splits is in several leaves.  It is built at compile time
 * (bvh_build.h) and walked by trace.c; this module is what a worker needs
 * to trust the tree it maps.
 */
#ifndef FRANJA_BVH_H
#define FRANJA_BVH_H

#include "error.h"
#include "scene.h"

/** Check the BVH arrays of a scene whose other sections are already valid:
 * every child index, leaf range and lane, that the nodes form one tree no
 * deeper than FR_BVH_MAX_DEPTH, that every lane names a valid primitive
 * and every primitive sits in at least one lane, that a triangle's lane
 * holds exact copies of its vertices, finite boxes and vertices.  `base` is the start of the
 * binary scene the arrays point into, so messages give byte offsets.
 * Returns 0, or -1 with *err set. */
int bvh_validate(const fr_scene *s, const void *base, fr_error *err);

#endif
