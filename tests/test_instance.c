/* test_instance.c -- instanced meshes render as their flattened copies.
 *
 * A scene places two meshes (a textured, smooth-shaded torus and a glass
 * one) by rotations, uniform and non-uniform scales and a mirror, and an
 * emissive mesh by two instances; its twin is the same builder flattened
 * (bld_flatten), every instance a copy of its triangles in world space.
 * Rays traced against both hit at the same t (1e-5 relative), with the
 * same material, normal and texture coordinates; the portable and the
 * AVX2 walks agree bit for bit; the images agree within float rounding of
 * the transforms; rows render the same bytes in any split.  A glTF mesh
 * drawn by 12 nodes compiles to one mesh and 12 instances; many instances
 * cost an instance each, not a mesh each; the loader refuses damaged
 * instance sections. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "check.h"
#include "passes.h"
#include "compile/builder_instance.h"
#include "compile/freeze.h"
#include "compile/gltf_scene.h"
#include "compile/json_scene.h"
#include "fbin.h"
#include "fmath.h"
#include "pathtrace.h"
#include "trace.h"

static const char base_json[] =
    "{\"image\": {\"width\": 40, \"height\": 30, \"spp\": 16, \"max_depth\": 6, \"seed\": 3},"
    " \"camera\": {\"position\": [0, 3, -9], \"target\": [0, 0.6, 0], \"fov\": 45},"
    " \"textures\": {\"chk\": {\"type\": \"checker\", \"scale\": 8, \"colors\": [[0.9, 0.9, 0.9],"
    "   [0.2, 0.3, 0.6]]}},"
    " \"materials\": {\"w\": {\"type\": \"lambert\", \"albedo\": \"chk\"},"
    "   \"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
    "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [6, 5, 4]}},"
    " \"lights\": [{\"type\": \"point\", \"position\": [2, 5, -3], \"intensity\": [30, 30, 30]}],"
    " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [-3, 0.5, 1], \"radius\": 0.5, \"material\": \"w\"}]}";

/* Material index by JSON order: chk-textured w = 0, floor 1, glass 2, lamp 3. */
enum { MAT_W = 0, MAT_GLASS = 2, MAT_LAMP = 3 };

/* A torus of radii R, r about +y in its own space, nu x nv quads, with
 * normals and UVs, added as mesh; returns its index. */
static uint32_t torus(fr_builder *b, float R, float r, int nu, int nv, uint32_t mat)
{
    uint32_t m = bld_mesh_begin(b), base = b->positions.count;
    for (int i = 0; i <= nu; i++)
        for (int j = 0; j <= nv; j++) {
            float su, cu, sv, cv;
            fm_sincosf(2.0f * FM_PI * (float)i / (float)nu, &su, &cu);
            fm_sincosf(2.0f * FM_PI * (float)j / (float)nv, &sv, &cv);
            vec3 p = v3((R + r * cv) * cu, r * sv + r, (R + r * cv) * su), n = v3(cv * cu, sv, cv * su);
            vec2 uv = {(float)i / (float)nu, (float)j / (float)nv};
            bld_push(&b->positions, &p);
            bld_pad(&b->normals, base + (uint32_t)(i * (nv + 1) + j));
            bld_push(&b->normals, &n);
            bld_pad(&b->uvs, base + (uint32_t)(i * (nv + 1) + j));
            bld_push(&b->uvs, &uv);
        }
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            uint32_t a = base + (uint32_t)(i * (nv + 1) + j), c = a + (uint32_t)(nv + 1);
            fr_triangle t1 = {{a, a + 1, c + 1}, FR_TRI_NORMALS | FR_TRI_UVS};
            fr_triangle t2 = {{a, c + 1, c}, FR_TRI_NORMALS | FR_TRI_UVS};
            fr_prim p = {FR_PRIM_TRIANGLE, bld_push(&b->triangles, &t1), mat, FR_NONE};
            bld_push(&b->prims, &p);
            p.index = bld_push(&b->triangles, &t2);
            bld_push(&b->prims, &p);
        }
    fr_error e;
    if (bld_mesh_end(b, m, &e) < 0)
        printf("FAIL mesh: %s\n", e.msg);
    return m;
}

