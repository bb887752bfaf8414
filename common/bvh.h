/* bvh.h -- the bounding volume hierarchy over a scene's bounded primitives.
 *
 * Built once when a scene is compiled and stored in the binary scene as an
 * array of fr_bvh_node (scene.h): depth-first order, the first child of an
 * interior node right after it, leaves holding contiguous ranges of the
 * prims array.  Traversal lives in trace.c. */
#ifndef FRANJA_BVH_H
#define FRANJA_BVH_H

#include "builder.h"

/* Build the BVH over b->prims, reordering b->prims into leaf order, and
 * append its nodes to `nodes` (an fr_array of fr_bvh_node, owned by the
 * caller).  An empty scene gives no nodes. */
int bvh_build(fr_builder *b, fr_array *nodes, fr_error *err);

/* Bounding box of prim `i` of the builder. */
void bvh_prim_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi);

#define BVH_MAX_DEPTH 64

#endif
