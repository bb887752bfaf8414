/* test_fbin.c -- the binary scene loader refuses every damaged file with a
 * message naming the place, and accepts what the builder wrote.
 *
 * Damage comes in two kinds: bytes changed behind the hash's back (caught
 * by the header checks or the hash), and files rewritten with a correct
 * hash but broken contents (caught by the structural checks, which are what
 * stands between a hostile file and the renderer's unchecked indexing). */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "bvh.h"
#include "check.h"
#include "fbin.h"
#include "compile/freeze.h"
#include "pathtrace.h"
#include "pfmmap.h"
#include "scenes.h"

static const char *scene_json =
    "{\"image\": {\"width\": 32, \"height\": 24, \"spp\": 2},"
    " \"camera\": {\"position\": [0, 1, -4], \"target\": [0, 0.5, 0], \"fov\": 50},"
    " \"materials\": {\"w\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]},"
    "                \"l\": {\"type\": \"emitter\", \"emission\": [5, 5, 5]}},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [10, 10, 10]}],"
    " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.5, \"material\": \"w\"},"
    "  {\"type\": \"rect\", \"origin\": [-0.5, 2, -0.5], \"edge_u\": [1, 0, 0], \"edge_v\": [0, 0, 1],"
    "   \"material\": \"l\"},"
    "  {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"w\"},"
    "  {\"type\": \"triangle\", \"vertices\": [[-2, 0, 1], [2, 0, 1], [0, 2, 1]], \"material\": \"w\"},"
    "  {\"type\": \"triangle\", \"vertices\": [[-2, 0, 2], [2, 0, 2], [0, 2, 2]], \"material\": \"w\"},"
    "  {\"type\": \"quad\", \"vertices\": [[-1, 0, 3], [1, 0, 3], [1, 1.5, 3], [-1, 1, 3]], \"material\": \"w\"}]}";

static fr_scene good;          /* the reference scene (owns its blob) */

/* A 16-byte-aligned copy of the good blob. */
static unsigned char *copy_blob(void)
{
    unsigned char *p = aligned_alloc(64, (good.blob_size + 63) / 64 * 64);
    memcpy(p, good.blob, good.blob_size);
    return p;
}

static void put32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void put64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static uint64_t get64(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }

static void rehash(unsigned char *p, size_t size) { put64(p + 32, XXH3_64bits(p + 64, size - 64)); }

/* Offset of section `id`'s data, from the table. */
static size_t section(const unsigned char *p, int id) { return (size_t)get64(p + 64 + 32 * (id - 1) + 8); }

/* Opening `p` (size bytes) must fail with a message containing every
 * string in want (NULL-terminated). */
static void refuse(const char *what, unsigned char *p, size_t size, const char *const *want)
{
    fr_scene s;
    fr_error err = {{0}};
    int rc = fbin_open_mem(p, size, 0, &s, &err);
    CHECK(rc < 0, "%s: accepted", what);
    if (rc == 0) {
        memset(&s, 0, sizeof s);   /* s points into p, which the caller frees */
        return;
    }
    for (int i = 0; want[i]; i++)
        CHECK(strstr(err.msg, want[i]) != NULL, "%s: message \"%s\" lacks \"%s\"", what, err.msg, want[i]);
}

#define REFUSE(what, p, size, ...)                                     \
    do {                                                               \
        const char *const want_[] = {__VA_ARGS__, NULL};              \
        refuse(what, p, size, want_);                                  \
    } while (0)

static void test_roundtrip(void)
{
    unsigned char *p = copy_blob();
    fr_scene s;
    fr_error err;
    CHECK(fbin_open_mem(p, good.blob_size, 0, &s, &err) == 0, "reopen: %s", err.msg);
    CHECK(s.hash == good.hash && s.n_prims == good.n_prims && s.n_nodes == good.n_nodes, "reopen differs");
    scn_free(&s);   /* frees p */

    char path[] = "/tmp/franja-test-fbin-XXXXXX";
    int fd = mkstemp(path);
    close(fd);
    CHECK(fbin_write(&good, path, &err) == 0, "write: %s", err.msg);
    CHECK(fbin_load(path, &s, &err) == 0, "load: %s", err.msg);
    CHECK(s.mapped && s.hash == good.hash && s.blob_size == good.blob_size, "loaded scene differs");
    scn_free(&s);
    /* Files that are not scenes: named in the message. */
    FILE *f = fopen(path, "wb");
    fclose(f);
    CHECK(fbin_load(path, &s, &err) < 0 && strstr(err.msg, path), "empty file accepted or unnamed: %s", err.msg);
    unlink(path);
    CHECK(fbin_load(path, &s, &err) < 0 && strstr(err.msg, path), "missing file: %s", err.msg);
    CHECK(fbin_load("/tmp", &s, &err) < 0 && strstr(err.msg, "/tmp"), "directory accepted: %s", err.msg);
}

