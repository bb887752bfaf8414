/* gengltf.c -- small glTF 2.0 scenes for the tests and the example scene
 * (nothing can be downloaded, so the project writes its own):
 *
 *   gengltf scene   DIR       scene.gltf (buffer in a data: URI), scene.glb,
 *                             and scene.json: the same triangles, materials,
 *                             camera and light as a Franja JSON scene
 *   gengltf frame   DIR       frame.gltf: an emissive square 1 wide at 2 in
 *                             front of a camera with tan(yfov/2) = 0.5 and
 *                             aspectRatio 2
 *   gengltf nodes   DIR       nodes.gltf: emissive squares placed through
 *                             a hierarchy (TRS, a matrix, a mirroring scale)
 *   gengltf uv      DIR PNG   uv.gltf (PNG in a data: URI), uv.glb (PNG in a
 *                             bufferView), uvxf.gltf (KHR_texture_transform):
 *                             a square filling the view, emitting the PNG
 *   gengltf example DIR       courtyard.glb: the example scene of scenes/
 *
 * Everything is written with fprintf from fixed numbers, so the files are
 * the same on every run. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmath.h"

/* ---- growable text and bytes ------------------------------------------ */

typedef struct { char *s; size_t n, cap; } str;

static void grow(str *t, size_t need)
{
    if (t->n + need + 1 <= t->cap)
        return;
    while (t->n + need + 1 > t->cap)
        t->cap = t->cap ? 2 * t->cap : 4096;
    if ((t->s = realloc(t->s, t->cap)) == NULL) {
        fprintf(stderr, "gengltf: out of memory\n");
        exit(1);
    }
}

static void addf(str *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void addf(str *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    grow(t, (size_t)n);
    va_start(ap, fmt);
    vsnprintf(t->s + t->n, (size_t)n + 1, fmt, ap);
    va_end(ap);
    t->n += (size_t)n;
}

static void addb(str *t, const void *p, size_t n)
{
    grow(t, n);
    memcpy(t->s + t->n, p, n);
    t->n += n;
    t->s[t->n] = 0;
}

/* ---- a glTF document under construction -------------------------------- */

typedef struct {
    str bin;                   /* the one buffer */
    str views, accessors, meshes, nodes, materials, extra;
    int n_views, n_accessors, n_meshes, n_nodes, n_materials;
    str roots;                 /* the scene's node list */
    str images, textures, samplers, cameras, lights;
    const char *used;          /* extensionsUsed, JSON array text, or NULL */
    char last_attrs[128];      /* the last mesh's primitive, less its material */
} doc;

static void sep(str *t, int n) { if (n) addf(t, ","); }

static void align4(str *b)
{
    while (b->n % 4)
        addb(b, "", 1);
}

static int view(doc *d, const void *p, size_t n)
{
    align4(&d->bin);
    sep(&d->views, d->n_views);
    addf(&d->views, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", d->bin.n, n);
    addb(&d->bin, p, n);
    return d->n_views++;
}

/* A float accessor of `count` elements of `comps` components. */
static int floats(doc *d, const float *v, int count, int comps)
{
    static const char *const type[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    int bv = view(d, v, (size_t)count * comps * sizeof *v);
    sep(&d->accessors, d->n_accessors);
    addf(&d->accessors, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"%s\"", bv, count,
         type[comps]);
    if (comps == 3) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int i = 0; i < count; i++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], v[3 * i + k]);
                hi[k] = fmaxf(hi[k], v[3 * i + k]);
            }
        addf(&d->accessors, ",\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]", lo[0], lo[1], lo[2], hi[0], hi[1],
             hi[2]);
    }
    addf(&d->accessors, "}");
    return d->n_accessors++;
}

static int indices16(doc *d, const uint16_t *v, int count)
{
    int bv = view(d, v, (size_t)count * sizeof *v);
    sep(&d->accessors, d->n_accessors);
    addf(&d->accessors, "{\"bufferView\":%d,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}", bv, count);
    return d->n_accessors++;
}

