/* test_bvh.c -- the BVH returns exactly the brute-force nearest hit.
 *
 * Random scenes (triangle soups, shared-edge grids, coplanar sheets,
 * degenerate triangles, identical triangles, spheres and rectangles mixed
 * in) are built through the builder; random rays (from outside and inside
 * the boxes, axis-parallel ones with exact zero components, rays lying in
 * box planes, rays with a finite tmax) are traced with trace_closest and
 * compared with a loop over every primitive: same primitive, same t, same
 * barycentrics, bit for bit.  Long crossing slivers make the build split
 * triangles spatially (one triangle in several leaves): the walk must still
 * return each hit once, as brute force does.  trace_occluded must agree with the nearest
 * hit, with and without a skipped primitive.  Every tree must pass
 * bvh_validate, name a primitive at most once per leaf and leave lanes
 * empty only in a leaf's last block.  Where there are two
 * traversals (x86-64 with AVX2), both are checked.  Trees built with and
 * without reinsertion are compared by their SAH cost, and reinsertion is
 * run alone (bvh_reinsert.h) on a poor binary tree, whose every node,
 * leaf, box and cost it must keep consistent.  Rays leaving from points on
 * a height grid's triangles, as bounce rays do, meet their own triangle at
 * t near 0 on either side. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "bvh.h"
#include "compile/bvh_build.h"
#include "compile/bvh_reinsert.h"
#include "check.h"
#include "fbin.h"
#include "compile/freeze.h"
#include "trace.h"

static uint64_t rng_state = 0x853c49e6748fea9bull;

static uint32_t rnd_u32(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    uint32_t x = (uint32_t)(((rng_state >> 18) ^ rng_state) >> 27), r = (uint32_t)(rng_state >> 59);
    return (x >> r) | (x << ((32 - r) & 31));
}

static float rnd(void) { return (float)(rnd_u32() >> 8) * (1.0f / 16777216.0f); }
static float rnd_in(float a, float b) { return a + (b - a) * rnd(); }
static vec3 rnd_vec(float a, float b) { return v3(rnd_in(a, b), rnd_in(a, b), rnd_in(a, b)); }

static vec3 rnd_dir(void)
{
    for (;;) {
        vec3 d = rnd_vec(-1.0f, 1.0f);
        float l = v3_len2(d);
        if (l > 1e-4f && l <= 1.0f)
            return v3_scale(d, 1.0f / sqrtf(l));
    }
}

static void start(fr_builder *b)
{
    bld_init(b);
    fr_material m;
    bld_material_init(&m);
    m.diffuse = v3s(0.5f);
    bsdf_lobe_probs(&m);
    bld_push(&b->materials, &m);
    b->settings = (fr_settings){.width = 64, .height = 64, .spp = 1, .max_depth = 4};
    b->camera.position = v3(0, 0, -5);
    b->camera.target = v3(0, 0, 0);
    b->camera.up = v3(0, 1, 0);
    b->camera.vfov = 1.0f;
    b->camera.focus = 5.0f;
}

/* An indexed triangle without checks (degenerate ones welcome). */
static void tri(fr_builder *b, uint32_t i0, uint32_t i1, uint32_t i2)
{
    fr_triangle t = {{i0, i1, i2}, 0};
    uint32_t ti = bld_push(&b->triangles, &t);
    fr_prim p = {FR_PRIM_TRIANGLE, ti, 0, FR_NONE};
    bld_push(&b->prims, &p);
}

static uint32_t vert(fr_builder *b, vec3 p) { return bld_push(&b->positions, &p); }

/* ---- the scenes ---- */

static void soup(fr_builder *b, int n, float size)
{
    for (int i = 0; i < n; i++) {
        vec3 c = rnd_vec(-1.0f, 1.0f);
        tri(b, vert(b, v3_add(c, rnd_vec(-size, size))), vert(b, v3_add(c, rnd_vec(-size, size))),
            vert(b, v3_add(c, rnd_vec(-size, size))));
    }
}

/* A height grid: every inner edge shared by two triangles. */
static void grid(fr_builder *b, int n)
{
    uint32_t base = b->positions.count;
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++)
            vert(b, v3(2.0f * i / n - 1.0f, 0.3f * rnd(), 2.0f * j / n - 1.0f));
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            uint32_t a = base + i * (n + 1) + j, c = a + n + 1;
            tri(b, a, c, c + 1);
            tri(b, a, c + 1, a + 1);
        }
}

/* Triangles in the planes z = k/4 and x = 0.5: axis-parallel rays lie in
 * them and in their boxes' faces. */
static void sheets(fr_builder *b, int n)
{
    for (int i = 0; i < n; i++) {
        float z = (float)(rnd_u32() % 5) * 0.25f - 0.5f;
        float x0 = rnd_in(-1, 1), y0 = rnd_in(-1, 1);
        tri(b, vert(b, v3(x0, y0, z)), vert(b, v3(x0 + rnd_in(0.05f, 0.4f), y0, z)),
            vert(b, v3(x0, y0 + rnd_in(0.05f, 0.4f), z)));
        tri(b, vert(b, v3(0.5f, y0, x0)), vert(b, v3(0.5f, y0 + 0.25f, x0)), vert(b, v3(0.5f, y0, x0 + 0.25f)));
    }
}

