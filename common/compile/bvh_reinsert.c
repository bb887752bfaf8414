/* bvh_reinsert.c -- subtree reinsertion that lowers the binary build tree's
 * cost (see bvh_reinsert.h). */

#include "compile/bvh_reinsert.h"

#include <stdlib.h>

/* Before the collapse the binary tree is improved by moving subtrees (the
 * insertion-based optimisation of Bittner, Hapala and Havran, 2013), each
 * move kept only where it lowers the collapse's cost of the whole tree.
 * Leaves keep their references, so a primitive cut by spatial splits stays
 * in the same leaves.
 *   - A leaf N is taken out (its parent goes, its sibling takes the
 *     parent's place, the nodes above are refitted) and put as the sibling
 *     of another node under a new parent.
 *   - An inner node N is taken out with its parent, and its two children
 *     are put back one after the other (the larger first).
 * Where a subtree goes is chosen by the summed area of the inner nodes,
 * the usual stand-in for the SAH: beside the node where it grows least,
 * found by branch and bound from the root (nodes in the order of how much
 * their ancestors would grow, a heap with ties to the lower index, a
 * subtree skipped where that growth plus the moved subtree's own area
 * reaches the best place found; no place where the tree would get deeper
 * than FR_BVH_MAX_DEPTH).  A move that does not lower the inner area is
 * not tried; one that does is kept only if the collapse's cost of the
 * root (bvh2_costs, recomputed up both paths) falls, else undone exactly.
 * A pass tries, worst first, the twentieth of the nodes whose parent is
 * largest against its two children (area(P) / (area(N) + area(S)) *
 * area(P)); passes stop when one gains less than REINS_STOP of the cost,
 * or after REINS_PASSES. */

enum { REINS_PASSES = 3, REINS_SHARE = 20 };
#define REINS_STOP 0.01f

typedef struct {
    float c;                   /* growth of the ancestors' areas */
    uint32_t node, depth;      /* depth: the root is 1 */
} reins_item;

typedef struct {
    bvh2_node *bn;             /* the tree, changed in place */
    float *area;               /* per node: bvh2_area(box) */
    uint32_t *up;              /* parent, FR_NONE at the root and out of the tree */
    uint8_t *height;           /* levels of the subtree: 1 for a leaf */
    uint32_t root, n;
    reins_item *heap;          /* the search's (a node enters it once) */
    uint32_t nh;
} reins;

static int reins_before(reins_item a, reins_item b) { return a.c < b.c || (a.c == b.c && a.node < b.node); }

static void reins_push(reins *R, reins_item it)
{
    uint32_t i = R->nh++;
    while (i > 0) {
        uint32_t p = (i - 1) / 2;
        if (!reins_before(it, R->heap[p]))
            break;
        R->heap[i] = R->heap[p];
        i = p;
    }
    R->heap[i] = it;
}

static reins_item reins_pop(reins *R)
{
    reins_item top = R->heap[0], last = R->heap[--R->nh];
    uint32_t i = 0, n = R->nh;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && reins_before(R->heap[c + 1], R->heap[c]))
            c++;
        if (!reins_before(R->heap[c], last))
            break;
        R->heap[i] = R->heap[c];
        i = c;
    }
    if (n > 0)
        R->heap[i] = last;
    return top;
}

static uint8_t max_u8(uint8_t a, uint8_t b) { return a > b ? a : b; }

/* Box, area, height, references and costs of inner node x and its
 * ancestors from their children. */
static void reins_update(reins *R, uint32_t x)
{
    bvh2_node *bn = R->bn;
    for (; x != FR_NONE; x = R->up[x]) {
        uint32_t a = bn[x].kid[0], b = bn[x].kid[1];
        bn[x].box = bn[a].box;
        bvh2_box_grow(&bn[x].box, bn[b].box);
        bn[x].refs = bn[a].refs + bn[b].refs;
        R->area[x] = bvh2_area(bn[x].box);
        R->height[x] = (uint8_t)(1 + max_u8(R->height[a], R->height[b]));
        bvh2_costs(bn, x);
    }
}

/* Put x where child `from` of p was (p FR_NONE: as the root). */
static void reins_replace(reins *R, uint32_t p, uint32_t from, uint32_t x)
{
    R->up[x] = p;
    if (p == FR_NONE)
        R->root = x;
    else
        R->bn[p].kid[R->bn[p].kid[0] == from ? 0 : 1] = x;
}

/* Take subtree x (not the root's child) out of the tree: its parent goes,
 * the sibling takes the parent's place. */