/* Rotation by `deg` about unit-ish axis (x, y, z), times scale s (per
 * axis), then translation t. */
static void xform(float xf[3][4], float deg, vec3 axis, vec3 s, vec3 t)
{
    float sn, cs;
    fm_sincosf(deg * (FM_PI / 180.0f), &sn, &cs);
    vec3 a = v3_norm(axis);
    float R[3][3] = {{cs + a.x * a.x * (1 - cs), a.x * a.y * (1 - cs) - a.z * sn, a.x * a.z * (1 - cs) + a.y * sn},
                     {a.y * a.x * (1 - cs) + a.z * sn, cs + a.y * a.y * (1 - cs), a.y * a.z * (1 - cs) - a.x * sn},
                     {a.z * a.x * (1 - cs) - a.y * sn, a.z * a.y * (1 - cs) + a.x * sn, cs + a.z * a.z * (1 - cs)}};
    const float sc[3] = {s.x, s.y, s.z}, tr[3] = {t.x, t.y, t.z};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            xf[i][j] = R[i][j] * sc[j];
        xf[i][3] = tr[i];
    }
}

/* The test scene; `flat`: every instance flattened; `uniform_only`: no
 * non-uniform scale (whose shading normals are interpolated after the
 * transform when flattened, before it when instanced). */
static void build(fr_scene *out, int flat, int uniform_only)
{
    fr_builder b;
    fr_error e;
    bld_init(&b);
    if (json_scene_parse(base_json, "(test)", NULL, &b, &e) < 0) {
        printf("FAIL scene: %s\n", e.msg);
        exit(1);
    }
    uint32_t knot = torus(&b, 0.8f, 0.3f, 48, 24, MAT_W), glass = torus(&b, 0.5f, 0.2f, 24, 12, MAT_GLASS);
    uint32_t lamp = torus(&b, 0.3f, 0.05f, 12, 6, MAT_LAMP);
    float xf[3][4];
    struct { uint32_t mesh; float deg; vec3 axis, s, t; } place[] = {
        {knot, 0.0f, {0, 1, 0}, {1, 1, 1}, {0, 0, 0}},
        {knot, 30.0f, {1, 0.5f, 0}, {0.7f, 0.7f, 0.7f}, {2.2f, 0.8f, 0.5f}},
        {knot, 75.0f, {0, 1, 0.2f}, {-1.1f, 1.1f, 1.1f}, {-2.0f, 0.1f, 0.3f}},   /* mirrored */
        {knot, 10.0f, {0, 0, 1}, {1.4f, 0.6f, 1.0f}, {0.5f, 0.0f, 3.0f}},        /* non-uniform */
        {glass, 20.0f, {1, 0, 0}, {1, 1, 1}, {-0.8f, 0.3f, -2.0f}},
        {glass, -40.0f, {0, 1, 0}, {1.3f, 1.3f, 1.3f}, {1.2f, 0.2f, -2.5f}},
        {lamp, 0.0f, {0, 1, 0}, {1, 1, 1}, {-1.0f, 2.5f, 0.0f}},
        {lamp, 90.0f, {1, 0, 0}, {1, 1, 1}, {1.0f, 2.5f, 0.0f}},
    };
    for (size_t i = 0; i < sizeof place / sizeof place[0]; i++) {
        if (uniform_only && i == 3)
            continue;
        xform(xf, place[i].deg, place[i].axis, place[i].s, place[i].t);
        if (bld_instance(&b, place[i].mesh, (const float(*)[4])xf, &e) < 0)
            printf("FAIL instance: %s\n", e.msg);
    }
    if ((flat && bld_flatten(&b, 1, &e) < 0) || frz_scene(&b, out, &e) < 0) {
        printf("FAIL freeze: %s\n", e.msg);
        exit(1);
    }
    bld_free(&b);
}