static void test_header(void)
{
    size_t n = good.blob_size;
    unsigned char *p = copy_blob();
    size_t cuts[] = {0, 10, 63, 64, 100, n / 2, n - 64, n - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        char what[64];
        snprintf(what, sizeof what, "truncated to %zu bytes", cuts[i]);
        if (cuts[i] < 64)
            REFUSE(what, p, cuts[i], "shorter than the 64-byte header");
        else
            REFUSE(what, p, cuts[i], "byte 24", "truncated");
    }
    p[1] = 'X';
    REFUSE("bad magic", p, n, "byte 0", "magic");
    memcpy(p, good.blob, n);
    put32(p + 8, FBIN_VERSION + 1);
    REFUSE("newer version", p, n, "byte 8", "version");
    put32(p + 8, FBIN_VERSION - 1);
    REFUSE("older version", p, n, "byte 8", "version");
    memcpy(p, good.blob, n);
    put32(p + 12, 0x04030201u);
    REFUSE("byte order", p, n, "byte 12", "byte order");
    memcpy(p, good.blob, n);
    p[50] = 1;
    REFUSE("reserved byte", p, n, "byte 50", "reserved");
    memcpy(p, good.blob, n);
    p[n - 100] ^= 0x10;
    REFUSE("flipped bit", p, n, "byte 32", "hash");
    memcpy(p, good.blob, n);
    put64(p + 32, get64(p + 32) + 1);
    REFUSE("wrong hash", p, n, "hash");
    memcpy(p, good.blob, n);
    CHECK(fbin_open_mem(p + 1, n - 1, 0, &(fr_scene){0}, &(fr_error){{0}}) < 0, "misaligned bytes accepted");
    free(p);
}

static void test_table(void)
{
    size_t n = good.blob_size;
    unsigned char *p = copy_blob();
    size_t e = 64 + 32 * 6;   /* entry of section 7, triangles */
    put32(p + e + 4, 20);
    rehash(p, n);
    REFUSE("element size", p, n, "byte 256", "triangles", "element size");
    memcpy(p, good.blob, n);
    put64(p + e + 8, get64(p + e + 8) + 4);
    rehash(p, n);
    REFUSE("misaligned section", p, n, "byte 256", "triangles");
    memcpy(p, good.blob, n);
    put64(p + e + 16, 1u << 30);
    put64(p + e + 24, (uint64_t)16 << 30);
    rehash(p, n);
    REFUSE("count past the end", p, n, "byte 256", "triangles", "out of bounds");
    memcpy(p, good.blob, n);
    put64(p + e + 8, get64(p + 64 + 32 * 5 + 8));   /* on top of rects */
    rehash(p, n);
    REFUSE("overlapping sections", p, n, "triangles", "overlapping");
    memcpy(p, good.blob, n);
    put32(p + e, 9);
    rehash(p, n);
    REFUSE("section id", p, n, "byte 256", "id 9");
    memcpy(p, good.blob, n);
    put64(p + 64 + 16, 2);   /* settings: count must be 1 */
    rehash(p, n);
    REFUSE("settings count", p, n, "settings");
    free(p);
}

/* Rewrite one u32 at `off` and fix the hash: a well-formed file with bad
 * contents, refused by section `sec` at byte `at` (the field itself unless
 * the check is about a whole element). */
static void poke_at(const char *what, size_t off, uint32_t v, const char *sec, size_t where)
{
    unsigned char *p = copy_blob();
    put32(p + off, v);
    rehash(p, good.blob_size);
    char at[32];
    snprintf(at, sizeof at, "byte %zu:", where);
    REFUSE(what, p, good.blob_size, sec, at);
    free(p);
}

static void poke(const char *what, size_t off, uint32_t v, const char *sec) { poke_at(what, off, v, sec, off); }

