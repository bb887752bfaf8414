/** @file bvh2.h
 * The binary tree that the BVH build (bvh_build.h) makes first, before it
 * collapses it to the 8-wide tree a scene stores, and the cost model of
 * that collapse.  For the build's modules only.
 *
 * Costs are in units of one leaf block test (four triangles); a node test
 * (eight boxes) costs about the same, BVH2_TRAV_COST.  Every slot of a
 * node a ray enters (a leaf or a child node) is also charged
 * BVH2_SLOT_COST: it adds a box tested together with the others and one
 * more leaf or subtree to visit.  (Charged nothing, the collapse cuts
 * sheets of long overlapping slivers into many small leaves that cost
 * more.)  A subtree becomes a leaf of at most BVH2_LEAF_MAX references
 * (four blocks); binary leaves hold at most BVH2_LEAF_MIN (one block).
 * Areas and costs use only exactly rounded float operations, so they are
 * the same on every machine.
 */
#ifndef FRANJA_BVH2_H
#define FRANJA_BVH2_H

#include <math.h>
#include <stdint.h>

#include "scene.h"
#include "simd4.h"

enum { BVH2_LEAF_MIN = 4, BVH2_LEAF_MAX = 16 };
/** bvh2_node.kinds: triangles, other primitives (a leaf holds one kind). */
enum { BVH2_TRIS = 1, BVH2_SHAPES = 2 };
#define BVH2_TRAV_COST 1.0f
#define BVH2_SLOT_COST 0.5f

/** An axis-aligned box: lower and upper corners in lanes 0-2 (lane 3
 * unused, kept 0). */
typedef struct { f4 lo, hi; } bvh2_box;

/** The empty box (+inf below, -inf above): growing it by b gives b. */
static inline bvh2_box bvh2_box_empty(void) { return (bvh2_box){f4_set1(INFINITY), f4_set1(-INFINITY)}; }
/** Grow *a to hold b. */
static inline void bvh2_box_grow(bvh2_box *a, bvh2_box b)
{
    a->lo = f4_min_num(b.lo, a->lo);
    a->hi = f4_max_num(b.hi, a->hi);
}
/** Grow *a to hold point p. */
static inline void bvh2_box_add(bvh2_box *a, f4 p)
{
    a->lo = f4_min_num(p, a->lo);
    a->hi = f4_max_num(p, a->hi);
}
/** Half the surface area of b: the SAH only compares areas. */
static inline float bvh2_area(bvh2_box b)
{
    f4 d = b.hi - b.lo;
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}
/** Leaf blocks that n references fill. */
static inline float bvh2_blocks(uint32_t n) { return (float)((n + 3) / 4); }

/** A node of the binary tree, kept in one array (children by index), with
 * the collapse's cost of its subtree: cost[j-1] is the least SAH cost of
 * the subtree given as at most j slots of a wide node, each slot a leaf
 * (area times its blocks) or a wide node (area times BVH2_TRAV_COST plus
 * the cost of its own up to eight slots), each slot also charged its area
 * times BVH2_SLOT_COST. */
typedef struct {
    bvh2_box box;
    uint32_t kid[2];           /**< children, or a leaf's references [kid[0], kid[1]) */
    uint32_t refs;             /**< references in the subtree */
    uint8_t is_leaf;
    uint8_t kinds;             /**< BVH2_TRIS and BVH2_SHAPES: what the subtree holds */
    uint8_t as_leaf;           /**< as one slot: 1 a leaf, 0 a wide node */
    uint8_t wide;              /**< as a wide node: slots from kid[0] (the rest from kid[1]) */
    uint8_t pick[FR_BVH_WIDTH]; /**< pick[j-1], j >= 2: 0 = as j-1 slots, else slots from kid[0] */
    float cost[FR_BVH_WIDTH];  /**< cost[j-1]: as at most j slots */
} bvh2_node;

/** Set the costs (and the choices behind them: as_leaf, wide, pick) of
 * node v of the array bn from those of its children (already set); a
 * leaf's from its box and references. */
void bvh2_costs(bvh2_node *bn, uint32_t v);

/** The cost of node v of bn emitted as the root of the 8-wide tree (a
 * wide node, however cheap v would be as a leaf). */
float bvh2_root_cost(const bvh2_node *bn, uint32_t v);

#endif
