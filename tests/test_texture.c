/* test_texture.c -- texture lookups, UVs, bump and normal maps against known
 * values.
 *
 * Textures, UVs, bump and normal maps: lookups against hand-computed
 * values, UV round trips on every primitive, an emissive textured quad
 * seen head-on, a flat bump map that changes nothing, and shading normals
 * that never let light through a surface; four-texel fetches that decode
 * every format, and every half-float value, to the bits of one-texel ones. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bsdf.h"
#include "check.h"
#include "pathtrace.h"
#include "scenes.h"
#include "texture.h"

/* ---- a texture hook that serves synthetic images ------------------------ */

/* The image behind every file name the scene uses: `grid` is 4x2 RGB with
 * texel (x, y) = (x/4, y/2, 0.25) (y = 0 the top row), `flat` a constant
 * grey 0.5, `ramp` an 8x8 grey ramp with value x/8 along x. */
static int synthetic(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    (void)data;
    (void)len;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (!strncmp(base, "grid", 4)) {
        img->width = 4, img->height = 2, img->channels = 3;
    } else if (!strncmp(base, "flat", 4) || !strncmp(base, "ramp", 4)) {
        img->width = 8, img->height = 8, img->channels = 1;
    } else if (!strncmp(base, "wide", 4)) {
        img->width = FR_TEX_MAX_SIDE + 1, img->height = 1, img->channels = 1;
    } else {
        return fr_fail(err, "%s: no such synthetic image", path);
    }
    img->pixels = malloc(sizeof(float) * img->width * img->height * img->channels);
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = 0; x < img->width; x++) {
            float *p = img->pixels + (y * img->width + x) * img->channels;
            if (img->channels == 3) {
                p[0] = x / 4.0f, p[1] = y / 2.0f, p[2] = 0.25f;
            } else {
                p[0] = base[0] == 'f' ? 0.5f : base[0] == 'w' ? 0.0f : x / 8.0f;
            }
        }
    return 0;
}

static const scene_hooks hooks = {.texture = synthetic};
static char dir[64];

/* Parse a scene whose image files live in dir (they exist, empty, so the
 * reader's existence check passes; the hook makes up their pixels). */
static int load(const char *json, fr_scene *out, fr_error *err)
{
    fr_builder b;
    bld_init(&b);
    char file[128];
    snprintf(file, sizeof file, "%s/scene.json", dir);
    int rc = json_scene_parse(json, file, &hooks, &b, err);
    if (rc == 0)
        rc = frz_scene(&b, out, err);
    bld_free(&b);
    return rc;
}

static void make_files(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-tex-%ld", (long)getpid());
    char cmd[256];
    snprintf(cmd, sizeof cmd, "mkdir -p %s && cd %s && touch grid.png grid.exr flat.png ramp.png wide.png", dir, dir);
    if (system(cmd) != 0) {
        printf("FAIL cannot create %s\n", dir);
        exit(1);
    }
}

static void remove_files(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        printf("note: could not remove %s\n", dir);
}

#define SCENE_HEAD                                                                                       \
    "{\"image\": {\"width\": 4, \"height\": 2, \"spp\": 1},"                                             \
    " \"camera\": {\"position\": [0, 0, 1], \"target\": [0, 0, 0], \"fov\": 60},"

/* ---- lookups -------------------------------------------------------------- */

static void srgb_curve(void)
{
    CHECK(tex_srgb_to_linear(0.0f) == 0.0f && tex_srgb_to_linear(1.0f) == 1.0f, "sRGB end points");
    CHECK(fabsf(tex_srgb_to_linear(0.5f) - 0.2140411f) < 1e-6f, "sRGB 0.5 -> %g", tex_srgb_to_linear(0.5f));
    CHECK(fabsf(tex_srgb_to_linear(0.04f) - 0.04f / 12.92f) < 1e-9f, "sRGB linear toe");
    float worst = 0.0f;
    for (int i = 0; i <= 255; i++) {
        double v = i / 255.0, ref = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
        worst = fmaxf(worst, fabsf((float)(tex_srgb_to_linear((float)v) - ref)));
    }
    CHECK(worst < 2e-7f, "sRGB decode of 8-bit values off by %g", worst);
}