static void reins_detach(reins *R, uint32_t x)
{
    uint32_t p = R->up[x], g = R->up[p];
    reins_replace(R, g, p, R->bn[p].kid[R->bn[p].kid[0] == x ? 1 : 0]);
    reins_update(R, g);
    R->up[x] = R->up[p] = FR_NONE;
}

/* Put subtree n beside x under the free node p (n its first child if
 * n_first). */
static void reins_attach(reins *R, uint32_t n, uint32_t x, uint32_t p, int n_first)
{
    reins_replace(R, R->up[x], x, p);
    R->bn[p].kid[0] = n_first ? n : x;
    R->bn[p].kid[1] = n_first ? x : n;
    R->up[x] = R->up[n] = p;
    reins_update(R, p);
}

/* The cheapest place for subtree n (out of the tree) as above: the node to
 * put it beside, FR_NONE if there is none within the depth; *cost gets the
 * growth of the inner area there. */
static uint32_t reins_search(reins *R, uint32_t n, float *cost)
{
    const bvh2_node *bn = R->bn;
    bvh2_box nb = bn[n].box;
    float an = R->area[n], best = INFINITY;
    uint32_t best_x = FR_NONE, hn = R->height[n];
    R->nh = 0;
    reins_push(R, (reins_item){0.0f, R->root, 1});
    while (R->nh > 0) {
        reins_item it = reins_pop(R);
        if (!(it.c + an < best))
            break;
        uint32_t x = it.node, h = R->height[x] > hn ? R->height[x] : hn;
        bvh2_box u = bn[x].box;
        bvh2_box_grow(&u, nb);
        float au = bvh2_area(u), total = it.c + au;
        if (total < best && it.depth + h <= FR_BVH_MAX_DEPTH) {
            best = total;
            best_x = x;
        }
        if (bn[x].is_leaf)
            continue;
        float c = it.c + (au - R->area[x]);
        if (c + an < best)
            for (int k = 0; k < 2; k++)
                reins_push(R, (reins_item){c, bn[x].kid[k], it.depth + 1});
    }
    *cost = best;
    return best_x;
}

/* The growth of the inner area from putting subtree n beside x, added up
 * as reins_search adds it. */
static float reins_cost_at(const reins *R, uint32_t n, uint32_t x)
{
    uint32_t path[256];
    int np = 0;
    for (uint32_t y = R->up[x]; y != FR_NONE && np < 256; y = R->up[y])
        path[np++] = y;
    bvh2_box nb = R->bn[n].box;
    float c = 0.0f;
    while (np > 0) {
        uint32_t y = path[--np];
        bvh2_box u = R->bn[y].box;
        bvh2_box_grow(&u, nb);
        c = c + (bvh2_area(u) - R->area[y]);
    }
    bvh2_box u = R->bn[x].box;
    bvh2_box_grow(&u, nb);
    return c + bvh2_area(u);
}


/* Whether a move from cost `before` is kept: the root's cost falls by more
 * than rounding. */
static int reins_better(const reins *R, float before)
{
    return bvh2_root_cost(R->bn, R->root) < before * 0.999999f;
}

/* Move leaf n; returns whether it moved. */
static int reins_move(reins *R, uint32_t n)
{
    uint32_t p = R->up[n];
    int n_first = R->bn[p].kid[0] == n;
    uint32_t s = R->bn[p].kid[n_first ? 1 : 0];
    float before = bvh2_root_cost(R->bn, R->root), cost;
    reins_detach(R, n);
    float stay = reins_cost_at(R, n, s);
    uint32_t x = reins_search(R, n, &cost);
    if (x != FR_NONE && x != s && cost < stay) {
        reins_attach(R, n, x, p, 0);
        if (reins_better(R, before))
            return 1;
        reins_detach(R, n);
    }
    reins_attach(R, n, s, p, n_first);
    return 0;
}

/* Summed area of y and its ancestors. */
static float reins_path_area(const reins *R, uint32_t y)
{
    float sum = 0.0f;
    for (; y != FR_NONE; y = R->up[y])
        sum += R->area[y];
    return sum;
}

/* Take inner node n out with its parent and put its children back;
 * returns whether that was kept. */