static void degenerate(fr_builder *b, int n)
{
    for (int i = 0; i < n; i++) {
        vec3 p = rnd_vec(-1, 1), q = rnd_vec(-1, 1);
        switch (i % 3) {
        case 0: tri(b, vert(b, p), vert(b, p), vert(b, q)); break;                         /* repeated vertex */
        case 1: tri(b, vert(b, p), vert(b, v3_scale(v3_add(p, q), 0.5f)), vert(b, q)); break; /* collinear */
        default: tri(b, vert(b, p), vert(b, p), vert(b, p)); break;                        /* a point */
        }
    }
}

/* Many copies of one triangle: every centroid equal, so the build must
 * fall back to splitting by count. */
static void copies(fr_builder *b, int n)
{
    uint32_t a = vert(b, v3(-0.3f, -0.2f, 0.1f)), c = vert(b, v3(0.4f, -0.1f, 0.1f)), d = vert(b, v3(0.0f, 0.5f, 0.2f));
    for (int i = 0; i < n; i++)
        tri(b, a, c, d);
}

static void others(fr_builder *b, int n)
{
    for (int i = 0; i < n; i++) {
        if (i % 2)
            bld_sphere(b, rnd_vec(-1, 1), rnd_in(0.01f, 0.3f), 0);
        else
            bld_rect(b, rnd_vec(-1, 1), rnd_vec(-0.3f, 0.3f), rnd_vec(-0.3f, 0.3f), 0);
    }
}

/* A sheet of long thin triangles lying diagonal to the axes (a 5 x m
 * grid stretched along one diagonal, squeezed along the other, bumpy):
 * their boxes are mostly empty, so the build cuts them with spatial splits
 * and puts parts of one triangle in several leaves. */
static void slivers(fr_builder *b, int n)
{
    int m = n / 8 + 2;
    uint32_t base = b->positions.count;
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < m; j++) {
            float u = 0.5f * (float)i - 1.0f, w = 2.0f * (float)j / (float)(m - 1) - 1.0f;
            vert(b, v3((u - w) * 0.70710678f, 0.1f * rnd() + 0.2f * w, (u + w) * 0.70710678f));
        }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j + 1 < m; j++) {
            uint32_t a = base + (uint32_t)(i * m + j), c = a + (uint32_t)m;
            tri(b, a, c, c + 1);
            tri(b, a, c + 1, a + 1);
        }
}

/* Triangles halving in size toward one point (and one far off): boxes
 * nested in one another, centroids bins cannot tell apart. */
static void nested(fr_builder *b, int n)
{
    float s = 1.0f;
    for (int i = 0; i < n; i++, s *= 0.5f) {
        vec3 c = v3(0.3f + s, 0.1f, 0.2f + 0.5f * s);
        tri(b, vert(b, c), vert(b, v3_add(c, v3(s, 0, 0))), vert(b, v3_add(c, v3(0, s, 0.1f * s))));
    }
    tri(b, vert(b, v3(-1, -1, 0)), vert(b, v3(-0.9f, -1, 0)), vert(b, v3(-1, -0.9f, 0)));
}

/* nested(), each triangle with a sphere beside it of its size: the
 * deepest leaves of a tree that is as deep as the build allows would hold
 * both kinds, which the build keeps apart with one level more. */
static void nested_mixed(fr_builder *b, int n)
{
    nested(b, n);
    float s = 1.0f;
    for (int i = 0; i < n; i++, s *= 0.5f)
        bld_sphere(b, v3(0.3f + 1.5f * s, 0.1f + 0.5f * s, 0.2f + 0.5f * s), 0.25f * s, 0);
}

/* Long thin triangles at random places, all along one diagonal and
 * crossing one another: the inner nodes' area, the usual stand-in for the
 * SAH, is a poor guide to the collapsed tree's cost here. */
static void crossing(fr_builder *b, int n)
{
    for (int i = 0; i < n; i++) {
        float u = rnd_in(-1, 1), w = rnd_in(-1, 1);
        tri(b, vert(b, v3(u, w, 0.0f)), vert(b, v3(u + 0.5f, w + 0.5f, 0.01f * rnd())),
            vert(b, v3(u + 0.501f, w + 0.5f, 0.0f)));
    }
}

/* ---- rays ---- */