static void test_contents(void)
{
    const unsigned char *g = good.blob;
    size_t tri = section(g, 7), prim = section(g, 4), node = section(g, 13), leaf = section(g, 14);
    poke("vertex index", tri + 4, 1000000, "section triangles");
    poke("triangle flags", tri + 12, 8, "section triangles");
    poke("prim kind", prim, 7, "section prims");
    poke("prim index", prim + 4, 5000, "section prims");
    poke("prim material", prim + 8, 99, "section prims");
    poke("prim light", prim + 12, 42, "section prims");
    /* Node 0: its slots, boxes, children and leaf words. */
    poke("leaf bad bits", node + 224, 0x1201, "section nodes");
    poke("leaf blocks past the end", node + 192, good.n_leaves, "section nodes");
    float nan = NAN, big = 1e30f, inf = INFINITY;
    uint32_t u;
    memcpy(&u, &nan, 4);
    poke("NaN box", node, u, "section nodes");
    memcpy(&u, &big, 4);
    poke("inverted box", node, u, "section nodes");
    /* An empty slot must have the empty box. */
    int empty = -1;
    for (int k = 0; k < FR_BVH_WIDTH; k++)
        if (good.nodes[0].child[k] == FR_NONE)
            empty = k;
    CHECK(empty >= 0, "node 0 has no empty slot (test scene too big)");
    if (empty >= 0) {
        memcpy(&u, &inf, 4);
        poke_at("empty slot with a box", node + 4 * 3 * FR_BVH_WIDTH + 4 * (size_t)empty, 0, "section nodes",
                node + 4 * 6 * FR_BVH_WIDTH + 4 * (size_t)empty);
    }
    /* Leaf blocks. */
    poke("lane 0 unused", leaf + 144, FR_NONE, "section leaves");
    poke("primitive past the end", leaf + 144, good.n_prims, "section leaves");
    /* A lane's vertex copies must be its triangle's, bit for bit; unused
     * lanes only end a block. */
    int tlane = -1;
    uint32_t tb = 0;
    for (uint32_t j = 0; j < good.n_leaves && tlane < 0; j++)
        for (int lane = 0; lane < 4 && tlane < 0; lane++)
            if (good.leaves[j].prim[lane] != FR_NONE &&
                good.prims[good.leaves[j].prim[lane]].kind == FR_PRIM_TRIANGLE) {
                tlane = lane;
                tb = j;
            }
    CHECK(tlane >= 0, "no leaf block holds a triangle (test scene changed?)");
    if (tlane >= 0) {
        size_t at = leaf + 160 * (size_t)tb + 16 * 4 + 4 * (size_t)tlane;   /* vertex 1, y */
        float y = good.leaves[tb].v[4][tlane], moved = y + 0.25f, nz = -0.0f;
        memcpy(&u, &moved, 4);
        poke_at("vertex copy differs from its triangle", at, u, "section leaves", at);
        if (y == 0.0f) {   /* -0 for 0: equal as floats, not as copies */
            memcpy(&u, &nz, 4);
            poke_at("vertex copy with another zero", at, u, "section leaves", at);
        }
    }
    if (good.leaves[0].prim[2] != FR_NONE)
        poke("unused lane before a used one", leaf + 144 + 4, FR_NONE, "section leaves");
    memcpy(&u, &inf, 4);
    poke("infinite vertex", leaf + 8, u, "section leaves");
    /* Lights and materials. */
    size_t light = section(g, 12), mat = section(g, 3);
    poke("light kind", light, 9, "section lights");
    poke("material texture", mat + 88, 3, "section materials");
    /* The microfacet fields (offsets as in FORMAT.md); errors name the
     * material's model field, or its first texture index. */
    size_t model = mat + 132;
    poke_at("material model", model, FR_MAT_MODELS, "section materials", model);
    poke_at("material flags", mat + 136, FR_MF_ALL + 1, "section materials", model);
    poke_at("material Fresnel mode", mat + 140, FR_FRESNEL_MODES, "section materials", model);
    float two = 2.0f, minus = -0.5f;
    memcpy(&u, &two, 4);
    poke_at("material roughness", mat + 144, u, "section materials", model);
    poke_at("material anisotropy", mat + 148, u, "section materials", model);
    memcpy(&u, &minus, 4);
    poke_at("material metallic", mat + 152, u, "section materials", model);
    poke_at("material transmission", mat + 156, u, "section materials", model);
    memcpy(&u, &nan, 4);
    poke_at("material eta", mat + 160, u, "section materials", model);
    poke_at("material fresnel_avg", mat + 184, u, "section materials", model);
    poke_at("material roughness texture", mat + 196, 3, "section materials", mat + 88);
    poke_at("material metallic texture", mat + 200, 3, "section materials", mat + 88);
    memcpy(&u, &nan, 4);
    poke("camera NaN", section(g, 2), u, "section camera");
    poke("settings width", section(g, 1), 0, "section settings");
}

/* The lights and the world of a scene with every kind of light and an
 * environment map: damaged values are refused, naming the section. */
