/* bvh2.c -- the cost model of collapsing the binary build tree to 8-wide nodes
 * (see bvh2.h). */

#include "compile/bvh2.h"

/* The costs of binary node v from those of its children. */
void bvh2_costs(bvh2_node *bn, uint32_t v)
{
    bvh2_node *n = &bn[v];
    float area = bvh2_area(n->box), slot = area * BVH2_SLOT_COST;
    if (n->is_leaf) {
        for (int j = 0; j < FR_BVH_WIDTH; j++) {
            n->cost[j] = slot + area * bvh2_blocks(n->refs);
            n->pick[j] = 0;
        }
        n->as_leaf = 1;
        return;
    }
    n->kinds = bn[n->kid[0]].kinds | bn[n->kid[1]].kinds;
    const float *ca = bn[n->kid[0]].cost, *cb = bn[n->kid[1]].cost;
    float split[FR_BVH_WIDTH + 1];
    uint8_t at[FR_BVH_WIDTH + 1];
    for (int j = 2; j <= FR_BVH_WIDTH; j++) {
        split[j] = INFINITY;
        at[j] = 1;
        for (int k = 1; k < j; k++) {
            float c = ca[k - 1] + cb[j - k - 1];
            if (c < split[j]) {
                split[j] = c;
                at[j] = (uint8_t)k;
            }
        }
    }
    float as_node = area * BVH2_TRAV_COST + split[FR_BVH_WIDTH];
    float as_leaf = n->refs <= BVH2_LEAF_MAX && n->kinds != (BVH2_TRIS | BVH2_SHAPES) ? area * bvh2_blocks(n->refs) : INFINITY;
    n->wide = at[FR_BVH_WIDTH];
    n->as_leaf = as_leaf <= as_node;
    n->cost[0] = slot + (n->as_leaf ? as_leaf : as_node);
    n->pick[0] = 0;
    for (int j = 2; j <= FR_BVH_WIDTH; j++) {
        if (split[j] < n->cost[j - 2]) {
            n->cost[j - 1] = split[j];
            n->pick[j - 1] = at[j];
        } else {
            n->cost[j - 1] = n->cost[j - 2];
            n->pick[j - 1] = 0;
        }
    }
}

/* The cost of binary node v emitted as the root (a wide node, as
 * emit_node makes it). */
float bvh2_root_cost(const bvh2_node *bn, uint32_t v)
{
    const bvh2_node *n = &bn[v];
    if (n->is_leaf)
        return n->cost[0];
    float best = INFINITY;
    for (int k = 1; k < FR_BVH_WIDTH; k++) {
        float c = bn[n->kid[0]].cost[k - 1] + bn[n->kid[1]].cost[FR_BVH_WIDTH - k - 1];
        best = c < best ? c : best;
    }
    return bvh2_area(n->box) * BVH2_TRAV_COST + best;
}
