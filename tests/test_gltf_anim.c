/* test_gltf_anim.c -- glTF animation samplers against hand-computed poses.
 *
 * glTF animations evaluated at one time (common/compile/gltf_anim.c): STEP
 * holds keys, CUBICSPLINE follows the Hermite spline with tangents scaled
 * by the interval (values worked out by hand below), LINEAR rotations take
 * the shorter arc, morph weights blend per target, the ends hold;
 * malformed samplers and channels and animated matrix nodes are refused
 * naming the JSON pointer.  The documents are .glb files built in memory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compile/gltf_anim.h"
#include "compile/gltf_scene.h"
#include "warnings.h"

#define T(c) CHECK(c, "%s", #c)

/* ---- the document ----------------------------------------------------- */

/* The binary chunk: key times, then the samplers' values (float32). */
static const float bin_floats[] = {
    /* 0: times (3) */ 0, 1, 3,
    /* 3: STEP translations (3 x VEC3) */ 1, 2, 3, 4, 5, 6, 7, 8, 9,
    /* 12: CUBICSPLINE scales (3 keys x in, value, out) */
    0, 0, 0, 1, 1, 1, 2, 0, -1,
    1, 1, 1, 3, 2, 1, 0.5f, 0, 0,
    0, 0, 1, 5, 2, 1, 0, 0, 0,
    /* 39: LINEAR rotations (3 x VEC4): identity, 90 degrees about y, 180
     * degrees about y written negated */
    0, 0, 0, 1, 0, 0.70710678f, 0, 0.70710678f, 0, -1, 0, 0,
    /* 51: times not increasing (3) */ 0, 2, 1};

/* The JSON: node 0 animated by STEP translation, CUBICSPLINE scale and
 * LINEAR rotation; `extra` replaces the "@" in it (more members or a
 * change). */
static const char *json_fmt =
    "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu}],"
    "\"accessors\":["
    "{\"bufferView\":0,\"byteOffset\":0,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},"
    "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
    "{\"bufferView\":0,\"byteOffset\":48,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},"
    "{\"bufferView\":0,\"byteOffset\":156,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
    "{\"bufferView\":0,\"byteOffset\":204,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},"
    "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":6,\"type\":\"SCALAR\"}],"
    "\"nodes\":[{\"name\":\"a\"},{\"name\":\"b\",\"children\":[0]},{\"name\":\"c\"}],"
    "\"animations\":[{\"samplers\":["
    "{\"input\":0,\"output\":1,\"interpolation\":\"STEP\"},"
    "{\"input\":0,\"output\":2,\"interpolation\":\"CUBICSPLINE\"},"
    "{\"input\":0,\"output\":3}],"
    "\"channels\":["
    "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}},"
    "{\"sampler\":1,\"target\":{\"node\":0,\"path\":\"scale\"}},"
    "{\"sampler\":2,\"target\":{\"node\":0,\"path\":\"rotation\"}}]}]%s}";

static unsigned char glb[16384];

static void put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16),
    p[3] = (unsigned char)(v >> 24);
}

/* A .glb of the document with `extra` appended to its JSON object and
 * `from` replaced by `to` (when not NULL); its length. */
static size_t make_glb(const char *extra, const char *from, const char *to)
{
    char json[8192], edited[8192];
    snprintf(json, sizeof json, json_fmt, sizeof bin_floats, sizeof bin_floats, extra);
    const char *at = from ? strstr(json, from) : NULL;
    if (at)
        snprintf(edited, sizeof edited, "%.*s%s%s", (int)(at - json), json, to, at + strlen(from));
    else
        snprintf(edited, sizeof edited, "%s", json);
    size_t jl = strlen(edited), jpad = (jl + 3) & ~(size_t)3, bl = sizeof bin_floats;
    size_t total = 12 + 8 + jpad + 8 + bl;
    memcpy(glb, "glTF", 4);
    put32(glb + 4, 2);
    put32(glb + 8, (uint32_t)total);
    put32(glb + 12, (uint32_t)jpad);
    memcpy(glb + 16, "JSON", 4);
    memcpy(glb + 20, edited, jl);
    memset(glb + 20 + jl, ' ', jpad - jl);
    put32(glb + 20 + jpad, (uint32_t)bl);
    memcpy(glb + 24 + jpad, "BIN\0", 4);
    for (size_t i = 0; i < bl / 4; i++) {
        uint32_t u;
        memcpy(&u, &bin_floats[i], 4);
        put32(glb + 28 + jpad + 4 * i, u);
    }
    return total;
}