static int material(doc *d, const char *body)
{
    sep(&d->materials, d->n_materials);
    addf(&d->materials, "{%s}", body);
    return d->n_materials++;
}

/* A mesh of one primitive: positions (and optional UVs, normals, indices). */
static int mesh(doc *d, const float *pos, int nv, const float *uv, const float *nrm, const uint16_t *idx, int ni,
                int mat)
{
    int p = floats(d, pos, nv, 3);
    int t = uv ? floats(d, uv, nv, 2) : -1, n = nrm ? floats(d, nrm, nv, 3) : -1;
    int i = idx ? indices16(d, idx, ni) : -1;
    int o = snprintf(d->last_attrs, sizeof d->last_attrs, "\"attributes\":{\"POSITION\":%d", p);
    if (t >= 0)
        o += snprintf(d->last_attrs + o, sizeof d->last_attrs - (size_t)o, ",\"TEXCOORD_0\":%d", t);
    if (n >= 0)
        o += snprintf(d->last_attrs + o, sizeof d->last_attrs - (size_t)o, ",\"NORMAL\":%d", n);
    o += snprintf(d->last_attrs + o, sizeof d->last_attrs - (size_t)o, "}");
    if (i >= 0)
        snprintf(d->last_attrs + o, sizeof d->last_attrs - (size_t)o, ",\"indices\":%d", i);
    sep(&d->meshes, d->n_meshes);
    addf(&d->meshes, "{\"primitives\":[{%s,\"material\":%d}]}", d->last_attrs, mat);
    return d->n_meshes++;
}

/* Another mesh with the last mesh's accessors and material `mat`. */
static int mesh_again(doc *d, int mat)
{
    sep(&d->meshes, d->n_meshes);
    addf(&d->meshes, "{\"primitives\":[{%s,\"material\":%d}]}", d->last_attrs, mat);
    return d->n_meshes++;
}

/* A node with JSON members `body`; root: listed in the scene. */
static int node(doc *d, int root, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int node(doc *d, int root, const char *fmt, ...)
{
    char body[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(body, sizeof body, fmt, ap);
    va_end(ap);
    sep(&d->nodes, d->n_nodes);
    addf(&d->nodes, "{%s}", body);
    if (root) {
        addf(&d->roots, "%s%d", d->roots.n ? "," : "", d->n_nodes);
    }
    return d->n_nodes++;
}

static void b64(str *t, const unsigned char *p, size_t n)
{
    static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        char q[4] = {a[v >> 18 & 63], a[v >> 12 & 63], i + 1 < n ? a[v >> 6 & 63] : '=', i + 2 < n ? a[v & 63] : '='};
        addb(t, q, 4);
    }
}

static void json_of(doc *d, str *j, int glb)
{
    addf(j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"franja gengltf\"}");
    if (d->used)
        addf(j, ",\"extensionsUsed\":%s", d->used);
    addf(j, ",\"scene\":0,\"scenes\":[{\"nodes\":[%s]}]", d->roots.s ? d->roots.s : "");
    addf(j, ",\"nodes\":[%s]", d->nodes.s ? d->nodes.s : "");
    if (d->n_meshes)
        addf(j, ",\"meshes\":[%s]", d->meshes.s);
    if (d->n_materials)
        addf(j, ",\"materials\":[%s]", d->materials.s);
    if (d->cameras.n)
        addf(j, ",\"cameras\":[%s]", d->cameras.s);
    if (d->lights.n)
        addf(j, ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[%s]}}", d->lights.s);
    if (d->images.n)
        addf(j, ",\"images\":[%s]", d->images.s);
    if (d->textures.n)
        addf(j, ",\"textures\":[%s]", d->textures.s);
    if (d->samplers.n)
        addf(j, ",\"samplers\":[%s]", d->samplers.s);
    if (d->n_accessors) {
        addf(j, ",\"accessors\":[%s],\"bufferViews\":[%s]", d->accessors.s, d->views.s);
        addf(j, ",\"buffers\":[{\"byteLength\":%zu", d->bin.n);
        if (!glb) {
            addf(j, ",\"uri\":\"data:application/octet-stream;base64,");
            b64(j, (const unsigned char *)d->bin.s, d->bin.n);
            addf(j, "\"");
        }
        addf(j, "}]");
    }
    addf(j, "}\n");
}

