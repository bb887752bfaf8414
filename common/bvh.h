/* bvh.h -- the bounding volume hierarchy over a scene's bounded primitives.
 *
 * An 8-wide BVH (fr_bvh_node, scene.h) built once when a scene is compiled
 * and stored in the binary scene: nodes in depth-first order (children
 * after their parent), leaves as blocks of four primitives with their
 * triangle vertices copied in (fr_bvh_leaf), primitives reordered so each
 * leaf's lanes are consecutive.  Traversal lives in trace.c.
 *
 * The build is a binned surface-area-heuristic build (32 bins per axis on
 * primitive centroids, O(n log n)): a node takes the child range with the
 * largest surface area and splits it at the cheapest bin boundary until it
 * has eight children or the SAH prefers leaves.  It is single-threaded and
 * uses only exactly rounded float operations, so a scene gives the same
 * bytes on every machine. */
#ifndef FRANJA_BVH_H
#define FRANJA_BVH_H

#include "builder.h"

/* Deepest node (the root is at depth 1).  Traversal's stack holds at most
 * FR_BVH_WIDTH - 1 entries per level, so BVH_STACK entries always suffice
 * for a tree that bvh_validate() accepted. */
#define BVH_MAX_DEPTH 64
#define BVH_STACK ((FR_BVH_WIDTH - 1) * BVH_MAX_DEPTH + 1)

/* Build the BVH over b->prims, reordering b->prims into leaf order, and
 * append its nodes to `nodes` (fr_array of fr_bvh_node) and its leaf blocks
 * to `leaves` (fr_array of fr_bvh_leaf), both owned by the caller.  An empty
 * scene gives neither.  Fails on memory exhaustion or a primitive with
 * non-finite bounds. */
int bvh_build(fr_builder *b, fr_array *nodes, fr_array *leaves, fr_error *err);

/* Bounding box of prim `i` of the builder. */
void bvh_prim_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi);

/* Check the BVH arrays of a scene whose other sections are already valid:
 * every child index, leaf range and lane, that the nodes form one tree no
 * deeper than BVH_MAX_DEPTH, that every primitive sits in exactly one lane,
 * finite boxes and triangle vertices.  `base` is the start of the binary
 * scene the arrays point into, so messages give byte offsets. */
int bvh_validate(const fr_scene *s, const void *base, fr_error *err);

#endif