static fr_ray make_ray(const fr_scene *s, int kind)
{
    fr_ray r;
    switch (kind) {
    case 0: /* from outside, toward the middle */
        r.o = v3_scale(rnd_dir(), 4.0f);
        r.d = v3_norm(v3_sub(rnd_vec(-0.8f, 0.8f), r.o));
        break;
    case 1: /* from inside the boxes, anywhere */
        r.o = rnd_vec(-1.2f, 1.2f);
        r.d = rnd_dir();
        break;
    case 2: { /* axis-parallel, with exact zeros (and signed zeros) */
        int a = (int)(rnd_u32() % 3);
        float c[3] = {rnd() < 0.5f ? 0.0f : -0.0f, rnd() < 0.5f ? 0.0f : -0.0f, rnd() < 0.5f ? 0.0f : -0.0f};
        c[a] = rnd() < 0.5f ? 1.0f : -1.0f;
        r.o = rnd_vec(-1.5f, 1.5f);
        r.d = v3(c[0], c[1], c[2]);
        break;
    }
    default: { /* axis-parallel through a vertex's coordinates: in box planes */
        if (s->n_positions == 0)
            return make_ray(s, 2);
        int a = (int)(rnd_u32() % 3);
        vec3 p = s->positions[rnd_u32() % s->n_positions];
        float c[3] = {0, 0, 0};
        c[a] = rnd() < 0.5f ? 1.0f : -1.0f;
        r.d = v3(c[0], c[1], c[2]);
        r.o = p;
        if (a == 0) r.o.x = rnd_in(-3, 3);
        if (a == 1) r.o.y = rnd_in(-3, 3);
        if (a == 2) r.o.z = rnd_in(-3, 3);
        break;
    }
    }
    return r;
}

/* Nearest hit by trying every primitive: lowest index wins a tie. */
static int brute(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip, fr_hit *h)
{
    int found = 0;
    float best = tmax;
    for (uint32_t p = 0; p < s->n_prims; p++) {
        float a, b;
        if (p == skip)
            continue;
        float t = trace_prim(s, p, r, best, &a, &b);
        if (t > 0.0f) {
            best = t;
            *h = (fr_hit){t, p, FR_NONE, a, b, 0};
            found = 1;
        }
    }
    return found;
}

static int same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

static void compare(const char *name, fr_builder *b, fr_builder *again, int rays, int want_split)
{
    fr_scene s;
    fr_error err;
    if (frz_scene(b, &s, &err) < 0) {
        CHECK(0, "%s: build failed: %s", name, err.msg);
        return;
    }
    CHECK(s.n_nodes > 0, "%s: has a BVH", name);
    CHECK(bvh_validate(&s, s.blob, &err) == 0, "%s: the tree is refused: %s", name, err.msg);
    /* A leaf names a primitive once (a subtree packed into one leaf may
     * hold two parts of a triangle cut by a spatial split: the builder
     * keeps one), and only its last block may have empty lanes. */
    /* The builder keeps triangles and other primitives in separate leaves,
     * marked mixed exactly when they hold no triangle. */
    int twice = 0, holes = 0, kinds = 0;
    for (uint32_t j = 0; j < s.n_nodes; j++)
        for (int c = 0; c < FR_BVH_WIDTH; c++) {
            uint32_t meta = s.nodes[j].leaf[c], nb = meta & FR_BVH_LEAF_MAX;
            if (!meta || s.nodes[j].child[c] == FR_NONE)
                continue;
            const fr_bvh_leaf *L = s.leaves + s.nodes[j].child[c];
            for (uint32_t x = 0; x < 4 * nb; x++) {
                uint32_t px = L[x / 4].prim[x % 4];
                if (px == FR_NONE) {
                    holes += x / 4 + 1 < nb;
                    continue;
                }
                kinds += (s.prims[px].kind == FR_PRIM_TRIANGLE) == !!(meta & FR_BVH_MIXED);
                for (uint32_t y = 0; y < x; y++)
                    twice += L[y / 4].prim[y % 4] == px;
            }
        }
    CHECK(twice == 0, "%s: %d primitives twice in one leaf", name, twice);
    CHECK(holes == 0, "%s: %d empty lanes before a leaf's last block", name, holes);
    CHECK(kinds == 0, "%s: %d lanes whose kind is not their leaf's (triangles, or mixed: other shapes)", name, kinds);
    /* Lanes in use: one per primitive, more where spatial splits put a
     * primitive in several leaves. */
    uint32_t lanes = 0;
    for (uint32_t j = 0; j < s.n_leaves; j++)
        for (int k = 0; k < 4; k++)
            lanes += s.leaves[j].prim[k] != FR_NONE;
    CHECK(lanes >= s.n_prims, "%s: %u lanes for %u primitives", name, lanes, s.n_prims);
    if (want_split)
        CHECK(lanes > s.n_prims + s.n_prims / 4, "%s: %u lanes for %u primitives: spatial splits not used", name, lanes,
              s.n_prims);
    int bad = 0, badany = 0, hits = 0;
    for (int i = 0; i < rays; i++) {
        fr_ray r = make_ray(&s, i % 4);
        float tmax = (i % 7 == 0) ? rnd_in(0.1f, 3.0f) : INFINITY;
        fr_hit hb = {0}, ht = {0};
        int fb = brute(&s, &r, tmax, FR_NONE, &hb);
        int ft = trace_closest(&s, &r, tmax, &ht);
        hits += fb;
        if (fb != ft || (fb && (ht.prim != hb.prim || !same_bits(ht.t, hb.t) || !same_bits(ht.a, hb.a) ||
                                !same_bits(ht.b, hb.b)))) {
            if (bad++ < 5)
                CHECK(0, "%s ray %d (kind %d): bvh %d prim %u t %.9g, brute %d prim %u t %.9g", name, i, i % 4, ft,
                      ft ? ht.prim : 0, ft ? (double)ht.t : 0.0, fb, fb ? hb.prim : 0, fb ? (double)hb.t : 0.0);
        }
        if (trace_occluded(&s, &r, tmax, FR_NONE) != fb && badany++ < 5)
            CHECK(0, "%s ray %d: any-hit %d, nearest hit %d", name, i, !fb, fb);
        if (fb) {
            /* Skipping the nearest primitive: occluded iff another one is hit. */
            fr_hit h2;
            int f2 = brute(&s, &r, tmax, hb.prim, &h2);
            if (trace_occluded(&s, &r, tmax, hb.prim) != f2 && badany++ < 5)
                CHECK(0, "%s ray %d: any-hit skipping %u disagrees", name, i, hb.prim);
        }
    }
    CHECK(bad == 0, "%s: %d of %d rays differ from brute force", name, bad, rays);
    CHECK(badany == 0, "%s: %d any-hit disagreements", name, badany);
    CHECK(hits > rays / 20, "%s: only %d of %d rays hit anything (test too weak)", name, hits, rays);
    /* The same input builds the same bytes. */
    fr_scene s2;
    if (frz_scene(again, &s2, &err) == 0) {
        CHECK(s2.hash == s.hash, "%s: rebuilding gives another hash", name);
        scn_free(&s2);
    }
    scn_free(&s);
}