static void save(const char *dir, const char *name, const void *p, size_t n)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(p, 1, n, f) != n || fclose(f) != 0) {
        perror(path);
        exit(1);
    }
}

static void le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> 8 * i);
}

static void write_doc(doc *d, const char *dir, const char *name, int glb)
{
    str j = {0};
    json_of(d, &j, glb);
    if (!glb) {
        save(dir, name, j.s, j.n);
        free(j.s);
        return;
    }
    while (j.n % 4)
        addb(&j, " ", 1);
    align4(&d->bin);
    str out = {0};
    unsigned char h[12];
    le32(h, 0x46546C67u);
    le32(h + 4, 2);
    le32(h + 8, (uint32_t)(12 + 8 + j.n + (d->bin.n ? 8 + d->bin.n : 0)));
    addb(&out, h, 12);
    le32(h, (uint32_t)j.n);
    le32(h + 4, 0x4E4F534Au);
    addb(&out, h, 8);
    addb(&out, j.s, j.n);
    if (d->bin.n) {
        le32(h, (uint32_t)d->bin.n);
        le32(h + 4, 0x004E4942u);
        addb(&out, h, 8);
        addb(&out, d->bin.s, d->bin.n);
    }
    save(dir, name, out.s, out.n);
    free(j.s);
    free(out.s);
}

/* ---- scenes ----------------------------------------------------------- */

/* The camera of the JSON comparison: 40 degrees as Franja's JSON reader
 * turns it into radians, so that both files give the same float. */
static float fov40(void) { return 40.0f * (FM_PI / 180.0f); }

static int camera(doc *d, float yfov, float aspect)
{
    int n = (int)(d->cameras.n ? 1 : 0);
    if (d->cameras.n)
        addf(&d->cameras, ",");
    if (aspect > 0)
        addf(&d->cameras, "{\"type\":\"perspective\",\"name\":\"lens%d\",\"perspective\":{\"yfov\":%.9g,"
             "\"aspectRatio\":%.9g,\"znear\":0.01}}", n, yfov, aspect);
    else
        addf(&d->cameras, "{\"type\":\"perspective\",\"name\":\"lens%d\",\"perspective\":{\"yfov\":%.9g,"
             "\"znear\":0.01}}", n, yfov);
    return n;
}

/* Triangles listed corner by corner (no index buffer, no normals): what a
 * JSON "triangle" shape gives the builder. */
typedef struct { float p[9]; } tri;

static void quad_tris(tri *t, const float a[3], const float b[3], const float c[3], const float e[3])
{
    const float *q[2][3] = {{a, b, c}, {a, c, e}};
    for (int k = 0; k < 2; k++)
        for (int v = 0; v < 3; v++)
            memcpy(t[k].p + 3 * v, q[k][v], 3 * sizeof(float));
}

static void json_tris(str *j, const tri *t, int n, const char *mat, const char *name)
{
    for (int i = 0; i < n; i++)
        addf(j, ",\n    {\"type\": \"triangle\", \"name\": \"%s\", \"material\": \"%s\", \"vertices\": "
             "[[%.9g, %.9g, %.9g], [%.9g, %.9g, %.9g], [%.9g, %.9g, %.9g]]}", name, mat, t[i].p[0], t[i].p[1],
             t[i].p[2], t[i].p[3], t[i].p[4], t[i].p[5], t[i].p[6], t[i].p[7], t[i].p[8]);
}