static void test_structure(const fr_scene *inst, const fr_scene *flat)
{
    CHECK(inst->n_meshes == 2 && inst->n_instances == 6, "instanced: %u meshes, %u instances, want 2 and 6 (the "
          "emissive mesh flattened)", inst->n_meshes, inst->n_instances);
    CHECK(flat->n_meshes == 0 && flat->n_instances == 0, "flattened: %u meshes, %u instances", flat->n_meshes,
          flat->n_instances);
    CHECK(inst->n_lights == flat->n_lights && inst->n_lights > 1, "lights: %u instanced, %u flattened",
          inst->n_lights, flat->n_lights);
    uint32_t tri = 48 * 24 * 2 + 24 * 12 * 2;
    CHECK(inst->n_triangles < flat->n_triangles && inst->meshes[0].n_prims + inst->meshes[1].n_prims == tri,
          "instanced meshes hold %u + %u triangles, want %u", inst->meshes[0].n_prims, inst->meshes[1].n_prims, tri);
}

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static float rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (float)(rng >> 40) / 16777216.0f;
}

/* Camera rays and rays between random points: the same hits. */
static void test_hits(const fr_scene *inst, const fr_scene *flat)
{
    int n = 0, hits = 0, mismatch = 0, bad_t = 0, bad_n = 0, bad_uv = 0, bad_mat = 0, bad_occ = 0;
    double worst_t = 0.0, worst_abs = 0.0;
    for (int k = 0; k < 20000; k++) {
        fr_ray r;
        if (k < 10000) {
            r.o = inst->camera.position;
            float x = (float)(k % 100) / 100.0f - 0.5f, y = (float)(k / 100) / 100.0f - 0.5f;
            r.d = v3_norm(v3_add(inst->camera.forward, v3_add(v3_scale(inst->camera.right, x * 0.9f),
                                                             v3_scale(inst->camera.upv, y * 0.7f))));
        } else {
            r.o = v3(rnd() * 8.0f - 4.0f, rnd() * 3.0f, rnd() * 8.0f - 4.0f);
            vec3 to = v3(rnd() * 8.0f - 4.0f, rnd() * 3.0f, rnd() * 8.0f - 4.0f);
            r.d = v3_norm(v3_sub(to, r.o));
        }
        fr_hit a, b;
        int ha = trace_closest(inst, &r, INFINITY, &a), hb = trace_closest(flat, &r, INFINITY, &b);
        n++;
        if (trace_occluded(inst, &r, 5.0f, FR_NONE) != trace_occluded(flat, &r, 5.0f, FR_NONE))
            bad_occ++;
        if (ha != hb || (ha && ((a.prim == FR_NONE) != (b.prim == FR_NONE)))) {
            mismatch++;
            continue;
        }
        if (!ha || a.prim == FR_NONE)
            continue;
        hits++;
        /* 1e-5 relative, or 1e-6 absolute for short rays: a few ulps of the
         * coordinates (|x| < 4), by which the two scenes' triangles differ. */
        double dt = fabs((double)a.t - b.t), rel = dt / b.t;
        worst_t = rel > worst_t && b.t > 0.1f ? rel : worst_t;
        worst_abs = dt > worst_abs ? dt : worst_abs;
        if (dt > 1e-5 * b.t + 1e-6) {
            bad_t++;
            continue;
        }
        fr_surface sa, sb;
        trace_surface(inst, &r, &a, &sa);
        trace_surface(flat, &r, &b, &sb);
        bad_mat += sa.material != sb.material;
        bad_n += v3_dot(sa.ng, sb.ng) < 0.9999f;
        bad_uv += fabsf(sa.uv.u - sb.uv.u) > 1e-4f || fabsf(sa.uv.v - sb.uv.v) > 1e-4f;
    }
    printf("  hits: %d rays, %d on instanced or flattened triangles, %d hit/miss mismatches, t differences: worst "
           "%.2g relative (t > 0.1), %.2g absolute\n", n, hits, mismatch, worst_t, worst_abs);
    CHECK(hits > 2000, "only %d rays hit triangles", hits);
    CHECK(mismatch * 1000 <= n, "%d of %d rays hit one scene and not the other", mismatch, n);
    CHECK(bad_t == 0, "%d hits differ in t by more than 1e-5 relative + 1e-6", bad_t);
    CHECK(bad_mat == 0 && bad_n == 0 && bad_uv == 0, "%d materials, %d normals, %d uvs differ", bad_mat, bad_n, bad_uv);
    CHECK(bad_occ * 1000 <= n, "%d shadow rays disagree", bad_occ);
}