static void test_lights(void)
{
    char dir[] = "/tmp/franja-fbinXXXXXX", path[256], file[256];
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    snprintf(path, sizeof path, "%s/m.pfm", dir);
    snprintf(file, sizeof file, "%s/s.json", dir);
    float map[4 * 2 * 3];
    for (int i = 0; i < 24; i++)
        map[i] = 0.1f * (float)(i + 1);
    CHECK(pfm_write(path, 4, 2, map) == 0, "write %s", path);
    fr_scene lit;
    test_scene_with(
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0],"
        " \"fov\": 40}, \"materials\": {\"g\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
        " \"textures\": {\"m\": {\"type\": \"image\", \"file\": \"m.pfm\"}}, \"environment\": {\"color\": \"m\"},"
        " \"lights\": [{\"type\": \"spot\", \"position\": [0, 3, 0], \"direction\": [0, -1, 0], \"intensity\": [5, 5, 5]},"
        "  {\"type\": \"sun\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1], \"angle\": 1}],"
        " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"g\"}]}",
        file, &pfm_hooks, &lit);
    unlink(path);
    rmdir(dir);
    CHECK(lit.n_lights == 3 && lit.lights[0].kind == FR_LIGHT_ENV && lit.lights[1].kind == FR_LIGHT_SUN &&
              lit.lights[2].kind == FR_LIGHT_SPOT && lit.world.env_light == 0,
          "lights not in the order environment, sun, spot");
    CHECK(lit.n_distrib == 4 * 2 + 3 + 2 * 5, "environment tables: %u values", lit.n_distrib);
    fr_scene keep = good;
    good = lit;
    const unsigned char *g = good.blob;
    size_t light = section(g, 12), world = section(g, 20), dist = section(g, 21);
    float neg = -1.0f, half = 0.5f, two = 2.0f;
    uint32_t u;
    memcpy(&u, &neg, 4);
    poke_at("world radius", world + 12, u, "section world", world);
    poke_at("environment light index", world + 20, 2, "section world", world + 20);
    poke_at("environment kind", world + 16, 7, "section world", world);
    poke_at("environment texture", world + 24, 5, "section world", world + 24);
    memcpy(&u, &two, 4);
    poke_at("rotation not a rotation", world + 44, u, "section world", world);
    memcpy(&u, &neg, 4);
    poke_at("negative density", dist + 4, u, "section distrib", dist + 4);
    memcpy(&u, &half, 4);
    poke_at("row table not ending at 1", dist + 4 * (8 + 2), u, "section distrib", dist + 4 * 8);
    poke_at("column table not increasing", dist + 4 * (8 + 3 + 1), u, "section distrib", dist + 4 * (8 + 3));
    /* Sun and spot swap kinds: the spot's fields make a valid sun, after a local light. */
    unsigned char *p = copy_blob();
    put32(p + light + 64, FR_LIGHT_POINT);
    put32(p + light + 2 * 64, FR_LIGHT_SUN);
    rehash(p, good.blob_size);
    char at[32];
    snprintf(at, sizeof at, "byte %zu:", light + 2 * 64);
    REFUSE("a distant light after a local one", p, good.blob_size, "section lights", at, "after a local");
    free(p);
    poke_at("spot cone inverted", light + 2 * 64 + 52, u, "section lights", light + 2 * 64);
    poke_at("sun axis not unit", light + 64 + 32, u, "section lights", light + 64);
    poke_at("second environment", light + 64, FR_LIGHT_ENV, "section lights", light + 64);
    poke_at("light kind", light + 64, 9, "section lights", light + 64);
    /* The second light's cumulative pick probability below the first's
     * (lgt_pick's binary search needs them in order). */
    poke_at("cumulative pick probability decreasing", light + 64 + 60, 0, "section lights", light + 64);
    good = keep;
    scn_free(&lit);
}

/* A BVH written by hand (through fbin_serialize, so the hash is right). */
static int open_with_bvh(const fr_bvh_node *nodes, uint32_t n_nodes, const fr_bvh_leaf *leaves, uint32_t n_leaves,
                         fr_error *err)
{
    fr_scene view = good;
    view.nodes = nodes;
    view.n_nodes = n_nodes;
    view.leaves = leaves;
    view.n_leaves = n_leaves;
    void *blob;
    size_t size;
    if (fbin_serialize(&view, &blob, &size, err) < 0)
        return -1;
    fr_scene s;
    int rc = fbin_open_mem(blob, size, 0, &s, err);
    if (rc == 0)
        scn_free(&s);
    else
        free(blob);
    return rc;
}