static void gen_scene(const char *dir)
{
    tri floor[2], wall[2], prism[4];
    const float f0[3] = {-2, 0, 2}, f1[3] = {2, 0, 2}, f2[3] = {2, 0, -2}, f3[3] = {-2, 0, -2};
    const float w0[3] = {-2, 0, -2}, w1[3] = {2, 0, -2}, w2[3] = {2, 2.5f, -2}, w3[3] = {-2, 2.5f, -2};
    quad_tris(floor, f0, f1, f2, f3);
    quad_tris(wall, w0, w1, w2, w3);
    /* A tetrahedron on the floor, faces outward. */
    const float a[3] = {-0.6f, 0, 0.3f}, b[3] = {0.5f, 0, 0.4f}, c[3] = {0, 0, -0.7f}, top[3] = {0, 1.2f, 0};
    const float *faces[4][3] = {{a, b, top}, {b, c, top}, {c, a, top}, {a, c, b}};
    for (int i = 0; i < 4; i++)
        for (int v = 0; v < 3; v++)
            memcpy(prism[i].p + 3 * v, faces[i][v], 3 * sizeof(float));
    doc d = {0};
    d.used = "[\"KHR_lights_punctual\",\"KHR_materials_transmission\",\"KHR_materials_ior\"]";
    /* a rough metal, a dielectric over a diffuse base, a rough glass */
    int grey = material(&d, "\"name\":\"grey\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.6,0.6,1],"
                            "\"metallicFactor\":1,\"roughnessFactor\":1}");
    int blue = material(&d, "\"name\":\"blue\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.2,0.3,0.7,1],"
                            "\"metallicFactor\":0,\"roughnessFactor\":0.5}");
    int red = material(&d, "\"name\":\"red\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.7,0.2,0.2,1],"
                           "\"metallicFactor\":0.25,\"roughnessFactor\":0.3},\"extensions\":{"
                           "\"KHR_materials_transmission\":{\"transmissionFactor\":0.8},"
                           "\"KHR_materials_ior\":{\"ior\":1.4}}");
    int m0 = mesh(&d, floor[0].p, 6, NULL, NULL, NULL, 0, grey);
    int m1 = mesh(&d, wall[0].p, 6, NULL, NULL, NULL, 0, blue);
    int m2 = mesh(&d, prism[0].p, 12, NULL, NULL, NULL, 0, red);
    node(&d, 1, "\"name\":\"floor\",\"mesh\":%d", m0);
    node(&d, 1, "\"name\":\"wall\",\"mesh\":%d", m1);
    node(&d, 1, "\"name\":\"prism\",\"mesh\":%d", m2);
    camera(&d, fov40(), 0);
    node(&d, 1, "\"name\":\"cam\",\"camera\":0,\"translation\":[0,1,4]");
    /* 20 W/sr: 20 x 683 candela (scenes/README.md) */
    addf(&d.lights, "{\"type\":\"point\",\"color\":[1,1,1],\"intensity\":13660}");
    node(&d, 1, "\"name\":\"lamp\",\"translation\":[0,3,2],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}");
    write_doc(&d, dir, "scene.gltf", 0);
    write_doc(&d, dir, "scene.glb", 1);

    str j = {0};
    addf(&j, "{\n  \"image\": {\"width\": 640, \"height\": 480, \"spp\": 64, \"max_depth\": 8},\n"
             "  \"camera\": {\"position\": [0, 1, 4], \"target\": [0, 1, 3], \"up\": [0, 1, 0], \"fov\": 40},\n"
             "  \"materials\": {\"grey\": {\"type\": \"principled\", \"base_color\": [0.6, 0.6, 0.6]},\n"
             "                \"blue\": {\"type\": \"principled\", \"base_color\": [0.2, 0.3, 0.7], \"metallic\": 0,"
             " \"roughness\": 0.5},\n"
             "                \"red\": {\"type\": \"principled\", \"base_color\": [0.7, 0.2, 0.2], \"metallic\": 0.25,"
             " \"roughness\": 0.3, \"transmission\": 0.8, \"ior\": 1.4}},\n"
             "  \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 2], \"intensity\": [20, 20, 20]}],\n"
             "  \"shapes\": [");
    str t = {0};
    json_tris(&t, floor, 2, "grey", "floor");
    json_tris(&t, wall, 2, "blue", "wall");
    json_tris(&t, prism, 4, "red", "prism");
    addf(&j, "%s\n  ]\n}\n", t.s + 1);
    save(dir, "scene.json", j.s, j.n);
    free(j.s);
    free(t.s);
}