static int reins_split(reins *R, uint32_t n)
{
    bvh2_node *bn = R->bn;
    uint32_t p = R->up[n], g = R->up[p], a = bn[n].kid[0], b = bn[n].kid[1];
    int n_first = bn[p].kid[0] == n;
    uint32_t s = bn[p].kid[n_first ? 1 : 0];
    float before = bvh2_root_cost(bn, R->root), area_before = reins_path_area(R, n);
    reins_detach(R, n);
    float area_after = reins_path_area(R, g);
    R->up[a] = R->up[b] = FR_NONE;
    uint32_t first = R->area[a] >= R->area[b] ? a : b, second = first == a ? b : a;
    /* Beside s is where first was, within the depth; where second finds
     * no place within it, all is undone. */
    float c1, c2;
    uint32_t x1 = reins_search(R, first, &c1);
    if (x1 == FR_NONE)
        c1 = reins_cost_at(R, first, x1 = s);
    reins_attach(R, first, x1, n, 0);
    uint32_t x2 = reins_search(R, second, &c2);
    int undo = x2 == FR_NONE;
    reins_attach(R, second, undo ? first : x2, p, 0);
    if (!undo && area_before - area_after > c1 + c2 && reins_better(R, before))
        return 1;
    reins_detach(R, second);
    reins_detach(R, first);
    bn[n].kid[0] = a;
    bn[n].kid[1] = b;
    R->up[a] = R->up[b] = n;
    R->up[n] = FR_NONE;
    reins_update(R, n);
    reins_attach(R, n, s, p, n_first);
    return 0;
}

typedef struct {
    float score;
    uint32_t node;
} reins_cand;

/* Worst first, ties to the lower index (a total order: qsort's algorithm
 * does not matter). */
static int reins_cand_cmp(const void *a, const void *b)
{
    const reins_cand *x = a, *y = b;
    if (x->score != y->score)
        return x->score > y->score ? -1 : 1;
    return x->node < y->node ? -1 : x->node > y->node;
}

/* One pass (cand: scratch for every node). */
static void reins_pass(reins *R, reins_cand *cand)
{
    const bvh2_node *bn = R->bn;
    uint32_t nc = 0;
    for (uint32_t i = 0; i < R->n; i++) {
        uint32_t p = R->up[i];
        if (p == FR_NONE || R->up[p] == FR_NONE)
            continue;
        uint32_t s = bn[p].kid[bn[p].kid[0] == i ? 1 : 0];
        float score = R->area[p] / (R->area[s] + R->area[i]) * R->area[p];
        cand[nc++] = (reins_cand){score == score ? score : 0.0f, i};   /* 0/0: flat boxes */
    }
    qsort(cand, nc, sizeof *cand, reins_cand_cmp);
    for (uint32_t k = 0; k < nc / REINS_SHARE; k++) {
        uint32_t n = cand[k].node, p = R->up[n];
        if (p == FR_NONE || R->up[p] == FR_NONE)   /* now a child of the root */
            continue;
        if (bn[n].is_leaf)
            reins_move(R, n);
        else
            reins_split(R, n);
    }
}

int bvh_reinsert(bvh2_node *bn, uint32_t n, uint32_t *root, fr_error *err)
{
    if (n < 7)
        return 0;
    reins R = {0};
    R.bn = bn;
    R.n = n;
    R.root = *root;
    R.area = malloc((size_t)n * sizeof *R.area);
    R.up = malloc((size_t)n * sizeof *R.up);
    R.height = malloc(n);
    R.heap = malloc((size_t)n * sizeof *R.heap);
    reins_cand *cand = malloc((size_t)n * sizeof *cand);
    int rc = 0;
    if (!R.area || !R.up || !R.height || !R.heap || !cand) {
        rc = fr_fail(err, "out of memory for the BVH reinsertion (%u nodes)", n);
        goto done;
    }
    /* The build numbers a node before its children: from the back, children
     * come first. */
    for (uint32_t i = n; i-- > 0;) {
        const bvh2_node *v = &R.bn[i];
        R.up[i] = FR_NONE;
        R.height[i] = 1;
        if (!v->is_leaf) {
            R.height[i] = (uint8_t)(1 + max_u8(R.height[v->kid[0]], R.height[v->kid[1]]));
            R.up[v->kid[0]] = R.up[v->kid[1]] = i;
        }
        R.area[i] = bvh2_area(v->box);
    }
    for (int pass = 0; pass < REINS_PASSES; pass++) {
        float before = bvh2_root_cost(R.bn, R.root);
        reins_pass(&R, cand);
        if (!(bvh2_root_cost(R.bn, R.root) < before * (1.0f - REINS_STOP)))
            break;
    }
    *root = R.root;
done:
    free(R.area);
    free(R.up);
    free(R.height);
    free(R.heap);
    free(cand);
    return rc;
}