/* Scene s from builder b; on failure a failed check naming `what`, b
 * freed, and -1. */
static int freeze(fr_builder *b, fr_scene *s, const char *what)
{
    fr_error err;
    if (frz_scene(b, s, &err) == 0)
        return 0;
    CHECK(0, "%s: build failed: %s", what, err.msg);
    bld_free(b);
    return -1;
}

/* Leaves that mix triangles with other shapes, which the build no longer
 * makes but a scene file may hold (FORMAT.md): a scene's tree replaced by
 * one node over eight mixed leaves, the primitives dealt out to them in
 * turn, and every walk checked against brute force. */
static void mixed_leaves(void)
{
    fr_builder b;
    start(&b);
    soup(&b, 60, 0.3f);
    others(&b, 30);
    fr_scene s;
    if (freeze(&b, &s, "mixed leaves") < 0)
        return;
    uint32_t np = s.n_prims, per = (np + FR_BVH_WIDTH - 1) / FR_BVH_WIDTH, nb = (per + 3) / 4;
    fr_bvh_leaf *blocks = calloc((size_t)FR_BVH_WIDTH * nb, sizeof *blocks);
    fr_bvh_node root;
    memset(&root, 0, sizeof root);
    int tris = 0, shapes = 0;
    for (int c = 0; c < FR_BVH_WIDTH; c++) {
        for (uint32_t k = 0; k < 4 * nb; k++) {
            uint32_t p = (uint32_t)c + FR_BVH_WIDTH * k;
            fr_bvh_leaf *L = &blocks[(size_t)c * nb + k / 4];
            L->prim[k % 4] = k < per && p < np ? p : FR_NONE;
            if (L->prim[k % 4] == FR_NONE)
                continue;
            if (s.prims[p].kind != FR_PRIM_TRIANGLE) {
                shapes++;
                continue;
            }
            tris++;
            const fr_triangle *t = &s.triangles[s.prims[p].index];
            for (int v = 0; v < 3; v++) {
                vec3 q = s.positions[t->v[v]];
                L->v[3 * v + 0][k % 4] = q.x;
                L->v[3 * v + 1][k % 4] = q.y;
                L->v[3 * v + 2][k % 4] = q.z;
            }
        }
        /* Boxes far larger than their leaves (a bound need not be
         * tight): every ray visits every leaf. */
        for (int r = 0; r < 6; r++)
            root.box[r][c] = r < 3 ? -100.0f : 100.0f;
        root.child[c] = (uint32_t)c * nb;
        root.leaf[c] = nb | FR_BVH_MIXED;
    }
    CHECK(tris > 0 && shapes > 0, "mixed leaves: %d triangle and %d other lanes", tris, shapes);
    s.nodes = &root;
    s.n_nodes = 1;
    s.leaves = blocks;
    s.n_leaves = FR_BVH_WIDTH * nb;
    unsigned walks = trace_walks();
    int def = trace_walk();
    for (int k = 0; k < TRACE_WALKS; k++) {
        if (!(walks >> k & 1))
            continue;
        trace_set_walk(k);
        int bad = 0, hits = 0;
        for (int i = 0; i < 3000; i++) {
            fr_ray r = make_ray(&s, i % 4);
            fr_hit hb = {0}, ht = {0};
            int fb = brute(&s, &r, INFINITY, FR_NONE, &hb), ft = trace_closest(&s, &r, INFINITY, &ht);
            hits += fb;
            bad += fb != ft || (fb && (ht.prim != hb.prim || !same_bits(ht.t, hb.t))) ||
                   trace_occluded(&s, &r, INFINITY, FR_NONE) != fb;
        }
        CHECK(bad == 0, "mixed leaves (%s walk): %d of 3000 rays differ from brute force", trace_walk_name(k), bad);
        CHECK(hits > 150, "mixed leaves (%s walk): only %d rays hit", trace_walk_name(k), hits);
    }
    trace_set_walk(def);
    free(blocks);
    scn_free(&s);
    bld_free(&b);
}