/* An emissive square facing +z, half-size h, centred at the origin. */
static int emissive_square(doc *d, float h, int mat)
{
    const float p[12] = {-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0};
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    return mesh(d, p, 4, NULL, NULL, idx, 6, mat);
}

static void gen_frame(const char *dir)
{
    doc d = {0};
    int glow = material(&d, "\"emissiveFactor\":[1,1,1],\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]}");
    int sq = emissive_square(&d, 0.5f, glow);
    node(&d, 1, "\"name\":\"square\",\"mesh\":%d,\"translation\":[0,0,-2]", sq);
    camera(&d, (float)(2.0 * atan(0.5)), 2.0f);
    node(&d, 1, "\"name\":\"eye\",\"camera\":0");
    write_doc(&d, dir, "frame.gltf", 0);
}

static void gen_nodes(const char *dir)
{
    doc d = {0};
    int glow = material(&d, "\"emissiveFactor\":[1,1,1],\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]}");
    /* A square of half-size 0.5 in the child's y-z plane, facing -x. */
    const float p[12] = {0, -0.5f, -0.5f, 0, -0.5f, 0.5f, 0, 0.5f, 0.5f, 0, 0.5f, -0.5f};
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    int sq = mesh(&d, p, 4, NULL, NULL, idx, 6, glow);
    /* parent: T(0,0,-4) R_y(90) S(2); child: a matrix translating by
     * (0.25, 0, 0.5).  World: the square faces +z, centre (1, 0, -4.5),
     * half-size 1. */
    node(&d, 1, "\"name\":\"parent\",\"translation\":[0,0,-4],\"rotation\":[0,%.9g,0,%.9g],\"scale\":[2,2,2],"
                "\"children\":[1]", sqrt(0.5), sqrt(0.5));
    node(&d, 0, "\"name\":\"child\",\"mesh\":%d,\"matrix\":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0.25,0,0.5,1]", sq);
    /* A mirrored copy: scale -1 along x keeps the square facing +z (its
     * corners are swapped back), centre (-1.5, 0, -4.5), half-size 0.5. */
    int sq2 = emissive_square(&d, 0.5f, glow);
    node(&d, 1, "\"name\":\"mirrored\",\"mesh\":%d,\"translation\":[-1.5,0,-4.5],\"scale\":[-1,1,1]", sq2);
    camera(&d, (float)(2.0 * atan(0.5)), 1.0f);
    node(&d, 1, "\"name\":\"eye\",\"camera\":0");
    write_doc(&d, dir, "nodes.gltf", 0);
}