/* Evaluates the document (with an edit) at t: 0, or -1 with err. */
static int eval(const char *extra, const char *from, const char *to, double t, ganim_pose *p, fr_error *err)
{
    size_t n = make_glb(extra, from, to);
    gltf_doc d;
    memset(p, 0, sizeof *p);
    if (gdoc_open_mem(&d, glb, n, "t.glb", NULL, err) < 0)
        return -1;
    int rc = ganim_eval(&d, t, p, err);
    gdoc_free(&d);
    return rc;
}

static int near3(const double *v, double x, double y, double z)
{
    int ok = fabs(v[0] - x) < 1e-6 && fabs(v[1] - y) < 1e-6 && fabs(v[2] - z) < 1e-6;
    if (!ok)
        printf("  got (%.9g %.9g %.9g), want (%.9g %.9g %.9g)\n", v[0], v[1], v[2], x, y, z);
    return ok;
}

/* Quaternion (0, sin(a/2), 0, cos(a/2)) for a about y, up to sign, after
 * normalising v. */
static int about_y(const double *v, double deg)
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    double h = deg * M_PI / 360.0;
    int ok = 0;
    for (double s = -1.0; s <= 1.0; s += 2.0)
        ok |= fabs(v[0]) < 1e-6 && fabs(v[2]) < 1e-6 && fabs(s * v[1] / l - sin(h)) < 1e-6 &&
              fabs(s * v[3] / l - cos(h)) < 1e-6;
    if (!ok)
        printf("  got (%.9g %.9g %.9g %.9g), want %g degrees about y\n", v[0], v[1], v[2], v[3], deg);
    return ok;
}

/* A check that message s holds frag. */
#define HAS(s, frag) CHECK(strstr(s, frag) != NULL, "message '%s' lacks '%s'", s, frag)

/* ---- tests ------------------------------------------------------------ */

static void test_step(void)
{
    static const struct { double t, x, y, z; } want[] = {
        {-1, 1, 2, 3}, {0, 1, 2, 3}, {0.5, 1, 2, 3}, {1, 4, 5, 6}, {2.9, 4, 5, 6}, {3, 7, 8, 9}, {5, 7, 8, 9}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        ganim_pose p;
        fr_error e;
        int rc = eval("", NULL, NULL, want[i].t, &p, &e);
        CHECK(rc == 0, "STEP at %g: %s", want[i].t, rc ? e.msg : "");
        if (rc == 0) {
            T(p.n == 3 && p.channels == 3);
            T(p.node[0].set == (GANIM_T | GANIM_R | GANIM_S) && p.node[1].set == 0 && p.node[2].set == 0);
            CHECK(near3(p.node[0].t, want[i].x, want[i].y, want[i].z), "STEP translation at t = %g", want[i].t);
        }
        ganim_free(&p);
    }
}

static void test_cubic(void)
{
    /* By hand: at u = 1/2 the Hermite weights are h00 = h01 = 1/2, h10 =
     * 1/8, h11 = -1/8; tangents times the interval's length td.
     * [0,1] at t = 0.5 (td 1): 0.5 p0 + 0.125 out0 + 0.5 p1 - 0.125 in1
     *   = (0.5 + 0.25 + 1.5 - 0.125, 0.5 + 0 + 1 - 0.125, 0.5 - 0.125 + 0.5 - 0.125)
     * [1,3] at t = 2 (td 2): 0.5 p1 + 0.25 out1 + 0.5 p2 - 0.25 in2
     *   = (1.5 + 0.125 + 2.5, 1 + 1, 0.5 + 0.5 - 0.25) */
    static const struct { double t, x, y, z; } want[] = {
        {0, 1, 1, 1}, {0.5, 2.125, 1.375, 0.75}, {1, 3, 2, 1}, {2, 4.125, 2, 0.75}, {3, 5, 2, 1}, {4, 5, 2, 1}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        ganim_pose p;
        fr_error e;
        int rc = eval("", NULL, NULL, want[i].t, &p, &e);
        CHECK(rc == 0, "CUBICSPLINE at %g: %s", want[i].t, rc ? e.msg : "");
        if (rc == 0)
            CHECK(near3(p.node[0].s, want[i].x, want[i].y, want[i].z), "CUBICSPLINE scale at t = %g", want[i].t);
        ganim_free(&p);
    }
    /* At u = 1/4 on [0,1]: h00 = 27/32, h10 = 9/64, h01 = 5/32, h11 = -3/64:
     * x = 27/32 + 18/64 + 15/32 - 3/64 */
    ganim_pose p;
    fr_error e;
    if (eval("", NULL, NULL, 0.25, &p, &e) == 0)
        CHECK(near3(p.node[0].s, 27.0 / 32 + 18.0 / 64 + 15.0 / 32 - 3.0 / 64, 27.0 / 32 + 10.0 / 32 - 3.0 / 64,
                    27.0 / 32 - 9.0 / 64 + 5.0 / 32 - 3.0 / 64), "CUBICSPLINE scale at t = 0.25");
    else
        CHECK(0, "CUBICSPLINE at 0.25: %s", e.msg);
    ganim_free(&p);
}