/* Depth of the wide tree under node v (1 for v alone). */
static int wide_depth(const fr_bvh_node *nodes, uint32_t v)
{
    int d = 0;
    for (int i = 0; i < FR_BVH_WIDTH; i++)
        if (nodes[v].child[i] != FR_NONE && !nodes[v].leaf[i]) {
            int e = wide_depth(nodes, nodes[v].child[i]);
            d = e > d ? e : d;
        }
    return d + 1;
}

/* Reinsertion against the plain top-down tree on the same scene: never a
 * higher SAH cost (the builder keeps a move only where its own cost of the
 * tree falls; 1e-5 allows for the rounding of its float sums against
 * bvh_sah_cost's), every primitive still in a leaf, within the depth; where
 * the top-down split leaves much overlap (`gain`: the least relative drop
 * expected) it must help.  And bvh_build's tree is the reinsertion's. */
static void reinsertion(const char *name, int which, int n, double gain)
{
    fr_builder b[3];
    uint64_t seed = rng_state;
    fr_array nodes[3], leaves[3];
    double cost[3];
    for (int k = 0; k < 3; k++) {
        rng_state = seed;
        start(&b[k]);
        switch (which) {
        case 0: soup(&b[k], n, 0.05f); break;
        case 1: grid(&b[k], n); break;
        case 2: slivers(&b[k], n); break;
        case 3: nested(&b[k], n); break;
        case 4: crossing(&b[k], n); break;
        default: slivers(&b[k], n); sheets(&b[k], 200); soup(&b[k], 300, 0.2f); break;
        }
        nodes[k] = (fr_array){NULL, 0, 0, sizeof(fr_bvh_node)};
        leaves[k] = (fr_array){NULL, 0, 0, sizeof(fr_bvh_leaf)};
        bvh_options opt = {k == 1};
        fr_error err;
        uint32_t *placed = NULL;
        if (bvh_build_with(&b[k], k < 2 ? &opt : NULL, &nodes[k], &leaves[k], &placed, &err) < 0) {
            CHECK(0, "%s: build %d failed: %s", name, k, err.msg);
            return;
        }
        free(placed);
        cost[k] = bvh_sah_cost(nodes[k].data, nodes[k].count);
        uint32_t np = b[k].prims.count, seen = 0;
        uint8_t *in = calloc(np, 1);
        const fr_bvh_leaf *L = leaves[k].data;
        for (uint32_t j = 0; j < leaves[k].count; j++)
            for (int l = 0; l < 4; l++)
                if (L[j].prim[l] != FR_NONE && L[j].prim[l] < np && !in[L[j].prim[l]]++)
                    seen++;
        free(in);
        CHECK(seen == np, "%s (build %d): %u of %u primitives in leaves", name, k, seen, np);
        int depth = wide_depth(nodes[k].data, 0);
        CHECK(depth <= FR_BVH_MAX_DEPTH, "%s (build %d): depth %d", name, k, depth);
    }
    CHECK(cost[0] > 0.0 && cost[1] <= cost[0] * (1.0 + 1e-5), "%s: SAH cost %.6f with reinsertion, %.6f without", name, cost[1],
          cost[0]);
    if (gain > 0.0)
        CHECK(cost[1] < cost[0] * (1.0 - gain), "%s: SAH cost %.6f with reinsertion, %.6f without: less than %.1f %% gained",
              name, cost[1], cost[0], 100.0 * gain);
    CHECK(nodes[1].count == nodes[2].count && leaves[1].count == leaves[2].count &&
              !memcmp(nodes[1].data, nodes[2].data, nodes[1].count * sizeof(fr_bvh_node)) &&
              !memcmp(leaves[1].data, leaves[2].data, leaves[1].count * sizeof(fr_bvh_leaf)),
          "%s: bvh_build's tree is not the one with reinsertion", name);
    for (int k = 0; k < 3; k++) {
        free(nodes[k].data);
        free(leaves[k].data);
        bld_free(&b[k]);
    }
}

/* A binary tree over `leaves` small random boxes, paired in their random
 * order (so spatially poor: reinsertion has much to gain), numbered as the
 * build numbers it (a node before its children), costs set.  Leaf i holds
 * references [4 i, 4 i + 4).  Returns the root. */
static uint32_t poor_tree(bvh2_node *bn, uint32_t *n, uint32_t first, uint32_t count)
{
    uint32_t me = (*n)++;
    memset(&bn[me], 0, sizeof bn[me]);
    if (count == 1) {
        vec3 c = rnd_vec(-1.0f, 1.0f), e = rnd_vec(0.01f, 0.05f);
        bn[me].box = (bvh2_box){{c.x - e.x, c.y - e.y, c.z - e.z, 0.0f}, {c.x + e.x, c.y + e.y, c.z + e.z, 0.0f}};
        bn[me].kid[0] = 4 * first;
        bn[me].kid[1] = 4 * first + 4;
        bn[me].refs = 4;
        bn[me].is_leaf = 1;
    } else {
        uint32_t a = poor_tree(bn, n, first, count / 2), b = poor_tree(bn, n, first + count / 2, count - count / 2);
        bn[me].kid[0] = a;
        bn[me].kid[1] = b;
        bn[me].box = bn[a].box;
        bvh2_box_grow(&bn[me].box, bn[b].box);
        bn[me].refs = bn[a].refs + bn[b].refs;
    }
    bvh2_costs(bn, me);
    return me;
}