static void gen_uv(const char *dir, const char *png)
{
    FILE *f = fopen(png, "rb");
    str img = {0};
    char buf[4096];
    size_t n;
    if (!f) {
        perror(png);
        exit(1);
    }
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        addb(&img, buf, n);
    fclose(f);
    /* A square from (-1, 1) to (1, -1) at z = -1, UV (0, 0) at its top-left
     * corner as glTF has it; the camera sees [-0.5, 0.5] of it. */
    const float p[12] = {-1, 1, -1, 1, 1, -1, 1, -1, -1, -1, -1, -1};
    const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    const uint16_t idx[6] = {0, 2, 1, 0, 3, 2};
    /* Variant 3 (mr.gltf): the image as a white material's
     * metallicRoughnessTexture (roughness in G, metallic in B), lit by a
     * point light at (0.5, 0.5, 0): a smooth dielectric top-left (red), a
     * rough one top-right (green), a smooth metal bottom-left (blue), a
     * rough metal bottom-right (white). */
    for (int variant = 0; variant < 4; variant++) {
        doc d = {0};
        const char *xf = variant == 2 ? ",\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.5,0],"
                                        "\"scale\":[0.5,0.5]}}" : "";
        char body[512];
        if (variant == 3)
            snprintf(body, sizeof body, "\"pbrMetallicRoughness\":{\"metallicRoughnessTexture\":{\"index\":0}}");
        else
            snprintf(body, sizeof body, "\"emissiveFactor\":[1,1,1],\"emissiveTexture\":{\"index\":0%s},"
                     "\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]}", xf);
        if (variant == 3) {
            d.used = "[\"KHR_lights_punctual\"]";
            addf(&d.lights, "{\"type\":\"point\",\"intensity\":683}");
            node(&d, 1, "\"translation\":[0.5,0.5,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}");
        }
        if (variant == 2)
            d.used = "[\"KHR_texture_transform\"]";
        int m = material(&d, body);
        int sq = mesh(&d, p, 4, uv, NULL, idx, 6, m);
        node(&d, 1, "\"mesh\":%d", sq);
        camera(&d, (float)(2.0 * atan(0.5)), 1.0f);
        node(&d, 1, "\"camera\":0");
        addf(&d.samplers, "{\"magFilter\":9728,\"minFilter\":9728,\"wrapS\":33071,\"wrapT\":33071}");
        addf(&d.textures, "{\"source\":0,\"sampler\":0}");
        if (variant == 1) {
            int bv = view(&d, img.s, img.n);
            addf(&d.images, "{\"bufferView\":%d,\"mimeType\":\"image/png\"}", bv);
        } else {
            addf(&d.images, "{\"uri\":\"data:image/png;base64,");
            b64(&d.images, (const unsigned char *)img.s, img.n);
            addf(&d.images, "\"}");
        }
        static const char *const names[] = {"uv.gltf", "uv.glb", "uvxf.gltf", "mr.gltf"};
        write_doc(&d, dir, names[variant], variant == 1);
    }
    free(img.s);
}