static fr_bvh_node empty_node(void)
{
    fr_bvh_node n;
    for (int k = 0; k < FR_BVH_WIDTH; k++) {
        for (int a = 0; a < 3; a++) {
            n.box[a][k] = INFINITY;
            n.box[3 + a][k] = -INFINITY;
        }
        n.child[k] = FR_NONE;
        n.leaf[k] = 0;
    }
    return n;
}

static void set_slot(fr_bvh_node *n, int k, uint32_t child, uint32_t leaf)
{
    for (int a = 0; a < 3; a++) {
        n->box[a][k] = -10.0f;
        n->box[3 + a][k] = 10.0f;
    }
    n->child[k] = child;
    n->leaf[k] = leaf;
}

/* Lane `lane` of block L holds primitive p's vertices (none if not a triangle). */
static void copy_vertices(fr_bvh_leaf *L, uint32_t lane, uint32_t p)
{
    if (good.prims[p].kind != FR_PRIM_TRIANGLE)
        return;
    const fr_triangle *t = &good.triangles[good.prims[p].index];
    for (int v = 0; v < 3; v++) {
        vec3 q = good.positions[t->v[v]];
        L->v[3 * v][lane] = q.x;
        L->v[3 * v + 1][lane] = q.y;
        L->v[3 * v + 2][lane] = q.z;
    }
}

static void test_shapes(void)
{
    /* One leaf with all of the good scene's primitives (mixed: spheres and
     * rects), hung at the bottom of a chain of `depth` nodes. */
    uint32_t np = good.n_prims, nblk = (np + 3) / 4;
    fr_bvh_leaf *blocks = calloc(nblk + 1, sizeof *blocks);
    for (uint32_t i = 0; i < 4 * nblk; i++) {
        blocks[i / 4].prim[i % 4] = i < np ? i : FR_NONE;
        if (i < np)
            copy_vertices(&blocks[i / 4], i % 4, i);
    }
    int depths[] = {1, 2, 63, 64, 65, 90};
    fr_bvh_node chain[100];
    fr_error err;
    for (size_t d = 0; d < sizeof depths / sizeof depths[0]; d++) {
        int n = depths[d];
        for (int i = 0; i < n; i++) {
            chain[i] = empty_node();
            if (i + 1 < n)
                set_slot(&chain[i], 0, (uint32_t)i + 1, 0);
            else
                set_slot(&chain[i], 0, 0, nblk | FR_BVH_MIXED);
        }
        int rc = open_with_bvh(chain, (uint32_t)n, blocks, nblk, &err);
        if (n <= 64)
            CHECK(rc == 0, "chain of %d nodes refused: %s", n, err.msg);
        else
            CHECK(rc < 0 && strstr(err.msg, "deeper than 64") && strstr(err.msg, "section nodes"),
                  "chain of %d nodes: %s", n, rc < 0 ? err.msg : "accepted");
    }
    /* A primitive may be in several lanes (a spatial split puts a triangle
     * in each leaf its parts are in): a second leaf holding a triangle
     * again, beside the first, is accepted; with its vertex copies moved it
     * is refused. */
    uint32_t tri = FR_NONE;
    for (uint32_t p = 0; p < np && tri == FR_NONE; p++)
        if (good.prims[p].kind == FR_PRIM_TRIANGLE)
            tri = p;
    CHECK(tri != FR_NONE, "the test scene has no triangle");
    if (tri != FR_NONE) {
        fr_bvh_leaf *twice = &blocks[nblk];
        memset(twice, 0, sizeof *twice);
        twice->prim[0] = tri;
        twice->prim[1] = twice->prim[2] = twice->prim[3] = FR_NONE;
        copy_vertices(twice, 0, tri);
        chain[0] = empty_node();
        set_slot(&chain[0], 0, 0, nblk | FR_BVH_MIXED);
        set_slot(&chain[0], 1, nblk, 1);
        int rc = open_with_bvh(chain, 1, blocks, nblk + 1, &err);
        CHECK(rc == 0, "a triangle in two leaves refused: %s", err.msg);
        twice->v[8][0] += 1.0f;
        rc = open_with_bvh(chain, 1, blocks, nblk + 1, &err);
        CHECK(rc < 0 && strstr(err.msg, "differs from its triangle") && strstr(err.msg, "section leaves"),
              "a second copy with a moved vertex: %s", rc < 0 ? err.msg : "accepted");
    }
    /* Children must come after their parent, inside the array. */
    chain[0] = empty_node();
    set_slot(&chain[0], 0, 0, 0);
    CHECK(open_with_bvh(chain, 1, blocks, nblk, &err) < 0 && strstr(err.msg, "child 0 not in"), "self loop: %s",
          err.msg);
    chain[1] = empty_node();
    set_slot(&chain[0], 0, 1, 0);
    set_slot(&chain[1], 0, 0, 0);
    CHECK(open_with_bvh(chain, 2, blocks, nblk, &err) < 0 && strstr(err.msg, "node 1 slot 0: child 0"), "cycle: %s",
          err.msg);
    set_slot(&chain[0], 0, 7, 0);
    CHECK(open_with_bvh(chain, 2, blocks, nblk, &err) < 0 && strstr(err.msg, "child 7 not in"), "child past the end: %s",
          err.msg);
    /* Not mixed although it holds a sphere. */
    chain[0] = empty_node();
    set_slot(&chain[0], 0, 0, nblk);
    CHECK(open_with_bvh(chain, 1, blocks, nblk, &err) < 0 && strstr(err.msg, "mixed"), "unmarked mixed leaf: %s",
          err.msg);
    /* Two parents for one node; an unreachable node; a block in two leaves;
     * a block in none. */
    chain[0] = empty_node();
    chain[1] = empty_node();
    set_slot(&chain[0], 0, 1, 0);
    set_slot(&chain[0], 1, 1, 0);
    set_slot(&chain[1], 0, 0, nblk | FR_BVH_MIXED);
    CHECK(open_with_bvh(chain, 2, blocks, nblk, &err) < 0 && strstr(err.msg, "two parents"), "DAG: %s", err.msg);
    chain[0] = empty_node();
    set_slot(&chain[0], 0, 0, nblk | FR_BVH_MIXED);
    CHECK(open_with_bvh(chain, 2, blocks, nblk, &err) < 0 && strstr(err.msg, "not reachable"), "orphan: %s",
          err.msg);
    set_slot(&chain[0], 1, 0, 1 | FR_BVH_MIXED);
    CHECK(open_with_bvh(chain, 1, blocks, nblk, &err) < 0 && strstr(err.msg, "two leaves"), "shared block: %s",
          err.msg);
    chain[0] = empty_node();
    set_slot(&chain[0], 0, 0, (nblk - 1) | FR_BVH_MIXED);
    if (nblk > 1)
        CHECK(open_with_bvh(chain, 1, blocks, nblk, &err) < 0 && strstr(err.msg, "no leaf"), "lost block: %s",
              err.msg);
    /* A primitive left out. */
    blocks[nblk - 1].prim[(np - 1) % 4] = FR_NONE;
    set_slot(&chain[0], 0, 0, nblk | FR_BVH_MIXED);
    CHECK(open_with_bvh(chain, 1, blocks, nblk, &err) < 0 && strstr(err.msg, "no BVH leaf"), "lost prim: %s",
          err.msg);
    /* No BVH at all for a scene with primitives. */
    CHECK(open_with_bvh(chain, 0, blocks, 0, &err) < 0 && strstr(err.msg, "no BVH"), "no BVH: %s", err.msg);
    free(blocks);
}