/* Walk the binary tree from v: every node reached once, each inner node's
 * box, references and costs as its children give them (bvh2_costs again,
 * bit for bit), leaves' reference ranges marked in *ranges.  Returns the
 * depth under v (1 for a leaf), or -1 on a fault. */
static int check_tree(const bvh2_node *bn, uint32_t n, uint32_t v, uint8_t *seen, uint8_t *ranges, uint32_t n_ranges)
{
    if (v >= n || seen[v]++)
        return -1;
    const bvh2_node *x = &bn[v];
    bvh2_node again[3];
    if (x->is_leaf) {
        uint32_t r = x->kid[0] / 4;
        if (x->kid[1] != x->kid[0] + 4 || r >= n_ranges || ranges[r]++)
            return -1;
        again[0] = *x;
        bvh2_costs(again, 0);
        return memcmp(again[0].cost, x->cost, sizeof x->cost) ? -1 : 1;
    }
    int da = check_tree(bn, n, x->kid[0], seen, ranges, n_ranges), db = check_tree(bn, n, x->kid[1], seen, ranges, n_ranges);
    if (da < 0 || db < 0)
        return -1;
    again[0] = *x;
    again[0].kid[0] = 1;
    again[0].kid[1] = 2;
    again[1] = bn[x->kid[0]];
    again[2] = bn[x->kid[1]];
    bvh2_box box = again[1].box;
    bvh2_box_grow(&box, again[2].box);
    if (memcmp(&box, &x->box, sizeof box) || x->refs != again[1].refs + again[2].refs)
        return -1;
    bvh2_costs(again, 0);
    if (memcmp(again[0].cost, x->cost, sizeof x->cost) || again[0].as_leaf != x->as_leaf)
        return -1;
    return 1 + (da > db ? da : db);
}

/* bvh_reinsert through its own header, on a tree it can improve much: the
 * same nodes relinked into one tree that reaches each once, every leaf
 * with its references, boxes and costs consistent with the children,
 * within the depth, the root's cost lower; the same result twice; a tree
 * of fewer than seven nodes left alone. */
static void reinsert_contract(void)
{
    enum { LEAVES = 500, NODES = 2 * LEAVES - 1 };
    bvh2_node *bn = malloc(NODES * sizeof *bn), *copy = malloc(NODES * sizeof *copy);
    uint8_t *seen = malloc(NODES), *ranges = malloc(LEAVES);
    uint32_t n = 0, root = poor_tree(bn, &n, 0, LEAVES), root2 = root;
    memcpy(copy, bn, NODES * sizeof *bn);
    float before = bvh2_root_cost(bn, root);
    fr_error err;
    int rc = bvh_reinsert(bn, n, &root, &err), rc2 = bvh_reinsert(copy, n, &root2, &err);
    CHECK(rc == 0 && rc2 == 0 && n == NODES, "reinsert: failed (%d, %d) or %u nodes", rc, rc2, n);
    memset(seen, 0, NODES);
    memset(ranges, 0, LEAVES);
    int depth = check_tree(bn, n, root, seen, ranges, LEAVES), all = 1;
    for (uint32_t i = 0; i < NODES; i++)
        all &= seen[i] == 1;
    for (uint32_t i = 0; i < LEAVES; i++)
        all &= ranges[i] == 1;
    CHECK(depth > 0 && all, "reinsert: not one consistent tree over every node and leaf (depth %d)", depth);
    CHECK(depth <= FR_BVH_MAX_DEPTH, "reinsert: depth %d", depth);
    float after = bvh2_root_cost(bn, root);
    CHECK(after < before * 0.9f, "reinsert: root cost %.4f from %.4f, less than 10 %% gained", after, before);
    CHECK(root == root2 && !memcmp(bn, copy, NODES * sizeof *bn), "reinsert: two runs differ");
    n = 0;
    root = poor_tree(bn, &n, 0, 3);
    memcpy(copy, bn, n * sizeof *bn);
    root2 = root;
    CHECK(bvh_reinsert(bn, n, &root, &err) == 0 && root == root2 && !memcmp(bn, copy, n * sizeof *bn),
          "reinsert: a tree of %u nodes changed", n);
    free(bn);
    free(copy);
    free(seen);
    free(ranges);
}

/* Zero bounds are stored as +0: where -0 meets +0, SSE and NEON min and
 * max return different zeros, so without that a mesh with -0 coordinates
 * would give other bytes on arm64 than on amd64. */