/* The example of scenes/: a small courtyard of smooth-shaded objects. */
static void gen_example(const char *dir)
{
    doc d = {0};
    d.used = "[\"KHR_lights_punctual\",\"KHR_materials_emissive_strength\"]";
    /* glTF's factors default to a rough metal: the stone and the clay say
     * they are not metals; the teal is a rough metal */
    int ground = material(&d, "\"name\":\"stone\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.55,0.52,0.48,1],"
                              "\"metallicFactor\":0,\"roughnessFactor\":0.8}");
    int clay = material(&d, "\"name\":\"clay\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.75,0.35,0.2,1],"
                            "\"metallicFactor\":0,\"roughnessFactor\":0.45}");
    int teal = material(&d, "\"name\":\"teal\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.15,0.5,0.5,1],"
                            "\"metallicFactor\":1,\"roughnessFactor\":0.35}");
    int lamp = material(&d, "\"name\":\"lamp\",\"emissiveFactor\":[1,0.8,0.5],\"extensions\":"
                            "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":6}}");
    /* ground */
    const float g[12] = {-4, 0, 4, 4, 0, 4, 4, 0, -4, -4, 0, -4};
    const float gn[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    const uint16_t gi[6] = {0, 1, 2, 0, 2, 3};
    int mg = mesh(&d, g, 4, NULL, gn, gi, 6, ground);
    /* a UV sphere with normals, 48 x 24 */
    enum { SU = 48, SV = 24 };
    static float sp[(SU + 1) * (SV + 1) * 3], sn[(SU + 1) * (SV + 1) * 3];
    static uint16_t si[SU * SV * 6];
    int k = 0;
    for (int j = 0; j <= SV; j++)
        for (int i = 0; i <= SU; i++, k++) {
            double th = M_PI * j / SV, ph = 2 * M_PI * i / SU;
            double x = sin(th) * cos(ph), y = cos(th), z = -sin(th) * sin(ph);
            sp[3 * k] = sn[3 * k] = (float)x;
            sp[3 * k + 1] = sn[3 * k + 1] = (float)y;
            sp[3 * k + 2] = sn[3 * k + 2] = (float)z;
        }
    int q = 0;
    for (int j = 0; j < SV; j++)
        for (int i = 0; i < SU; i++) {
            uint16_t a = (uint16_t)(j * (SU + 1) + i), b = (uint16_t)(a + 1), c = (uint16_t)(a + SU + 1),
                     e = (uint16_t)(c + 1);
            const uint16_t t[6] = {a, c, b, b, c, e};
            memcpy(si + q, t, sizeof t);
            q += 6;
        }
    int ms = mesh(&d, sp, k, NULL, sn, si, q, clay);
    int ms2 = mesh_again(&d, teal);
    int ml = mesh_again(&d, lamp);
    /* a box, as a cube mesh with flat faces (no normals) */
    const float cb[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
    const uint16_t ci[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                             3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
    int mb = mesh(&d, cb, 8, NULL, NULL, ci, 36, teal);
    node(&d, 1, "\"name\":\"ground\",\"mesh\":%d", mg);
    /* a group: a box turned 30 degrees with a sphere on top */
    node(&d, 1, "\"name\":\"group\",\"translation\":[0.9,0,-0.6],\"rotation\":[0,%.9g,0,%.9g],\"children\":[2,3]",
         sin(M_PI / 12), cos(M_PI / 12));
    node(&d, 0, "\"name\":\"box\",\"mesh\":%d,\"translation\":[0,0.5,0],\"scale\":[0.5,0.5,0.5]", mb);
    node(&d, 0, "\"name\":\"ball\",\"mesh\":%d,\"translation\":[0,1.4,0],\"scale\":[0.4,0.4,0.4]", ms);
    node(&d, 1, "\"name\":\"big ball\",\"mesh\":%d,\"translation\":[-0.9,0.7,0.2],\"scale\":[0.7,0.7,0.7]", ms2);
    node(&d, 1, "\"name\":\"glow\",\"mesh\":%d,\"translation\":[0.2,0.25,1.1],\"scale\":[0.25,0.25,0.25]", ml);
    camera(&d, (float)(38.0 * M_PI / 180.0), 1.5f);
    /* the camera 4.6 m away, 1.9 m up, looking down about 17 degrees */
    double a = -17.0 * M_PI / 360.0;
    node(&d, 1, "\"name\":\"camera\",\"camera\":0,\"translation\":[0,1.9,4.6],\"rotation\":[%.9g,0,0,%.9g]",
         sin(a), cos(a));
    addf(&d.lights, "{\"type\":\"point\",\"color\":[1,0.95,0.9],\"intensity\":27320}");
    node(&d, 1, "\"name\":\"key light\",\"translation\":[-2.5,4,3],\"extensions\":{\"KHR_lights_punctual\":"
                "{\"light\":0}}");
    write_doc(&d, dir, "courtyard.glb", 1);
}

int main(int argc, char **argv)
{
    if (argc >= 3 && !strcmp(argv[1], "scene"))
        gen_scene(argv[2]);
    else if (argc >= 3 && !strcmp(argv[1], "frame"))
        gen_frame(argv[2]);
    else if (argc >= 3 && !strcmp(argv[1], "nodes"))
        gen_nodes(argv[2]);
    else if (argc >= 4 && !strcmp(argv[1], "uv"))
        gen_uv(argv[2], argv[3]);
    else if (argc >= 3 && !strcmp(argv[1], "example"))
        gen_example(argv[2]);
    else {
        fprintf(stderr, "usage: gengltf scene|frame|nodes|example DIR, gengltf uv DIR PNG\n");
        return 2;
    }
    return 0;
}