static void lookups(void)
{
    fr_scene s;
    fr_error err;
    const char *json = SCENE_HEAD
        "\"textures\": {\"g\": {\"type\": \"image\", \"file\": \"grid.png\", \"colorspace\": \"linear\"},"
        "  \"c\": {\"type\": \"image\", \"file\": \"grid.png\", \"wrap\": \"clamp\", \"colorspace\": \"linear\"},"
        "  \"n\": {\"type\": \"image\", \"file\": \"grid.png\", \"filter\": \"nearest\", \"colorspace\": \"linear\"},"
        "  \"s\": {\"type\": \"image\", \"file\": \"grid.png\"},"
        "  \"e\": {\"type\": \"image\", \"file\": \"grid.exr\"},"
        "  \"k\": {\"type\": \"checker\", \"colors\": [[1, 0, 0], [0, 0, 1]], \"scale\": [4, 2], \"offset\": [0.5, 0]}},"
        "\"materials\": {\"a\": {\"type\": \"lambert\", \"albedo\": \"g\"}, \"b\": {\"type\": \"lambert\", \"albedo\": \"c\"},"
        "  \"c\": {\"type\": \"lambert\", \"albedo\": \"n\"}, \"d\": {\"type\": \"lambert\", \"albedo\": \"s\"},"
        "  \"e\": {\"type\": \"lambert\", \"albedo\": \"e\"}, \"f\": {\"type\": \"lambert\", \"albedo\": \"k\"},"
        "  \"h\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5], \"bump\": \"g\"}},"
        "\"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, -3], \"radius\": 1, \"material\": \"a\"}],"
        "\"lights\": [{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}]}";
    if (load(json, &s, &err) < 0) {
        CHECK(0, "lookup scene: %s", err.msg);
        return;
    }
    /* Textures are stored in order of first use: g, c, n, s, e, k, then g
     * again for the bump map (data: no sRGB decoding, but "linear" was
     * asked for anyway, so it is the same as the first g). */
    CHECK(s.n_textures == 6, "%u textures stored, expected 6 (one per distinct use)", s.n_textures);
    uint32_t g = 0, c = 1, n = 2, sr = 3, e = 4, k = 5;
    /* Texel centres: texel (x, y) is at u = (x + 0.5)/4, v = 1 - (y + 0.5)/2. */
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 4; x++) {
            vec2 uv = {(x + 0.5f) / 4.0f, 1.0f - (y + 0.5f) / 2.0f};
            vec3 v = tex_eval(&s, g, uv);
            CHECK(v.x == x / 4.0f && v.y == y / 2.0f && v.z == 0.25f, "texel (%d,%d) centre: %g %g %g", x, y, v.x, v.y, v.z);
        }
    /* Halfway between texels 1 and 2 of the top row. */
    vec3 v = tex_eval(&s, g, (vec2){0.5f, 0.75f});
    CHECK(fabsf(v.x - 0.375f) < 1e-6f && v.y == 0.0f, "bilinear midpoint %g %g", v.x, v.y);
    /* At u = 0 repeat blends the last and first columns, clamp does not. */
    v = tex_eval(&s, g, (vec2){0.0f, 0.75f});
    CHECK(fabsf(v.x - 0.375f) < 1e-6f, "repeat across the seam: %g, expected 0.375", v.x);
    v = tex_eval(&s, g, (vec2){3.0f, 0.75f});
    CHECK(fabsf(v.x - 0.375f) < 1e-6f, "repeat at u = 3: %g", v.x);
    v = tex_eval(&s, g, (vec2){-1.875f, 0.75f});
    CHECK(fabsf(v.x - 0.0f) < 1e-6f, "repeat at negative u: %g, expected texel 0", v.x);
    v = tex_eval(&s, c, (vec2){0.0f, 0.75f});
    CHECK(v.x == 0.0f, "clamp at u = 0: %g", v.x);
    v = tex_eval(&s, c, (vec2){7.0f, -3.0f});
    CHECK(v.x == 0.75f && v.y == 0.5f, "clamp far outside: %g %g", v.x, v.y);
    v = tex_eval(&s, n, (vec2){0.49f, 0.9f});
    CHECK(v.x == 0.25f && v.y == 0.0f, "nearest: %g %g", v.x, v.y);
    /* Integer images are sRGB-decoded as colours by default, float ones not. */
    v = tex_eval(&s, sr, (vec2){(2 + 0.5f) / 4.0f, 0.75f});
    CHECK(fabsf(v.x - tex_srgb_to_linear(0.5f)) < 1e-7f, "sRGB colour texture: %g", v.x);
    v = tex_eval(&s, e, (vec2){(2 + 0.5f) / 4.0f, 0.75f});
    CHECK(v.x == 0.5f, "EXR colour texture stays linear: %g", v.x);
    /* Checker: u' = 4u + 0.5, v' = 2v. */
    v = tex_eval(&s, k, (vec2){0.0f, 0.1f});
    CHECK(v.x == 1.0f, "checker square at the origin");
    v = tex_eval(&s, k, (vec2){0.2f, 0.1f});
    CHECK(v.z == 1.0f, "checker next square along u");
    v = tex_eval(&s, k, (vec2){0.2f, 0.6f});
    CHECK(v.x == 1.0f, "checker diagonal square");
    v = tex_eval(&s, k, (vec2){-0.2f, 0.1f});
    CHECK(v.z == 1.0f, "checker at negative u");
    v = tex_eval(&s, k, (vec2){1e9f, 3e9f});
    CHECK(v.x == 1.0f || v.z == 1.0f, "checker far away is still one of its colours");
    scn_free(&s);
}