static void signed_zeros(void)
{
    fr_builder b;
    start(&b);
    for (int i = 0; i < 300; i++) {
        float u = rnd_in(-1, 1), w = rnd_in(-1, 1);
        tri(&b, vert(&b, v3(-0.0f, u, w)), vert(&b, v3(0.0f, u + 0.1f, w)), vert(&b, v3(-0.0f, u, w + 0.1f)));
        tri(&b, vert(&b, v3(u, -0.0f, w)), vert(&b, v3(u + 0.1f, 0.0f, w)), vert(&b, v3(u, -0.0f, w + 0.1f)));
        tri(&b, vert(&b, v3(u, w, 0.0f)), vert(&b, v3(u + 0.1f, w, -0.0f)), vert(&b, v3(u, w + 0.1f, -0.0f)));
    }
    fr_array nodes = {NULL, 0, 0, sizeof(fr_bvh_node)}, leaves = {NULL, 0, 0, sizeof(fr_bvh_leaf)};
    fr_error err;
    if (bvh_build(&b, &nodes, &leaves, NULL, &err) < 0) {
        CHECK(0, "signed zeros: build failed: %s", err.msg);
    } else {
        int zeros = 0, negative = 0;
        const fr_bvh_node *nd = nodes.data;
        for (uint32_t j = 0; j < nodes.count; j++)
            for (int k = 0; k < 6; k++)
                for (int i = 0; i < FR_BVH_WIDTH; i++)
                    if (nd[j].box[k][i] == 0.0f) {
                        zeros++;
                        negative += signbit(nd[j].box[k][i]) != 0;
                    }
        CHECK(zeros > 0, "signed zeros: no bound at zero (test too weak)");
        CHECK(negative == 0, "signed zeros: %d of %d zero bounds are -0", negative, zeros);
    }
    free(nodes.data);
    free(leaves.data);
    bld_free(&b);
}

/* Rays leaving from points on the triangles of a height grid, as bounce
 * rays do, a third of them grazing the surface: the triangle a ray leaves
 * from lies at t near 0, just behind the origin, just in front of it or
 * through it, where only the rounding-error bound of the triangle test
 * turns it away, and its neighbours' hits are close.  The walk must
 * return brute force's nearest hit, bit for bit, and any-hit queries must
 * agree with it, with and without the ray's own triangle skipped, through
 * every walk this processor runs. */
static void from_surfaces(void)
{
    int def = trace_walk();
    for (int k = 0; k < TRACE_WALKS; k++) {
        if (!(trace_walks() >> k & 1))
            continue;
        trace_set_walk(k);
        const char *name = trace_walk_name(k);
        fr_builder b;
        start(&b);
        grid(&b, 40);
        fr_scene s;
        if (freeze(&b, &s, "from surfaces") < 0)
            continue;
        int rays = 6000, bad = 0, badany = 0, hits = 0, own = 0;
        for (int i = 0; i < rays; i++) {
            uint32_t p = rnd_u32() % s.n_prims;
            const fr_triangle *t = &s.triangles[s.prims[p].index];
            vec3 p0 = s.positions[t->v[0]], e1 = v3_sub(s.positions[t->v[1]], p0), e2 = v3_sub(s.positions[t->v[2]], p0);
            float u = rnd(), v = rnd();
            if (u + v > 1.0f) {
                u = 1.0f - u;
                v = 1.0f - v;
            }
            fr_ray r;
            r.o = v3_add(p0, v3_add(v3_scale(e1, u), v3_scale(e2, v)));
            /* A third of the rays graze the surface (a tenth of a radian
             * or less from its plane), on either side. */
            vec3 n = v3_norm(v3_cross(e1, e2)), d = rnd_dir();
            if (i % 3 == 0)
                d = v3_norm(v3_add(v3_sub(d, v3_scale(n, v3_dot(d, n))), v3_scale(n, rnd_in(-0.1f, 0.1f))));
            r.d = d;
            fr_hit hb = {0}, ht = {0};
            int fb = brute(&s, &r, INFINITY, FR_NONE, &hb), ft = trace_closest(&s, &r, INFINITY, &ht);
            hits += fb;
            own += fb && hb.prim == p;
            if (fb != ft || (fb && (ht.prim != hb.prim || !same_bits(ht.t, hb.t) || !same_bits(ht.a, hb.a) ||
                                    !same_bits(ht.b, hb.b)))) {
                if (bad++ < 5)
                    CHECK(0, "from surfaces (%s) ray %d from prim %u: bvh %d prim %u t %.9g, brute %d prim %u t %.9g",
                          name, i, p, ft, ft ? ht.prim : 0, ft ? (double)ht.t : 0.0, fb, fb ? hb.prim : 0,
                          fb ? (double)hb.t : 0.0);
            }
            if (trace_occluded(&s, &r, INFINITY, FR_NONE) != fb && badany++ < 5)
                CHECK(0, "from surfaces (%s) ray %d: any-hit %d, nearest hit %d", name, i, !fb, fb);
            if (trace_occluded(&s, &r, INFINITY, p) != brute(&s, &r, INFINITY, p, &hb) && badany++ < 5)
                CHECK(0, "from surfaces (%s) ray %d: any-hit skipping its own triangle disagrees", name, i);
        }
        CHECK(bad == 0, "from surfaces (%s): %d of %d rays differ from brute force", name, bad, rays);
        CHECK(badany == 0, "from surfaces (%s): %d any-hit disagreements", name, badany);
        /* Some rays hit another slope, few or none their own triangle. */
        CHECK(hits > rays / 20 && hits < rays - rays / 20, "from surfaces (%s): %d of %d rays hit (test too weak)",
              name, hits, rays);
        CHECK(own < rays / 100, "from surfaces (%s): %d rays hit the triangle they leave from", name, own);
        scn_free(&s);
        bld_free(&b);
    }
    trace_set_walk(def);
}