/* A scene whose one material is textured by a 2x2 RGB float image (words
 * 0..11, one mip level) followed by 4 spare words, so a texture may also
 * start later. */
static int textured_scene(fr_scene *out, fr_error *err)
{
    static const char *json =
        "{\"image\": {\"width\": 8, \"height\": 8, \"spp\": 1},"
        " \"camera\": {\"position\": [0, 0, -4], \"target\": [0, 0, 0], \"fov\": 40},"
        " \"textures\": {\"t\": {\"type\": \"checker\", \"colors\": [[1, 1, 1], [0, 0, 0]]}},"
        " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": \"t\"}},"
        " \"lights\": [{\"type\": \"point\", \"position\": [0, 0, -3], \"intensity\": [5, 5, 5]}],"
        " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}]}";
    fr_builder b;
    bld_init(&b);
    int rc = json_scene_parse(json, "(test)", NULL, &b, err);
    if (rc == 0 && b.textures.count != 1)
        rc = fr_fail(err, "%u textures, expected 1", b.textures.count);
    if (rc == 0) {
        fr_texture *t = b.textures.data;
        t->kind = FR_TEX_IMAGE;
        t->width = t->height = 2;
        t->channels = 3;
        t->format = FR_TEXEL_F32;
        t->levels = 1;
        memset(t->first, 0, sizeof t->first);
        for (int i = 0; i < 16 && rc == 0; i++) {
            float v = (float)i / 16.0f;
            if (bld_push(&b.texels, &v) == FR_NONE)
                rc = fr_fail(err, "out of memory");
        }
    }
    if (rc == 0)
        rc = frz_scene(&b, out, err);
    bld_free(&b);
    return rc;
}