/* ---- UV round trips ------------------------------------------------------ */

/* Shoot at point p from `from` and check the hit's UV and tangents; the
 * tangents' frame should face the way the normal does unless the UVs are
 * mirrored. */
static void round_trip(const fr_scene *s, const char *what, vec3 from, vec3 p, vec2 uv, vec3 dpdu, vec3 dpdv,
                       int mirrored)
{
    fr_ray r = {from, v3_norm(v3_sub(p, from)), 0.0f};
    fr_hit h;
    if (!trace_closest(s, &r, INFINITY, &h)) {
        CHECK(0, "%s: ray missed", what);
        return;
    }
    fr_surface sf;
    trace_surface(s, &r, &h, &sf);
    CHECK(fabsf(sf.uv.u - uv.u) < 2e-5f && fabsf(sf.uv.v - uv.v) < 2e-5f, "%s: uv (%g, %g), expected (%g, %g)", what,
          sf.uv.u, sf.uv.v, uv.u, uv.v);
    float eu = v3_len(v3_sub(sf.dpdu, dpdu)) / v3_len(dpdu), ev = v3_len(v3_sub(sf.dpdv, dpdv)) / v3_len(dpdv);
    CHECK(eu < 1e-3f && ev < 1e-3f, "%s: tangents off by %g, %g (relative)", what, eu, ev);
    /* The tangents face out the way the normal does (images not mirrored). */
    CHECK((v3_dot(v3_cross(sf.dpdu, sf.dpdv), sf.ng) > 0.0f) != mirrored, "%s: cross(dpdu, dpdv) faces %s", what,
          mirrored ? "out" : "in");
}

