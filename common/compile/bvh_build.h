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
 * a triangle then sits in several leaves.  Reinsertion then moves
 * subtrees of the binary tree (a leaf, or the two children of an inner
 * node taken out) to where the inner nodes' area grows least, found by
 * branch and bound from the root, keeping a move only where the collapse's
 * cost of the whole tree falls: a pass over the twentieth of the nodes
 * that enlarge their parent most, up to three passes while one gains
 * 1 % of the cost (bvh_reinsert.h).  The binary tree is then
 * collapsed to the 8-wide one at the least SAH cost (dynamic programming
 * over each subtree: which descendants become a node's up to eight
 * children, which subtrees become leaves of up to four blocks, their
 * references packed into full blocks; the tree and its cost model are in
 * bvh2.h).  It is single-threaded and uses
 * only exactly rounded float operations, so a scene gives the same bytes
 * on every machine.
 */
#ifndef FRANJA_BVH_BUILD_H
#define FRANJA_BVH_BUILD_H

#include "compile/builder.h"

/** Build the BVH over b->prims, reordering b->prims into leaf order, and
 * append its nodes to `nodes` (fr_array of fr_bvh_node) and its leaf blocks
 * to `leaves` (fr_array of fr_bvh_leaf), both owned by the caller.  An empty
 * scene gives neither.  With `placed` not NULL, *placed gets (malloc'd, the
 * caller frees it; NULL for an empty scene) where each primitive went:
 * (*placed)[i] is the new index of the primitive that was b->prims[i].
 * Returns 0, or -1 with *err set on memory exhaustion or a primitive with
 * non-finite bounds (*placed untouched). */
int bvh_build(fr_builder *b, fr_array *nodes, fr_array *leaves, uint32_t **placed, fr_error *err);

/** What a build does beyond the top-down split, for tests and benchmarks
 * that compare trees. */
typedef struct {
    int reinsert;              /**< 1: reinsertion passes over the binary tree (bvh_build's choice); 0: none */
} bvh_options;

/** bvh_build with the choices in *opt (NULL: bvh_build's). */
int bvh_build_with(fr_builder *b, const bvh_options *opt, fr_array *nodes, fr_array *leaves, uint32_t **placed,
                   fr_error *err);

/** The SAH cost of a built 8-wide tree in the builder's own cost model:
 * per ray through the root's box, the expected node tests, plus half a
 * test for every slot entered, plus the leaf blocks tested (areas relative
 * to the root box's, rays not stopped at hits), in units of one leaf block
 * test.  For comparing trees of the same scene; 0 for an empty tree or a
 * flat root box.  Children are followed only forward and to
 * FR_BVH_MAX_DEPTH, so a damaged tree cannot loop. */
double bvh_sah_cost(const fr_bvh_node *nodes, uint32_t n_nodes);

#endif