/* Image sizes and texel ranges: refused whenever the image does not fit in
 * the texels after `first`, including sizes whose product wraps in 64
 * bits, and accepted when it fits exactly. */
static void test_texture_sizes(void)
{
    fr_scene ts;
    fr_error err;
    if (textured_scene(&ts, &err) < 0) {
        CHECK(0, "textured scene: %s", err.msg);
        return;
    }
    CHECK(ts.n_textures == 1 && ts.n_texels == 16, "textured scene: %u textures, %u texels", ts.n_textures,
          ts.n_texels);
    size_t tex = section(ts.blob, 15);
    /* Fields: width, height, channels, format, levels, first[0], first[1]. */
    static const struct { uint32_t w, h, ch, fmt, lv, first, first1; int ok; const char *what; } cases[] = {
        {2, 2, 3, 0, 1, 0, 0, 1, "the image as written"},
        {4, 4, 1, 0, 1, 0, 0, 1, "grey, all 16 texels"},
        {2, 2, 3, 0, 1, 4, 0, 1, "starting at texel 4, ending at the last"},
        {2, 2, 3, 0, 1, 5, 0, 0, "one texel past the end"},
        {1, 1, 1, 0, 1, 16, 0, 0, "starting at the end"},
        {1, 1, 1, 0, 1, 17, 0, 0, "starting past the end"},
        {1, 1, 1, 0, 1, 0xffffffffu, 0, 0, "starting at 2^32 - 1"},
        {3384208571u, 3633886365u, 3, 0, 1, 0, 0, 0, "w*h*3 wraps to 13 in 64 bits"},
        {4294901763u, 1431677610u, 3, 0, 1, 0, 0, 0, "w*h*3 wraps to 327674 in 64 bits"},
        {0x80000000u, 0x80000000u, 1, 0, 1, 0, 0, 0, "w*h = 2^62"},
        {0xffffffffu, 0xffffffffu, 3, 0, 1, 0, 0, 0, "the largest 32-bit sizes"},
        {16, 0x10000001u, 1, 0, 1, 0, 0, 0, "w*h wraps to 16 in 32 bits"},
        {0, 2, 3, 0, 1, 0, 0, 0, "width 0"},
        {2, 2, 2, 0, 1, 0, 0, 0, "2 channels"},
        {2, 2, 3, FR_TEXEL_FORMATS, 1, 0, 0, 0, "an unknown texel format"},
        {2, 2, 3, 0, 0, 0, 0, 0, "no mip level"},
        {2, 2, 3, 0, 3, 0, 12, 0, "three levels for a 2x2 image"},
        {2, 2, 3, 0, 2, 0, 12, 1, "two levels: 2x2 then 1x1 in the spare words"},
        {2, 2, 3, 0, 2, 0, 14, 0, "a second level past the end"},
        {2, 2, 3, 0, 1, 0, 12, 0, "an offset for a level not stored"},
        {8, 1, 1, FR_TEXEL_U8_SRGB, 4, 0, 2, 1, "8 bytes, then 4, 2 and 1 (levels in words 0, 2, ...)"},
        {68, 1, 1, FR_TEXEL_U8, 1, 0, 0, 0, "68 bytes are 17 words"},
        {32, 1, 1, FR_TEXEL_F16, 1, 0, 0, 1, "32 halves in 16 words"},
        {34, 1, 1, FR_TEXEL_U16, 1, 0, 0, 0, "34 16-bit values are 17 words"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        unsigned char *p = aligned_alloc(64, (ts.blob_size + 63) / 64 * 64);
        memcpy(p, ts.blob, ts.blob_size);
        put32(p + tex + 4, cases[i].w);
        put32(p + tex + 8, cases[i].h);
        put32(p + tex + 12, cases[i].ch);
        put32(p + tex + 16, cases[i].fmt);
        put32(p + tex + 20, cases[i].lv);
        put32(p + tex + 72, cases[i].first);
        put32(p + tex + 76, cases[i].first1);
        if (cases[i].lv == 4)          /* the 8x1 bytes: levels 4x1, 2x1, 1x1 one word each */
            put32(p + tex + 80, 3), put32(p + tex + 84, 4);
        rehash(p, ts.blob_size);
        if (cases[i].ok) {
            fr_scene s;
            int rc = fbin_open_mem(p, ts.blob_size, 0, &s, &err);
            CHECK(rc == 0, "%s: refused: %s", cases[i].what, err.msg);
            if (rc == 0) {
                /* Rendered: every lookup lands in the texels. */
                vec3 c = pt_sample(&s, PT_MIS, 4, 4, 0);
                CHECK(isfinite(c.x) && c.x > 0.0f, "%s: pixel (4, 4) is %g", cases[i].what, c.x);
                scn_free(&s);
            } else {
                free(p);
            }
        } else {
            char at[32];
            snprintf(at, sizeof at, "byte %zu:", tex);
            REFUSE(cases[i].what, p, ts.blob_size, "section textures", at, "texture 0");
            free(p);
        }
    }
    scn_free(&ts);
}

/* The light tree (section 22): each rule of FORMAT.md refuses a file that
 * breaks it, at the field at fault. */
static void test_light_tree(void)
{
    const unsigned char *g = good.blob;
    size_t t = section(g, 22);
    uint32_t n = good.n_light_nodes, root = n - 1;
    CHECK(n >= 1, "test scene: %u light tree nodes", n);
    if (n < 1)
        return;
    float two = 2.0f, neg = -1.0f;
    uint32_t u;
    memcpy(&u, &two, 4);
    poke_at("light node cone cosine above 1", t + 36, u, "section lighttree", t);
    memcpy(&u, &neg, 4);
    poke_at("light node negative power", t + 44, u, "section lighttree", t);
    poke_at("light node unknown flag", t + 60, 2, "section lighttree", t);
    poke_at("leaf with a child", t + 48, 0, "section lighttree", t + 48);
    poke_at("root with a parent", t + 64 * root + 56, 0, "section lighttree", t + 64 * root + 56);
    if (n >= 3)
        poke_at("leaf's parent a leaf", t + 56, 1, "section lighttree", t + 56);
}

/* The objects and light group sections (29 to 32): an object or group
 * past the names, or a count that is not one per element, is refused. */
static void test_objects_groups(void)
{
    fr_scene g;
    test_scene("{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, -5],"
               " \"target\": [0, 0, 0], \"fov\": 40}, \"materials\": {\"g\": {\"type\": \"lambert\","
               " \"albedo\": [0.5, 0.5, 0.5]}}, \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0],"
               " \"intensity\": [5, 5, 5], \"light_group\": \"key\"}],"
               " \"shapes\": [{\"type\": \"sphere\", \"name\": \"ball\", \"center\": [0, 0, 0], \"radius\": 1,"
               " \"material\": \"g\"}, {\"type\": \"plane\", \"point\": [0, -1, 0], \"normal\": [0, 1, 0],"
               " \"material\": \"g\"}]}",
               &g);
    CHECK(g.n_objects == 2 && g.n_object_names == 2 && !strcmp(g.object_names[0].name, "ball") &&
              g.n_light_groups == 1 && g.n_group_names == 2 && !strcmp(g.group_names[1].name, "key"),
          "objects %u (2), names %u (2), light groups %u (1), names %u (2)", g.n_objects, g.n_object_names,
          g.n_light_groups, g.n_group_names);
    size_t n = g.blob_size;
    unsigned char *p = aligned_alloc(64, (n + 63) / 64 * 64);
    memcpy(p, g.blob, n);
    put32(p + section(p, 29) + 4, 2);   /* the plane's object: past the two names */
    rehash(p, n);
    REFUSE("object past the names", p, n, "section objects", "object 2 of 2 names");
    memcpy(p, g.blob, n);
    put32(p + section(p, 31), 5);
    rehash(p, n);
    REFUSE("group past the names", p, n, "section light_groups", "group 5 of 2 names");
    memcpy(p, g.blob, n);
    put64(p + 64 + 32 * 28 + 16, 1);    /* objects: one entry for a prim and a plane */
    rehash(p, n);
    REFUSE("objects count", p, n, "section objects");
    memcpy(p, g.blob, n);
    p[section(p, 30) + 70] = 0x07;      /* a control character in the second name */
    rehash(p, n);
    REFUSE("object name", p, n, "section object_names", "name 1");
    free(p);
    scn_free(&g);
}

int main(void)
{
    test_scene(scene_json, &good);
    CHECK(good.n_prims >= 6 && good.n_nodes >= 1, "test scene: %u prims, %u nodes", good.n_prims, good.n_nodes);
    test_roundtrip();
    test_header();
    test_table();
    test_contents();
    test_shapes();
    test_texture_sizes();
    test_lights();
    test_light_tree();
    test_objects_groups();
    scn_free(&good);
    return check_done();
}