static void uv_round_trips(void)
{
    fr_builder b;
    fr_error err;
    bld_init(&b);
    b.settings = (fr_settings){.width = 4, .height = 4, .spp = 1, .max_depth = 1};
    b.camera = (fr_camera){.position = v3(0, 0, 10), .target = v3(0, 0, 0), .up = v3(0, 1, 0), .vfov = 1.0f};
    fr_material m;
    bld_material_init(&m);
    m.diffuse = v3s(0.5f);
    bsdf_lobe_probs(&m);
    bld_push(&b.materials, &m);
    vec3 c = v3(5, 1, -2);
    float rad = 1.5f;
    bld_sphere(&b, c, rad, 0);
    vec3 ro = v3(-5, 0, 0), eu = v3(2, 0, 0.5f), ev = v3(0, 3, 0);
    bld_rect(&b, ro, eu, ev, 0);
    /* A triangle with UVs, mirrored in u (its UV frame is left-handed) to
     * check the tangents of such meshes too; one without UVs. */
    vec3 t0 = v3(-2, -5, 0), t1 = v3(2, -5, 0), t2 = v3(0, -2, 0);
    vec2 w0 = {0.9f, 0.1f}, w1 = {0.1f, 0.2f}, w2 = {0.4f, 0.8f};
    uint32_t base = b.positions.count;
    bld_push(&b.positions, &t0), bld_push(&b.positions, &t1), bld_push(&b.positions, &t2);
    while (b.uvs.count < base)
        bld_push(&b.uvs, &(vec2){0, 0});
    bld_push(&b.uvs, &w0), bld_push(&b.uvs, &w1), bld_push(&b.uvs, &w2);
    fr_triangle tri = {{base, base + 1, base + 2}, FR_TRI_UVS};
    uint32_t ti = bld_push(&b.triangles, &tri);
    fr_prim pr = {FR_PRIM_TRIANGLE, ti, 0, FR_NONE};
    bld_push(&b.prims, &pr);
    vec3 q0 = v3(3, 3, 0), q1 = v3(5, 3, 0), q2 = v3(3, 6, 0);
    bld_triangle(&b, q0, q1, q2, 0);
    fr_plane pl = {v3(0, 0, -20), v3(0, 0, 1), 0, 0};
    bld_push(&b.planes, &pl);
    fr_scene s;
    if (frz_scene(&b, &s, &err) < 0) {
        CHECK(0, "uv scene: %s", err.msg);
        bld_free(&b);
        return;
    }
    bld_free(&b);

    /* Sphere: u = (phi + pi) / 2pi with phi = atan2(-z, x), v = 1 - theta/pi. */
    const float us[] = {0.1f, 0.3f, 0.55f, 0.8f, 0.95f}, vs[] = {0.15f, 0.4f, 0.5f, 0.7f, 0.9f};
    for (int i = 0; i < 5; i++) {
        float phi = 2.0f * (float)M_PI * us[i] - (float)M_PI, theta = (float)M_PI * (1.0f - vs[i]);
        vec3 d = v3(sinf(theta) * cosf(phi), cosf(theta), -sinf(theta) * sinf(phi));
        vec3 p = v3_madd(c, d, rad);
        vec3 dpdu = v3_scale(v3(d.z, 0, -d.x), 2.0f * (float)M_PI * rad);   /* d(p)/d(phi) * 2pi */
        vec3 dth = v3(cosf(theta) * cosf(phi), -sinf(theta), -cosf(theta) * sinf(phi));
        vec3 dpdv = v3_scale(dth, -(float)M_PI * rad);
        char what[64];
        snprintf(what, sizeof what, "sphere uv %d", i);
        round_trip(&s, what, v3_madd(c, d, 4.0f * rad), p, (vec2){us[i], vs[i]}, dpdu, dpdv, 0);
    }
    /* Rect: uv are the coordinates along its edges. */
    for (int i = 0; i < 5; i++) {
        vec3 p = v3_add(ro, v3_add(v3_scale(eu, us[i]), v3_scale(ev, vs[i])));
        vec3 n = v3_norm(v3_cross(eu, ev));
        char what[64];
        snprintf(what, sizeof what, "rect uv %d", i);
        round_trip(&s, what, v3_madd(p, n, 3.0f), p, (vec2){us[i], vs[i]}, eu, ev, 0);
    }
    /* Triangles: interpolated UVs; without UVs the barycentrics of p1, p2. */
    float det = (w1.u - w0.u) * (w2.v - w0.v) - (w1.v - w0.v) * (w2.u - w0.u);
    vec3 e1 = v3_sub(t1, t0), e2 = v3_sub(t2, t0);
    vec3 dpdu = v3_scale(v3_sub(v3_scale(e1, w2.v - w0.v), v3_scale(e2, w1.v - w0.v)), 1.0f / det);
    vec3 dpdv = v3_scale(v3_sub(v3_scale(e2, w1.u - w0.u), v3_scale(e1, w2.u - w0.u)), 1.0f / det);
    for (int i = 0; i < 4; i++) {
        float a = 0.1f + 0.2f * i, bb = 0.6f - 0.15f * i, b0 = 1.0f - a - bb;
        vec3 p = v3_add(v3_add(v3_scale(t0, b0), v3_scale(t1, a)), v3_scale(t2, bb));
        vec2 uv = {b0 * w0.u + a * w1.u + bb * w2.u, b0 * w0.v + a * w1.v + bb * w2.v};
        char what[64];
        snprintf(what, sizeof what, "triangle uv %d", i);
        round_trip(&s, what, v3_add(p, v3(0, 0, 3)), p, uv, dpdu, dpdv, 1);
        p = v3_add(v3_add(v3_scale(q0, b0), v3_scale(q1, a)), v3_scale(q2, bb));
        snprintf(what, sizeof what, "triangle barycentric uv %d", i);
        round_trip(&s, what, v3_add(p, v3(0, 0, 3)), p, (vec2){a, bb}, v3_sub(q1, q0), v3_sub(q2, q0), 0);
    }
    /* Plane: a projection onto its own tangent frame. */
    vec3 pt, pb;
    v3_basis(pl.normal, &pt, &pb);
    vec3 p = v3_add(pl.point, v3_add(v3_scale(pt, 7.25f), v3_scale(pb, -3.5f)));
    round_trip(&s, "plane uv", v3(20, -30, 30), p, (vec2){7.25f, -3.5f}, pt, pb, 0);
    scn_free(&s);
}