static void test_slerp(void)
{
    /* identity -> 90 degrees about y over [0,1]; 90 -> 180 degrees over
     * [1,3], the 180 degree key written negated: the shorter arc goes on
     * through 135 degrees, not back through 0. */
    static const struct { double t, deg; } want[] = {{0, 0}, {0.5, 45}, {0.25, 22.5}, {1, 90}, {2, 135}, {2.5, 157.5},
                                                     {3, 180}, {7, 180}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        ganim_pose p;
        fr_error e;
        int rc = eval("", NULL, NULL, want[i].t, &p, &e);
        CHECK(rc == 0, "rotation at %g: %s", want[i].t, rc ? e.msg : "");
        if (rc == 0)
            CHECK(about_y(p.node[0].r, want[i].deg), "rotation at t = %g", want[i].t);
        ganim_free(&p);
    }
}

static void test_weights(void)
{
    /* accessor 5: six scalars 1..6, two weights per key: (1, 2) at 0,
     * (3, 4) at 1, (5, 6) at 3, LINEAR */
    static const struct { double t, w0, w1; } want[] = {{0, 1, 2}, {0.5, 2, 3}, {1, 3, 4}, {2, 4, 5}, {9, 5, 6}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        ganim_pose p;
        fr_error e;
        int rc = eval("", "{\"input\":0,\"output\":3}],\"channels\":[",
                      "{\"input\":0,\"output\":3},{\"input\":0,\"output\":5}],\"channels\":["
                      "{\"sampler\":3,\"target\":{\"node\":2,\"path\":\"weights\"}},", want[i].t, &p, &e);
        CHECK(rc == 0, "weights at %g: %s", want[i].t, rc ? e.msg : "");
        if (rc == 0) {
            T(p.node[2].set == GANIM_W && p.node[2].n_weights == 2);
            CHECK(fabs(p.node[2].w[0] - want[i].w0) < 1e-9 && fabs(p.node[2].w[1] - want[i].w1) < 1e-9,
                  "weights at %g: (%g %g), want (%g %g)", want[i].t, p.node[2].w[0], p.node[2].w[1], want[i].w0,
                  want[i].w1);
        }
        ganim_free(&p);
    }
}

static void test_frame_time(void)
{
    /* frame / fps rounded to single precision: the exporter's key times */
    T(ganim_frame_time(0, 24) == 0.0);
    T(ganim_frame_time(1, 24) == (double)(float)(1.0 / 24.0));
    T(ganim_frame_time(48, 24) == 2.0);
    T(ganim_frame_time(1, 12) == ganim_frame_time(2, 24));
}

/* The document with `from` replaced by `to` (or `extra` added) is refused
 * with a message holding `frag`. */
static void refused(const char *what, const char *extra, const char *from, const char *to, const char *frag)
{
    ganim_pose p;
    fr_error e;
    int rc = eval(extra, from, to, 0.5, &p, &e);
    ganim_free(&p);
    CHECK(rc < 0, "%s: accepted", what);
    if (rc < 0) {
        HAS(e.msg, frag);
        HAS(e.msg, "t.glb: /");
    }
}