int main(void)
{
    signed_zeros();
    reinsert_contract();
    reinsertion("reinsertion, soup", 0, 3000, 0.0);
    reinsertion("reinsertion, grid", 1, 60, 0.0);
    reinsertion("reinsertion, slivers", 2, 4000, 0.03);
    reinsertion("reinsertion, nested", 3, 120, 0.0);
    reinsertion("reinsertion, crossing slivers", 4, 8000, 0.015);
    reinsertion("reinsertion, slivers, sheets and soup", 5, 2000, 0.005);

    struct { const char *name; int n; int rays; } cases[] = {
        {"small soup", 1, 2000},     {"soup", 3000, 4000},    {"large triangles", 400, 3000},
        {"grid", 40, 4000},          {"sheets", 600, 4000},   {"degenerate", 300, 2000},
        {"copies", 200, 1000},       {"mixed", 800, 3000},    {"mixed soup", 1500, 3000},
        {"slivers", 2000, 4000},     {"slivers and sheets", 600, 4000}, {"nested", 120, 2000},
        {"nested among spheres", 120, 2000},
    };
    /* Every case through every walk this processor runs (the portable one
     * everywhere; on x86-64 the AVX2 one and the AVX-512 one where the
     * processor and its OS have them). */
    unsigned walks = trace_walks();
    CHECK(walks & (1u << TRACE_WALK_PORTABLE), "the portable walk is not available");
    CHECK((walks >> trace_walk()) & 1, "the walk in use (%s) is not available", trace_walk_name(trace_walk()));
    CHECK(trace_walk() == 31 - __builtin_clz(walks), "the default walk is %s, not the fastest available",
          trace_walk_name(trace_walk()));
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
    __builtin_cpu_init();
    CHECK(!(walks >> TRACE_WALK_AVX2 & 1) == !__builtin_cpu_supports("avx2"), "the AVX2 walk is %s on a processor %s AVX2",
          walks >> TRACE_WALK_AVX2 & 1 ? "available" : "not available", __builtin_cpu_supports("avx2") ? "with" : "without");
    int v4 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
    CHECK(!(walks >> TRACE_WALK_AVX512 & 1) == !v4, "the AVX-512 walk is %s on a processor %s AVX-512 F/VL/BW/DQ",
          walks >> TRACE_WALK_AVX512 & 1 ? "available" : "not available", v4 ? "with" : "without");
#endif
    int def = trace_walk();
    size_t ncases = sizeof cases / sizeof cases[0];
    for (size_t c = 0; c < TRACE_WALKS * ncases; c++) {
        size_t cs = c % ncases;
        int k = (int)(c / ncases);
        if (!(walks >> k & 1))
            continue;
        trace_set_walk(k);
        fr_builder b[2];
        uint64_t seed = rng_state;
        for (int k = 0; k < 2; k++) {
            rng_state = seed;
            start(&b[k]);
            switch (cs) {
            case 0: soup(&b[k], 1, 0.5f); break;
            case 1: soup(&b[k], cases[cs].n, 0.05f); break;
            case 2: soup(&b[k], cases[cs].n, 0.8f); break;
            case 3: grid(&b[k], cases[cs].n); break;
            case 4: sheets(&b[k], cases[cs].n); break;
            case 5: degenerate(&b[k], cases[cs].n); soup(&b[k], 200, 0.1f); break;
            case 6: copies(&b[k], cases[cs].n); soup(&b[k], 20, 0.1f); break;
            case 7: others(&b[k], cases[cs].n); break;
            case 8: others(&b[k], 100); soup(&b[k], cases[cs].n, 0.1f); degenerate(&b[k], 50); grid(&b[k], 10); break;
            case 9: slivers(&b[k], cases[cs].n); break;
            case 11: nested(&b[k], cases[cs].n); soup(&b[k], 100, 0.1f); break;
            case 12: nested_mixed(&b[k], cases[cs].n); soup(&b[k], 100, 0.1f); break;
            default: slivers(&b[k], cases[cs].n); sheets(&b[k], 200); copies(&b[k], 30); others(&b[k], 40); break;
            }
        }
        char name[96];
        snprintf(name, sizeof name, "%s (%s walk)", cases[cs].name, trace_walk_name(k));
        compare(name, &b[0], &b[1], cases[cs].rays, cs == 9);
        bld_free(&b[0]);
        bld_free(&b[1]);
    }
    trace_set_walk(def);
    mixed_leaves();
    from_surfaces();
    return check_done();
}