/* ---- rendering ------------------------------------------------------------ */

/* An emissive rectangle that exactly fills the frame, textured with the
 * 4x2 grid (nearest texels): each of the 4x2 pixels sees one texel. */
static void textured_quad(void)
{
    /* tan(fov/2) = 1/2: the frame is 2 high at distance 2; the rect is 4 x 2. */
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 4, \"height\": 2, \"spp\": 64, \"max_depth\": 0},"
             " \"camera\": {\"position\": [0, 0, 2], \"target\": [0, 0, 0], \"fov\": %.9f},"
             " \"textures\": {\"g\": {\"type\": \"image\", \"file\": \"grid.png\", \"filter\": \"nearest\"}},"
             " \"materials\": {\"screen\": {\"type\": \"emitter\", \"emission\": {\"texture\": \"g\", \"factor\": [2, 2, 2]}}},"
             " \"shapes\": [{\"type\": \"rect\", \"origin\": [-2, -1, 0], \"edge_u\": [4, 0, 0], \"edge_v\": [0, 2, 0],"
             "   \"material\": \"screen\"}]}",
             2.0 * atan(0.5) * 180.0 / M_PI);
    fr_scene s;
    fr_error err;
    if (load(json, &s, &err) < 0) {
        CHECK(0, "quad scene: %s", err.msg);
        return;
    }
    float rgb[4 * 2 * 3];
    pt_render_rows(&s, PT_MIS, 0, 2, rgb);
    float worst = 0.0f;
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 4; x++) {
            /* Texel values are sRGB-decoded (a colour from a png). */
            float expect[3] = {2 * tex_srgb_to_linear(x / 4.0f), 2 * tex_srgb_to_linear(y / 2.0f),
                               2 * tex_srgb_to_linear(0.25f)};
            for (int k = 0; k < 3; k++)
                worst = fmaxf(worst, fabsf(rgb[(y * 4 + x) * 3 + k] - expect[k]));
        }
    CHECK(worst < 1e-5f, "textured emitter seen head-on differs from its texture by %g", worst);
    scn_free(&s);
}

/* A textured area light over a diffuse floor: light sampling must read the
 * emission texture where it samples, so light-only and BSDF-only estimates
 * agree (half the checker is black: ignoring the texture would double the
 * light-only estimate). */
static void textured_light(void)
{
    const char *json =
        "{\"image\": {\"width\": 4, \"height\": 4, \"spp\": 1, \"max_depth\": 1},"
        " \"camera\": {\"position\": [0, 3, 3], \"target\": [0, 0, 0], \"fov\": 40},"
        " \"textures\": {\"k\": {\"type\": \"checker\", \"colors\": [[1, 1, 1], [0, 0, 0]], \"scale\": [3, 2]}},"
        " \"materials\": {\"lamp\": {\"type\": \"emitter\", \"emission\": {\"texture\": \"k\", \"factor\": [4, 4, 4]}},"
        "   \"floor\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]}},"
        " \"shapes\": [{\"type\": \"rect\", \"origin\": [-1, 1, -1], \"edge_u\": [0, 0, 2], \"edge_v\": [2, 0, 0], \"material\": \"lamp\"},"
        "   {\"type\": \"rect\", \"origin\": [-3, 0, 3], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 0, -6], \"material\": \"floor\"}]}";
    fr_scene s;
    fr_error err;
    if (load(json, &s, &err) < 0) {
        CHECK(0, "textured light scene: %s", err.msg);
        return;
    }
    double m[2] = {0, 0};
    const pt_strategy st[2] = {PT_LIGHT_ONLY, PT_BSDF_ONLY};
    for (int k = 0; k < 2; k++)
        for (uint32_t y = 0; y < 4; y++)
            for (uint32_t x = 0; x < 4; x++)
                for (uint32_t i = 0; i < 1024; i++)
                    m[k] += pt_sample(&s, st[k], x, y, i).x;
    CHECK(fabs(m[0] / m[1] - 1.0) < 0.03, "textured light: light sampling %g, BSDF sampling %g", m[0], m[1]);
    CHECK(m[1] > 0.0, "textured light: the floor is dark");
    scn_free(&s);
}

/* The surfaces render_plane draws: a rectangle, and an infinite plane
 * tilted off the axes (so a needless renormalization of its normal would
 * change bits). */