/* Every walk this processor runs agrees bit for bit with the portable
 * one on instances too. */
static void test_walks(const fr_scene *s)
{
    int was = trace_walk(), differ = 0, walks = 0;
    for (int w = TRACE_WALK_AVX2; w < TRACE_WALKS; w++) {
        if (!(trace_walks() & (1u << w)))
            continue;
        walks++;
        for (int k = 0; k < 5000; k++) {
            fr_ray r = {v3(rnd() * 8.0f - 4.0f, rnd() * 3.0f, rnd() * 8.0f - 4.0f),
                        v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f)), 0.0f};
            fr_hit a = {0}, b = {0};
            trace_set_walk(w);
            int ha = trace_closest(s, &r, INFINITY, &a);
            trace_set_walk(TRACE_WALK_PORTABLE);
            int hb = trace_closest(s, &r, INFINITY, &b);
            differ += ha != hb || memcmp(&a, &b, sizeof a) != 0;
        }
    }
    trace_set_walk(was);
    printf("  %d wide walks compared with the portable one\n", walks);
    CHECK(differ == 0, "%d rays hit differently in the walks", differ);
}

static float *render(const fr_scene *s, uint32_t y0, uint32_t y1)
{
    float *img = calloc((size_t)s->settings.width * (y1 - y0) * 3, sizeof *img);
    pt_render_rows(s, PT_MIS, y0, y1, img);
    return img;
}

/* The images of the two scenes: means within `tol_mean` relative, and at
 * most 1 % of the values more than `tol` apart (relative to 1 + value). */
static void test_images(const fr_scene *inst, const fr_scene *flat, double tol_mean, double tol)
{
    uint32_t w = inst->settings.width, h = inst->settings.height, n = w * h * 3;
    float *a = render(inst, 0, h), *b = render(flat, 0, h);
    double sa = 0.0, sb = 0.0, worst = 0.0;
    uint32_t differ = 0;
    for (uint32_t i = 0; i < n; i++) {
        sa += a[i];
        sb += b[i];
        double d = fabs((double)a[i] - b[i]) / (1.0 + b[i]);
        worst = d > worst ? d : worst;
        differ += d > tol;
    }
    printf("  images (%s): %ux%u, %u spp: means %.6f and %.6f, %u of %u values differ by more than %.0e "
           "(relative to 1 + value), worst %.3g\n", inst->n_instances == 6 ? "with a non-uniform scale" : "rigid, "
           "uniform scales, a mirror", w, h, inst->settings.spp, sa / n, sb / n, differ, n, tol, worst);
    CHECK(fabs(sa - sb) <= tol_mean * sb, "means differ: %.6f and %.6f", sa / n, sb / n);
    CHECK(differ * 100 <= n, "%u of %u values differ by more than %g", differ, n, tol);
    /* Split invariance: rows 0:h and two halves, byte for byte. */
    float *top = render(inst, 0, h / 3), *rest = render(inst, h / 3, h);
    size_t cut = (size_t)w * (h / 3) * 3;
    CHECK(memcmp(top, a, cut * sizeof *a) == 0 && memcmp(rest, a + cut, (n - cut) * sizeof *a) == 0,
          "rows 0:%u and %u:%u differ from the full image", h / 3, h / 3, h);
    free(a);
    free(b);
    free(top);
    free(rest);
}

/* ---- the loader ---- */

static void put32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static uint64_t get64(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }
static size_t section(const unsigned char *p, int id) { return (size_t)get64(p + 64 + 32 * (id - 1) + 8); }
enum { SEC_PRIMS = 4, SEC_MESHES = 22, SEC_INSTANCES = 23, SEC_MESH_NODES = 24, SEC_MESH_LEAVES = 25 };

/* Rewrite a u32 at `off`, fix the hash, and expect a refusal naming `want`. */
static void poke(const fr_scene *good, const char *what, size_t off, uint32_t v, const char *want)
{
    unsigned char *p = aligned_alloc(64, (good->blob_size + 63) / 64 * 64);
    memcpy(p, good->blob, good->blob_size);
    put32(p + off, v);
    uint64_t h = XXH3_64bits(p + 64, good->blob_size - 64);
    memcpy(p + 32, &h, 8);
    fr_scene s;
    fr_error e = {{0}};
    int rc = fbin_open_mem(p, good->blob_size, 0, &s, &e);
    CHECK(rc < 0, "%s: accepted", what);
    CHECK(rc == 0 || strstr(e.msg, want), "%s: message \"%s\" lacks \"%s\"", what, e.msg, want);
    free(p);
}