static void test_refused(void)
{
    refused("times", "", "\"byteOffset\":0,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},",
            "\"byteOffset\":204,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},",
            "/animations/0/samplers/0/input: accessor 0: time 2 (1) is not after time 1 (2)");
    refused("interpolation", "", "\"STEP\"", "\"SMOOTH\"",
            "/animations/0/samplers/0: interpolation: 'SMOOTH' is not LINEAR, STEP or CUBICSPLINE");
    refused("cubic count", "", "\"CUBICSPLINE\"", "\"LINEAR\"",
            "/animations/0/samplers/1/output: accessor 2 has 9 elements; 3 key times need 3");
    refused("sampler index", "", "{\"sampler\":2,", "{\"sampler\":3,",
            "/animations/0/channels/2: sampler: 3 is not an index into this animation's samplers");
    refused("node index", "", "\"node\":0,\"path\":\"scale\"", "\"node\":3,\"path\":\"scale\"",
            "/animations/0/channels/1/target: node: 3 is not an index into nodes");
    refused("path", "", "\"path\":\"scale\"", "\"path\":\"colour\"",
            "/animations/0/channels/1/target: path: 'colour' is not translation, rotation, scale or weights");
    refused("weights type", "", "\"path\":\"scale\"", "\"path\":\"weights\"",
            "/animations/0/samplers/1/output: accessor 2 has type VEC3, expected 1 components");
    refused("scalar translations", "", "{\"input\":0,\"output\":1,", "{\"input\":0,\"output\":4,",
            "/animations/0/samplers/0/output: accessor 4 has type SCALAR, expected 3 components");
    refused("weights count", "",
            "{\"input\":0,\"output\":2,\"interpolation\":\"CUBICSPLINE\"},{\"input\":0,\"output\":3}],\"channels\":[",
            "{\"input\":0,\"output\":2,\"interpolation\":\"CUBICSPLINE\"},{\"input\":0,\"output\":3},"
            "{\"input\":0,\"output\":5,\"interpolation\":\"CUBICSPLINE\"}],\"channels\":["
            "{\"sampler\":3,\"target\":{\"node\":2,\"path\":\"weights\"}},",
            "/animations/0/samplers/3/output: accessor 5 has 6 elements: not 3 key times of 1 to 64 weights");
    refused("input type", "", "{\"input\":0,\"output\":3}", "{\"input\":1,\"output\":3}",
            "/animations/0/samplers/2/input: accessor 1 has type VEC3, expected 1 components");
    refused("output accessor", "", "{\"input\":0,\"output\":3}", "{\"input\":0,\"output\":9}",
            "/animations/0/samplers/2: output: 9 is not an index into accessors");
    refused("no target", "", "\"target\":{\"node\":0,\"path\":\"translation\"}", "\"x\":1",
            "/animations/0/channels/0: target is missing");
}


#define SCENES ",\"scenes\":[{\"nodes\":[1,2]}]"

/* Through the scene reader: an animated node with a matrix is refused; a
 * second channel on the same property is warned about, the first used. */
static void test_scene(void)
{
    const scene_hooks hooks = warn_hooks;
    gltf_options o;
    gltf_options_default(&o);
    o.take_camera = 0;
    o.animate = 1;
    o.time = 0.5;
    fr_builder b;
    gltf_result r;
    fr_error e;
    bld_init(&b);
    size_t n = make_glb(SCENES, "{\"name\":\"a\"}", "{\"name\":\"a\",\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}");
    int rc = gltf_import_mem(glb, n, "t.glb", &hooks, &o, &b, &r, &e);
    CHECK(rc < 0, "an animated matrix node: accepted");
    if (rc < 0)
        HAS(e.msg, "t.glb: /nodes/0: matrix: a node animated by /animations/0/channels/0");
    bld_free(&b);

    bld_init(&b);
    n_warnings = 0;
    n = make_glb(SCENES, "{\"sampler\":2,\"target\":{\"node\":0,\"path\":\"rotation\"}}",
                 "{\"sampler\":2,\"target\":{\"node\":0,\"path\":\"rotation\"}},"
                 "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}");
    rc = gltf_import_mem(glb, n, "t.glb", &hooks, &o, &b, &r, &e);
    CHECK(rc == 0, "two channels on one property: %s", rc ? e.msg : "");
    T(n_warnings >= 1);
    HAS(last_warning, "t.glb: /animations/0/channels/3: node 0's translation is animated already");
    bld_free(&b);

    /* at rest (not animated): one warning that the animations are not played */
    bld_init(&b);
    n_warnings = 0;
    o.animate = 0;
    n = make_glb(SCENES, NULL, NULL);
    rc = gltf_import_mem(glb, n, "t.glb", &hooks, &o, &b, &r, &e);
    T(rc == 0 && n_warnings == 1);
    HAS(last_warning, "/animations: not played");
    bld_free(&b);
}

int main(void)
{
    test_step();
    test_cubic();
    test_slerp();
    test_weights();
    test_frame_time();
    test_refused();
    test_scene();
    return check_done();
}