static const char *const RECT = "{\"type\": \"rect\", \"origin\": [-2, 0, 2], \"edge_u\": [4, 0, 0], \"edge_v\": [0, 0, -4], \"material\": \"m\"}";
static const char *const PLANE = "{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0.1, 1, 0.23], \"material\": \"m\"}";
static const char *surface = RECT;

/* Render `surface` lit by a point light, with material `mat` (JSON). */
static int render_plane(const char *textures, const char *mat, vec3 light, float *rgb, fr_error *err)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 8, \"height\": 8, \"spp\": 4, \"max_depth\": 2},"
             " \"camera\": {\"position\": [0.3, 2, 1.5], \"target\": [0, 0, 0], \"fov\": 60},"
             " \"textures\": {%s},"
             " \"materials\": {\"m\": %s},"
             " \"shapes\": [%s],"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [5, 5, 5]}]}",
             textures, mat, surface, light.x, light.y, light.z);
    fr_scene s;
    if (load(json, &s, err) < 0)
        return -1;
    pt_render_rows(&s, PT_MIS, 0, 8, rgb);
    scn_free(&s);
    return 0;
}

static void flat_bump_changes_nothing(void)
{
    float plain[8 * 8 * 3], bumped[8 * 8 * 3], checker[8 * 8 * 3];
    fr_error err;
    const char *tex = "\"flat\": {\"type\": \"image\", \"file\": \"flat.png\", \"scale\": 3},"
                      "\"k\": {\"type\": \"checker\", \"colors\": [[0.3, 0.3, 0.3], [0.3, 0.3, 0.3]], \"scale\": 5}";
    if (render_plane(tex, "{\"type\": \"phong\", \"diffuse\": [0.5, 0.5, 0.5], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 20}",
                     v3(0.5f, 1, 0), plain, &err) < 0 ||
        render_plane(tex, "{\"type\": \"phong\", \"diffuse\": [0.5, 0.5, 0.5], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 20,"
                          " \"bump\": {\"texture\": \"flat\", \"strength\": 4}}",
                     v3(0.5f, 1, 0), bumped, &err) < 0 ||
        render_plane(tex, "{\"type\": \"phong\", \"diffuse\": [0.5, 0.5, 0.5], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 20,"
                          " \"bump\": {\"texture\": \"k\", \"strength\": 4}}",
                     v3(0.5f, 1, 0), checker, &err) < 0) {
        CHECK(0, "bump scenes: %s", err.msg);
        return;
    }
    CHECK(!memcmp(plain, bumped, sizeof plain), "a constant height map changes the image");
    CHECK(!memcmp(plain, checker, sizeof plain), "a constant checker height map changes the image");
    double sum = 0;
    for (int i = 0; i < 8 * 8 * 3; i++)
        sum += plain[i];
    CHECK(sum > 0.1, "the plain plane is lit (%g)", sum);
}

/* A ramp height map h = strength * u'/... tilts the normal by a known
 * angle: slope dh/du on the surface = strength * 1 (value 0..1 over one
 * texture width) * scale / |dpdu|. */
static void ramp_bump_normal(void)
{
    fr_scene s;
    fr_error err;
    const char *json = SCENE_HEAD
        "\"textures\": {\"r\": {\"type\": \"image\", \"file\": \"ramp.png\", \"wrap\": \"clamp\"}},"
        "\"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5], \"bump\": {\"texture\": \"r\", \"strength\": 0.5}}},"
        "\"shapes\": [{\"type\": \"rect\", \"origin\": [-1, -1, 0], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 2, 0], \"material\": \"m\"}],"
        "\"lights\": [{\"type\": \"point\", \"position\": [0, 0, 1], \"intensity\": [1, 1, 1]}]}";
    if (load(json, &s, &err) < 0) {
        CHECK(0, "ramp scene: %s", err.msg);
        return;
    }
    fr_ray r = {v3(0.1f, 0.2f, 1), v3(0, 0, -1), 0.0f};
    fr_hit h;
    trace_closest(&s, &r, INFINITY, &h);
    fr_surface sf;
    trace_surface(&s, &r, &h, &sf);
    fr_material tmp;
    tex_material(&s, &s.materials[0], &sf, &tmp);
    /* Texels hold x/8 for x = 0..7: slope 1/8 per texel = 1 per unit u'
     * (away from the clamped border); h = 0.5 * that; |dpdu| = 2, so the
     * height rises 0.25 per unit of x: normal ~ (-0.25, 0, 1). */
    vec3 expect = v3_norm(v3(-0.25f, 0, 1));
    CHECK(v3_len(v3_sub(sf.ns, expect)) < 1e-5f, "ramp bump normal (%g %g %g), expected (%g %g %g)", sf.ns.x, sf.ns.y,
          sf.ns.z, expect.x, expect.y, expect.z);
    CHECK(v3_dot(sf.ng, v3(0, 0, 1)) == 1.0f, "bump mapping changed the geometric normal");
    scn_free(&s);
}