static void test_loader(const fr_scene *s)
{
    const unsigned char *g = s->blob;
    size_t mesh = section(g, SEC_MESHES), inst = section(g, SEC_INSTANCES), prim = section(g, SEC_PRIMS);
    size_t mn = section(g, SEC_MESH_NODES), ml = section(g, SEC_MESH_LEAVES);
    float nan = NAN, big = 1e31f;
    uint32_t nanbits, bigbits, twobits;
    float two = 2.0f;
    memcpy(&nanbits, &nan, 4);
    memcpy(&bigbits, &big, 4);
    memcpy(&twobits, &two, 4);
    poke(s, "instance mesh", inst + 96, s->n_meshes, "section instances");
    poke(s, "instance pad", inst + 100, 1, "section instances");
    poke(s, "transform NaN", inst + 4, nanbits, "not finite");
    poke(s, "transform huge", inst + 12, bigbits, "not finite");
    poke(s, "inverse wrong", inst + 48, twobits, "inverse");
    poke(s, "mesh node count", mesh + 4, s->meshes[0].n_nodes + 1, "section meshes");
    poke(s, "mesh leaf start", mesh + 8, 1, "section meshes");
    poke(s, "mesh prim start", mesh + 16, s->meshes[0].prim_first - 1, "section meshes");
    poke(s, "mesh prim count", mesh + 20, 0, "section meshes");
    poke(s, "second mesh overlaps", mesh + 32 + 16, s->meshes[0].prim_first, "section meshes");
    /* The first instance prim of the scene's tree, and a mesh's prim. */
    uint32_t ip = 0;
    while (ip < s->n_prims && s->prims[ip].kind != FR_PRIM_INSTANCE)
        ip++;
    poke(s, "instance index", prim + 16 * ip + 4, s->n_instances, "section prims");
    poke(s, "instance as light", prim + 16 * ip + 12, 0, "section prims");
    size_t mp = prim + 16 * (size_t)s->meshes[0].prim_first;
    poke(s, "mesh prim kind", mp, FR_PRIM_SPHERE, "section prims");
    poke(s, "mesh prim light", mp + 12, 0, "section prims");
    /* The mesh's tree: a lane outside its range, a child past its nodes,
     * a mixed leaf. */
    poke(s, "mesh lane", ml + 144, 0, "mesh 0");
    poke(s, "mesh lane past", ml + 144, s->meshes[1].prim_first, "mesh 0");
    uint32_t slot = 0;
    const fr_bvh_node *root = &s->mesh_nodes[0];
    while (slot < 8 && root->leaf[slot] == 0)
        slot++;
    if (slot < 8)
        poke(s, "mesh mixed leaf", mn + 224 + 4 * slot, root->leaf[slot] | FR_BVH_MIXED, "triangles only");
    poke(s, "mesh child", mn + 192, s->meshes[0].n_nodes + 5, "mesh 0");
}

/* ---- glTF: one mesh drawn by 12 nodes ---- */

static void b64(const unsigned char *p, size_t n, char *out)
{
    static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)p[i] << 16 | (i + 1 < n ? (unsigned)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        out[o++] = a[v >> 18 & 63];
        out[o++] = a[v >> 12 & 63];
        out[o++] = i + 1 < n ? a[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? a[v & 63] : '=';
    }
    out[o] = 0;
}

/* A glTF document: a grid of g x g quads drawn by `nodes` nodes (each its
 * own mesh when `copies`, else all the same mesh); its fr_scene's size. */
