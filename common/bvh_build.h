/** @file bvh_build.h
 * Building the BVH of a scene at compile time (the layout it produces is
 * described in bvh.h and scene.h).
 *
 * A binary tree first: binned surface-area-heuristic splits (32 bins per
 * axis on reference centroids, O(n log n); spans of at most 64 references
 * sorted and cut at the best of every place) down to leaves of at most
 * four references; below the depth where the tree could exceed
 * FR_BVH_MAX_DEPTH it halves ranges instead.  Where the two sides of the
 * best such split overlap, it also tries spatial splits (a plane across
 * the range's longest axis, triangles crossing it cut in two, each side
 * bounding its part only), up to one extra reference per primitive in all;
 * a triangle then sits in several leaves.  The binary tree is then
 * collapsed to the 8-wide one at the least SAH cost (dynamic programming
 * over each subtree: which descendants become a node's up to eight
 * children, which subtrees become leaves of up to four blocks, their
 * references packed into full blocks).  It is single-threaded and uses
 * only exactly rounded float operations, so a scene gives the same bytes
 * on every machine.
 */
#ifndef FRANJA_BVH_BUILD_H
#define FRANJA_BVH_BUILD_H

#include "builder.h"

/** Build the BVH over b->prims, reordering b->prims into leaf order, and
 * append its nodes to `nodes` (fr_array of fr_bvh_node) and its leaf blocks
 * to `leaves` (fr_array of fr_bvh_leaf), both owned by the caller.  An empty
 * scene gives neither.  With `placed` not NULL, *placed gets (malloc'd, the
 * caller frees it; NULL for an empty scene) where each primitive went:
 * (*placed)[i] is the new index of the primitive that was b->prims[i].
 * Returns 0, or -1 with *err set on memory exhaustion or a primitive with
 * non-finite bounds (*placed untouched). */
int bvh_build(fr_builder *b, fr_array *nodes, fr_array *leaves, uint32_t **placed, fr_error *err);

/** Bounding box of prim `i` of the builder, into *lo and *hi. */
void bvh_prim_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi);

#endif