/* Steep bumps and normal maps: light below a surface never reaches above
 * it, and every sampled direction leaves on wo's side of the geometric
 * surface. */
static void no_leaks(void)
{
    const char *tex = "\"r\": {\"type\": \"image\", \"file\": \"ramp.png\", \"scale\": 7},"
                      "\"g\": {\"type\": \"image\", \"file\": \"grid.png\", \"scale\": 3}";
    const char *mats[] = {
        "{\"type\": \"lambert\", \"albedo\": [0.8, 0.8, 0.8], \"bump\": {\"texture\": \"r\", \"strength\": 50}}",
        "{\"type\": \"phong\", \"diffuse\": [0.3, 0.3, 0.3], \"glossy\": [0.6, 0.6, 0.6], \"exponent\": 5,"
        " \"normal_map\": {\"texture\": \"g\", \"strength\": 8}}",
    };
    for (int k = 0; k < 2; k++) {
        float below[8 * 8 * 3], above[8 * 8 * 3];
        fr_error err;
        if (render_plane(tex, mats[k], v3(0.2f, -1, 0), below, &err) < 0 ||
            render_plane(tex, mats[k], v3(0.2f, 1, 0), above, &err) < 0) {
            CHECK(0, "leak scenes: %s", err.msg);
            return;
        }
        double lit = 0, leak = 0;
        for (int i = 0; i < 8 * 8 * 3; i++)
            lit += above[i], leak += below[i];
        CHECK(leak == 0.0, "material %d: light below the surface leaks through it (%g)", k, leak);
        CHECK(lit > 0.0, "material %d: light above does not light it", k);
    }
    /* Direct: tilt ns hard with the normal map and sample the BSDF. */
    fr_scene s;
    fr_error err;
    char json[1024];
    snprintf(json, sizeof json, SCENE_HEAD "\"textures\": {%s}, \"materials\": {\"m\": %s},"
             "\"shapes\": [{\"type\": \"rect\", \"origin\": [-1, -1, 0], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 2, 0], \"material\": \"m\"}],"
             "\"lights\": [{\"type\": \"point\", \"position\": [0, 0, 1], \"intensity\": [1, 1, 1]}]}", tex, mats[1]);
    if (load(json, &s, &err) < 0) {
        CHECK(0, "normal-map scene: %s", err.msg);
        return;
    }
    int wrong = 0, tilted = 0, tries = 0;
    for (int i = 0; i < 64; i++) {
        fr_ray r = {v3(-0.9f + 0.028f * i, 0.7f - 0.02f * i, 1), v3_norm(v3(0.3f, -0.2f, -1)), 0.0f};
        fr_hit h;
        if (!trace_closest(&s, &r, INFINITY, &h))
            continue;
        fr_surface sf;
        trace_surface(&s, &r, &h, &sf);
        fr_material tmp;
        const fr_material *m = tex_material(&s, &s.materials[0], &sf, &tmp);
        tilted += v3_dot(sf.ns, sf.ng) < 0.5f;
        wrong += v3_dot(sf.ns, sf.ng) <= 0.0f;
        for (int j = 0; j < 64; j++, tries++) {
            fr_bsdf_sample bs;
            float u0 = (j + 0.5f) / 64.0f, u1 = fmodf(j * 0.618034f, 1.0f), u2 = fmodf(j * 0.414214f + i * 0.1f, 1.0f);
            if (bsdf_sample(m, &sf, v3_neg(r.d), u0, u1, u2, &bs))
                wrong += v3_dot(bs.wi, sf.ng) <= 0.0f;
        }
    }
    CHECK(wrong == 0, "%d shading normals or sampled directions on the wrong side of the surface", wrong);
    CHECK(tilted > 0, "the normal map tilted no normal by more than 60 degrees (test too weak)");
    scn_free(&s);
}