static size_t gltf_size(int nodes, int copies, fr_scene *out)
{
    enum { G = 30 };
    static float pos[(G + 1) * (G + 1) * 3];
    static uint32_t idx[G * G * 6];
    for (int i = 0; i <= G; i++)
        for (int j = 0; j <= G; j++) {
            float *p = pos + 3 * (i * (G + 1) + j);
            p[0] = (float)i / G;
            p[1] = 0.1f * (float)((i * 7 + j * 3) % 5) / 5.0f;
            p[2] = (float)j / G;
        }
    int k = 0;
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            uint32_t a = (uint32_t)(i * (G + 1) + j), c = a + G + 1;
            uint32_t q[6] = {a, a + 1, c + 1, a, c + 1, c};
            memcpy(idx + k, q, sizeof q);
            k += 6;
        }
    size_t nb = sizeof pos + sizeof idx;
    unsigned char *bin = malloc(nb);
    memcpy(bin, pos, sizeof pos);
    memcpy(bin + sizeof pos, idx, sizeof idx);
    char *enc = malloc(nb * 2 + 4), *doc = malloc(nb * 2 + 65536);
    b64(bin, nb, enc);
    int o = sprintf(doc, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
                    "\"uri\":\"data:application/octet-stream;base64,%s\"}],"
                    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,"
                    "\"byteLength\":%zu}],"
                    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
                    "\"min\":[0,0,0],\"max\":[1,0.1,1]},{\"bufferView\":1,\"componentType\":5125,\"count\":%d,"
                    "\"type\":\"SCALAR\"}],\"meshes\":[",
                    nb, enc, sizeof pos, sizeof pos, sizeof idx, (G + 1) * (G + 1), G * G * 6);
    for (int m = 0; m < (copies ? nodes : 1); m++)
        o += sprintf(doc + o, "%s{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}", m ? "," : "");
    o += sprintf(doc + o, "],\"nodes\":[");
    for (int n = 0; n < nodes; n++)
        o += sprintf(doc + o, "%s{\"mesh\":%d,\"translation\":[%d,0,%d],\"rotation\":[0,%.6f,0,%.6f]}", n ? "," : "",
                     copies ? n : 0, (n % 4) * 2, (n / 4) * 2, 0.2 * n / (1.0 + 0.2 * n), 1.0 / (1.0 + 0.2 * n));
    o += sprintf(doc + o, "],\"scenes\":[{\"nodes\":[");
    for (int n = 0; n < nodes; n++)
        o += sprintf(doc + o, "%s%d", n ? "," : "", n);
    sprintf(doc + o, "]}],\"scene\":0}");
    fr_builder b;
    fr_error e;
    bld_init(&b);
    size_t size = 0;
    if (gltf_build_scene("t.gltf", doc, strlen(doc), NULL, NULL, 0, &b, &e) < 0 || frz_scene(&b, out, &e) < 0)
        printf("FAIL glTF: %s\n", e.msg);
    else
        size = out->blob_size;
    bld_free(&b);
    free(bin);
    free(enc);
    free(doc);
    return size;
}

