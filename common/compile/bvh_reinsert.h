/** @file bvh_reinsert.h
 * Reinsertion: the BVH build's improvement of its binary tree (bvh2.h)
 * before the collapse to the 8-wide tree, by moving subtrees to where the
 * tree's summed area grows least and keeping a move only where the
 * collapse's cost of the whole tree (bvh2_root_cost) falls.  Leaves keep
 * their references.  Deterministic: the same tree gives the same moves on
 * every machine.
 */
#ifndef FRANJA_BVH_REINSERT_H
#define FRANJA_BVH_REINSERT_H

#include <stdint.h>

#include "compile/bvh2.h"
#include "error.h"

/** Reinsertion over the binary tree of the n nodes bn[0..n) rooted at
 * *root, changed in place.  On entry a node's children follow it in bn
 * (as the build numbers them), every node's costs are set (bvh2_costs),
 * and no leaf is deeper than FR_BVH_MAX_DEPTH.  On return the same holds
 * except for the order: children may come before their parent, and *root
 * may name another node.  Nodes are relinked, never added or removed.
 * Returns 0, or -1 with *err set on memory exhaustion (the tree then
 * unchanged). */
int bvh_reinsert(bvh2_node *bn, uint32_t n, uint32_t *root, fr_error *err);

#endif