/* An image wider than a texture may be is refused by name, and a lookup
 * at a NaN coordinate (clamped or repeated) reads a texel of the image. */
static void sizes_and_nan(void)
{
    fr_scene s;
    fr_error err;
    const char *wide = SCENE_HEAD "\"textures\": {\"w\": {\"type\": \"image\", \"file\": \"wide.png\"}},"
        "\"materials\": {\"a\": {\"type\": \"lambert\", \"albedo\": \"w\"}},"
        "\"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, -3], \"radius\": 1, \"material\": \"a\"}],"
        "\"lights\": [{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}]}";
    int rc = load(wide, &s, &err);
    CHECK(rc < 0 && strstr(err.msg, "wide.png") && strstr(err.msg, "65537x1") && strstr(err.msg, "65536"),
          "an image 65537 pixels wide: %s", rc < 0 ? err.msg : "accepted");
    if (rc == 0)
        scn_free(&s);
    const char *grid = SCENE_HEAD
        "\"textures\": {\"c\": {\"type\": \"image\", \"file\": \"grid.png\", \"wrap\": \"clamp\"},"
        "  \"n\": {\"type\": \"image\", \"file\": \"grid.png\", \"filter\": \"nearest\", \"wrap\": \"clamp\"},"
        "  \"r\": {\"type\": \"image\", \"file\": \"grid.png\"}},"
        "\"materials\": {\"a\": {\"type\": \"lambert\", \"albedo\": \"c\"}, \"b\": {\"type\": \"lambert\", \"albedo\": \"n\"},"
        "  \"d\": {\"type\": \"lambert\", \"albedo\": \"r\"}},"
        "\"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, -3], \"radius\": 1, \"material\": \"a\"}],"
        "\"lights\": [{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": [1, 1, 1]}]}";
    if (load(grid, &s, &err) < 0) {
        CHECK(0, "grid scene: %s", err.msg);
        return;
    }
    for (uint32_t t = 0; t < s.n_textures; t++) {
        vec3 c = tex_eval(&s, t, (vec2){NAN, 0.5f}), d = tex_eval(&s, t, (vec2){0.5f, -NAN});
        CHECK(c.x >= 0.0f && c.x <= 1.0f && d.y >= 0.0f && d.y <= 1.0f, "texture %u at NaN: %g %g", t, c.x, d.y);
    }
    scn_free(&s);
}

/* tex_texels4 against tex_texel, bit for bit: every format at one and three
 * channels over bytes that count up (so every 8- and 16-bit value, every
 * half float among them, NaNs and subnormals included, is decoded). */
static void texels4_match(void)
{
    enum { W = 65536 / 3 + 1 };
    uint32_t *words = calloc((size_t)W * 3 * 4 / 4 + 4, sizeof *words);
    unsigned char *bytes = (unsigned char *)words;
    for (size_t i = 0; i < (size_t)W * 3 * 4; i++)
        bytes[i] = (unsigned char)(i % 2 ? i / 512 : i / 2);   /* 16-bit values 0, 1, 2... little-endian */
    int bad = 0, tried = 0;
    for (uint32_t format = 0; format < FR_TEXEL_FORMATS; format++) {
        for (uint32_t channels = 1; channels <= 3; channels += 2) {
            fr_texture t = {.kind = FR_TEX_IMAGE, .channels = channels, .format = format, .levels = 1};
            t.width = (uint32_t)((size_t)W * 3 * 4 / (channels * tex_format_bytes(format)));
            t.height = 1;
            for (uint32_t x = 0; x + 3 < t.width; x += 4) {
                size_t at[4] = {x + 2, x, x + 3, x + 1};
                float four[4][3], one[3];
                tex_texels4(words, &t, 0, at, four);
                for (int k = 0; k < 4; k++) {
                    tex_texel(words, &t, 0, (uint32_t)at[k], 0, one);
                    bad += memcmp(four[k], one, channels * sizeof(float)) != 0;
                    tried++;
                }
            }
        }
    }
    CHECK(bad == 0, "tex_texels4 differs from tex_texel in %d of %d texels", bad, tried);
    free(words);
}

int main(void)
{
    make_files();
    srgb_curve();
    texels4_match();
    lookups();
    uv_round_trips();
    textured_quad();
    textured_light();
    flat_bump_changes_nothing();
    surface = PLANE;
    flat_bump_changes_nothing();
    surface = RECT;
    ramp_bump_normal();
    no_leaks();
    sizes_and_nan();
    remove_files();
    return check_done();
}