static void test_gltf(void)
{
    fr_scene one, shared, copies;
    size_t s1 = gltf_size(1, 0, &one), sn = gltf_size(12, 0, &shared), sc = gltf_size(12, 1, &copies);
    printf("  glTF: one node %zu bytes, 12 nodes of one mesh %zu bytes, 12 meshes %zu bytes\n", s1, sn, sc);
    CHECK(one.n_instances == 0 && one.n_meshes == 0, "one node: %u instances", one.n_instances);
    CHECK(shared.n_meshes == 1 && shared.n_instances == 12, "12 nodes of one mesh: %u meshes, %u instances",
          shared.n_meshes, shared.n_instances);
    CHECK(shared.n_triangles == one.n_triangles, "12 nodes of one mesh: %u triangles, one node %u",
          shared.n_triangles, one.n_triangles);
    CHECK(sn < s1 + s1 / 4 && sc > 8 * s1, "sizes: one %zu, shared %zu, copies %zu", s1, sn, sc);
    /* The shared mesh and the 12 copies are the same surfaces. */
    int differ = 0;
    for (int k = 0; k < 4000; k++) {
        fr_ray r = {v3(rnd() * 8.0f - 1.0f, 2.0f, rnd() * 6.0f - 1.0f), v3_norm(v3(rnd() - 0.5f, -1.0f, rnd() - 0.5f)), 0.0f};
        fr_hit a, c;
        int ha = trace_closest(&shared, &r, INFINITY, &a), hc = trace_closest(&copies, &r, INFINITY, &c);
        differ += ha != hc || (ha && fabsf(a.t - c.t) > 1e-5f * c.t);
    }
    CHECK(differ <= 4, "%d of 4000 rays hit the shared mesh and its copies differently", differ);
    /* Objects (the object_id pass): each node is one, by the instance it
     * places or the copy it owns, the same either way. */
    CHECK(shared.n_object_names == 12 && copies.n_object_names == 12 && !strcmp(shared.object_names[0].name, "node0")
              && !strcmp(shared.object_names[11].name, "node11"),
          "12 nodes, 12 objects node0..node11 (%u, %u)", shared.n_object_names, copies.n_object_names);
    int other = 0, hits = 0;
    unsigned seen = 0;
    for (int k = 0; k < 4000; k++) {
        fr_ray r = {v3(rnd() * 8.0f - 1.0f, 2.0f, rnd() * 6.0f - 1.0f), v3_norm(v3(rnd() - 0.5f, -1.0f, rnd() - 0.5f)), 0.0f};
        fr_hit a, c;
        if (!trace_closest(&shared, &r, INFINITY, &a) || !trace_closest(&copies, &r, INFINITY, &c))
            continue;
        fr_surface sa, sc;
        trace_surface(&shared, &r, &a, &sa);
        trace_surface(&copies, &r, &c, &sc);
        uint32_t oa = pass_object(&shared, &sa), oc = pass_object(&copies, &sc);
        other += oa != oc;
        hits++;
        if (oa > 0 && oa <= 32)
            seen |= 1u << (oa - 1);
    }
    CHECK(hits > 500 && other <= 4 && seen == 0xfffu,
          "objects: %d of %d hits differ between instances and copies; nodes hit %#x (want 0xfff)", other, hits, seen);
    scn_free(&one);
    scn_free(&shared);
    scn_free(&copies);
}

/* ---- many instances: a cost per instance, not per copy ---- */

static void test_many(void)
{
    fr_builder b;
    fr_error e;
    bld_init(&b);
    if (json_scene_parse(base_json, "(test)", NULL, &b, &e) < 0)
        return;
    uint32_t m = torus(&b, 0.8f, 0.3f, 100, 100, MAT_W);   /* 20 000 triangles */
    float xf[3][4];
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int i = 0; i < 1000; i++) {
        xform(xf, (float)(i * 37 % 360), v3(0, 1, 0), v3s(0.5f + (float)(i % 7) * 0.1f),
              v3((float)(i % 40) * 2.0f, 0.0f, (float)(i / 40) * 2.0f));
        bld_instance(&b, m, (const float(*)[4])xf, &e);
    }
    fr_scene s;
    int rc = frz_scene(&b, &s, &e);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    CHECK(rc == 0, "1000 instances: %s", e.msg);
    if (rc == 0) {
        printf("  1000 instances of a 20000-triangle mesh: %.2f s, %zu bytes\n", secs, s.blob_size);
        CHECK(s.n_triangles == 20000 && s.n_instances == 1000, "%u triangles, %u instances", s.n_triangles,
              s.n_instances);
        /* 20 000 triangles take about 2 MB; each instance about 150 bytes. */
        CHECK(s.blob_size < 4000000, "1000 instances take %zu bytes", s.blob_size);
        CHECK(secs < 10.0, "1000 instances took %.1f s to compile", secs);
        scn_free(&s);
    }
    bld_free(&b);
}

int main(void)
{
    fr_scene inst, flat, inst_u, flat_u;
    build(&inst, 0, 0);
    build(&flat, 1, 0);
    build(&inst_u, 0, 1);
    build(&flat_u, 1, 1);
    test_structure(&inst, &flat);
    test_hits(&inst, &flat);
    test_walks(&inst);
    test_images(&inst_u, &flat_u, 1e-5, 1e-4);
    test_images(&inst, &flat, 1e-3, 1e-2);
    test_loader(&inst);
    test_gltf();
    test_many();
    scn_free(&inst);
    scn_free(&flat);
    scn_free(&inst_u);
    scn_free(&flat_u);
    return check_done();
}
