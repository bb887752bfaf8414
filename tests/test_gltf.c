/* test_gltf.c -- the glTF reader in memory: accessors, nodes, camera and
 * errors.
 *
 * The glTF reader in memory (common/compile/gltf_doc.c, gltf_scene.c, gltf_mat.c):
 * base64 data URIs, accessors of every component type (normalized,
 * strided, sparse), strips and fans, node transforms and the camera,
 * JSON-pointer errors, bounds on instancing, warnings once each. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "texture.h"
#include "compile/gltf_doc.h"
#include "compile/gltf_scene.h"
#include "warnings.h"

/* A check that prints its own condition when it fails. */
#define T(c) CHECK(c, "%s", #c)

/* ---- writing little documents ---------------------------------------- */

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

static char doc_text[65536];

/* A document whose one buffer holds `bin`, with `body` (JSON members
 * after "asset" and "buffers"). */
static const char *docf(const void *bin, size_t n, const char *body)
{
    static char enc[40000];
    b64(bin, n, enc);
    snprintf(doc_text, sizeof doc_text,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
             "\"uri\":\"data:application/octet-stream;base64,%s\"}]%s%s}",
             n, enc, body[0] ? "," : "", body);
    return doc_text;
}


/* Imports text into a fresh builder; returns the import's status. */
static int import(const char *text, fr_builder *b, gltf_options *o, fr_error *err)
{
    gltf_result r;
    bld_init(b);
    n_warnings = 0;
    return gltf_import_mem(text, strlen(text), "t.gltf", &warn_hooks, o, b, &r, err);
}

static int contains(const char *s, const char *frag)
{
    if (strstr(s, frag))
        return 1;
    printf("  message: %s\n  lacks:   %s\n", s, frag);
    return 0;
}

/* ---- tests ------------------------------------------------------------ */

static void test_data_uri(void)
{
    unsigned char *out;
    size_t n;
    char mime[32];
    fr_error e;
    T(gdoc_data_uri("data:image/png;base64,AAECAw==", &out, &n, mime, sizeof mime, &e) == 0);
    T(n == 4 && out[0] == 0 && out[1] == 1 && out[2] == 2 && out[3] == 3);
    T(!strcmp(mime, "image/png"));
    free(out);
    T(gdoc_data_uri("data:;base64,/w", &out, &n, NULL, 0, &e) == 0 && n == 1 && out[0] == 255);
    free(out);
    T(gdoc_data_uri("data:text/plain,hello", &out, &n, NULL, 0, &e) < 0 && contains(e.msg, "base64"));
    T(gdoc_data_uri("data:;base64,AA!A", &out, &n, NULL, 0, &e) < 0 && contains(e.msg, "byte 2"));
    T(gdoc_data_uri("data:;base64,A", &out, &n, NULL, 0, &e) < 0);
}

static void test_accessors(void)
{
    /* bytes 0-3: u8 normalized 0, 255, 51, 0; 4-7: i16 normalized -32768,
     * 32767; 8-19: three f32; 20-21: sparse index 1 (u16); 24-27: value. */
    unsigned char bin[28] = {0, 255, 51, 0, 0x00, 0x80, 0xff, 0x7f};
    float f[3] = {1.5f, -2.0f, 3.25f}, sv = 7.0f;
    memcpy(bin + 8, f, sizeof f);
    bin[20] = 1;
    memcpy(bin + 24, &sv, 4);
    const char *t = docf(bin, sizeof bin,
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":4,\"byteLength\":4},"
        "{\"buffer\":0,\"byteOffset\":8,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":20,\"byteLength\":2},"
        "{\"buffer\":0,\"byteOffset\":24,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":8,\"byteLength\":12,\"byteStride\":8}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5121,\"normalized\":true,\"count\":4,\"type\":\"SCALAR\"},"
        "{\"bufferView\":1,\"componentType\":5122,\"normalized\":true,\"count\":2,\"type\":\"SCALAR\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\","
        " \"sparse\":{\"count\":1,\"indices\":{\"bufferView\":3,\"componentType\":5123},\"values\":{\"bufferView\":4}}},"
        "{\"bufferView\":5,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"},"
        "{\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"SCALAR\"},"
        "{\"bufferView\":0,\"componentType\":5126,\"normalized\":true,\"count\":1,\"type\":\"SCALAR\"}]");
    gltf_doc d;
    fr_error e;
    gdoc_acc a;
    T(gdoc_open_mem(&d, t, strlen(t), "t.gltf", NULL, &e) == 0);
    T(gdoc_accessor(&d, 0, "/x", 1, NULL, &a, &e) == 0);
    T(gdoc_get(&a, 0, 0) == 0.0 && gdoc_get(&a, 1, 0) == 1.0 && fabs(gdoc_get(&a, 2, 0) - 0.2) < 1e-12);
    T(gdoc_accessor(&d, 1, "/x", 1, NULL, &a, &e) == 0);
    T(gdoc_get(&a, 0, 0) == -1.0 && gdoc_get(&a, 1, 0) == 1.0);
    T(gdoc_accessor(&d, 2, "/x", 1, NULL, &a, &e) == 0);
    T(gdoc_get(&a, 0, 0) == 1.5 && gdoc_get(&a, 1, 0) == 7.0 && gdoc_get(&a, 2, 0) == 3.25);
    T(gdoc_accessor(&d, 3, "/x", 1, NULL, &a, &e) == 0); /* stride 8: elements 0 and 2 of the floats */
    T(gdoc_get(&a, 0, 0) == 1.5 && gdoc_get(&a, 1, 0) == 3.25);
    T(gdoc_accessor(&d, 4, "/x", 3, NULL, &a, &e) == 0 && gdoc_get(&a, 1, 2) == 0.0); /* no view: zeros */
    T(gdoc_accessor(&d, 4, "/here", 2, NULL, &a, &e) < 0 && contains(e.msg, "/here: accessor 4 has type VEC3"));
    T(gdoc_accessor(&d, 5, "/x", 1, NULL, &a, &e) < 0 &&
          contains(e.msg, "t.gltf: /accessors/5: 4 elements from byte 0 need 16 bytes; bufferView 2 has 12"));
    T(gdoc_accessor(&d, 6, "/x", 1, NULL, &a, &e) < 0 && contains(e.msg, "/accessors/6: normalized"));
    T(gdoc_accessor(&d, 7, "/x", 1, NULL, &a, &e) < 0 && contains(e.msg, "accessor 7 does not exist"));
    gdoc_free(&d);
}

/* A mesh from positions (float VEC3) with indices (u16) in `mode`. */
static const char *mesh_doc(const float *p, int nv, const unsigned short *idx, int ni, int mode, const char *nodes)
{
    static unsigned char bin[4096];
    size_t pb = (size_t)nv * 12, ib = (size_t)ni * 2;
    memcpy(bin, p, pb);
    memcpy(bin + pb, idx, ib);
    static char body[8192];
    snprintf(body, sizeof body,
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"mode\":%d}]}],"
             "\"nodes\":%s,\"scenes\":[{\"nodes\":[0]}]",
             pb, pb, ib, nv, ni, mode, nodes);
    return docf(bin, pb + ib, body);
}

static const float square[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

static void test_modes(void)
{
    fr_builder b;
    fr_error e;
    gltf_options o;
    gltf_options_default(&o);
    const unsigned short strip[4] = {0, 1, 3, 2}, fan[4] = {0, 1, 2, 3};
    T(import(mesh_doc(square, 4, strip, 4, 5, "[{\"mesh\":0}]"), &b, &o, &e) == 0);
    T(b.triangles.count == 2);
    /* every triangle of the strip faces +z (counter-clockwise) */
    const vec3 *p = b.positions.data;
    for (uint32_t i = 0; i < b.triangles.count; i++) {
        const fr_triangle *t = (const fr_triangle *)b.triangles.data + i;
        vec3 n = v3_cross(v3_sub(p[t->v[1]], p[t->v[0]]), v3_sub(p[t->v[2]], p[t->v[0]]));
        T(n.z > 0);
    }
    bld_free(&b);
    T(import(mesh_doc(square, 4, fan, 4, 6, "[{\"mesh\":0}]"), &b, &o, &e) == 0);
    T(b.triangles.count == 2);
    bld_free(&b);
    T(import(mesh_doc(square, 4, fan, 4, 1, "[{\"mesh\":0}]"), &b, &o, &e) == 0); /* lines */
    T(b.triangles.count == 0 && n_warnings == 1 && contains(last_warning, "points and lines are not rendered"));
    bld_free(&b);
    const unsigned short bad[3] = {0, 1, 4};
    T(import(mesh_doc(square, 4, bad, 3, 4, "[{\"mesh\":0}]"), &b, &o, &e) < 0 &&
          contains(e.msg, "t.gltf: /meshes/0/primitives/0: indices: accessor 1 element 2 is 4, not below the vertex count 4"));
    bld_free(&b);
}

static int close3(vec3 a, double x, double y, double z)
{
    return fabs(a.x - x) < 1e-5 && fabs(a.y - y) < 1e-5 && fabs(a.z - z) < 1e-5;
}

static void test_transforms(void)
{
    fr_builder b;
    fr_error e;
    gltf_options o;
    gltf_options_default(&o);
    const unsigned short tri[6] = {0, 1, 2, 0, 2, 3};
    /* parent: translate (10, 0, 0), rotate 90 degrees about z; child:
     * scale 2 then a matrix translating by (0, 0, 5): vertex (1, 0, 0)
     * -> (2, 0, 0) +(0,0,5) -> rotate: (0, 2, 5) -> (10, 2, 5). */
    char nodes[512];
    snprintf(nodes, sizeof nodes,
             "[{\"children\":[1],\"translation\":[10,0,0],\"rotation\":[0,0,%.17g,%.17g]},"
             "{\"children\":[2],\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,5,1]},{\"mesh\":0,\"scale\":[2,2,2]}]",
             sqrt(0.5), sqrt(0.5));
    const char *t = mesh_doc(square, 4, tri, 6, 4, nodes);
    /* the scene lists node 0 only; nodes 1 and 2 come through children */
    T(import(t, &b, &o, &e) == 0);
    const vec3 *p = b.positions.data;
    T(b.positions.count == 4 && close3(p[1], 10, 2, 5) && close3(p[0], 10, 0, 5) && close3(p[3], 8, 0, 5));
    bld_free(&b);
    /* a placement multiplies from the left */
    o.place[0][3] = 1.0;
    T(import(t, &b, &o, &e) == 0 && close3(((const vec3 *)b.positions.data)[1], 11, 2, 5));
    bld_free(&b);
    gltf_options_default(&o);
    /* forests only */
    T(import(mesh_doc(square, 4, tri, 6, 4, "[{\"children\":[0]}]"), &b, &o, &e) < 0 &&
          contains(e.msg, "/nodes/0/children: node 0 is its own child"));
    bld_free(&b);
    T(import(mesh_doc(square, 4, tri, 6, 4, "[{\"children\":[2]},{\"children\":[2]},{\"mesh\":0}]"), &b, &o, &e) < 0 &&
          contains(e.msg, "/nodes/1/children: node 2 has two parents"));
    bld_free(&b);
    T(import(mesh_doc(square, 4, tri, 6, 4, "[{\"mesh\":0,\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1],"
                                                 "\"scale\":[1,1,1]}]"), &b, &o, &e) < 0 &&
          contains(e.msg, "/nodes/0: both matrix and translation/rotation/scale"));
    bld_free(&b);
    T(import(mesh_doc(square, 4, tri, 6, 4, "[{\"mesh\":0,\"matrix\":[1,0,0,1,0,1,0,0,0,0,1,0,0,0,0,1]}]"), &b, &o,
                 &e) < 0 && contains(e.msg, "the last row must be 0 0 0 1"));
    bld_free(&b);
    /* a mesh drawn by 300 nodes is stored once and placed 300 times; the
     * bound on triangles counts the stored ones */
    char many[8192];
    size_t n = (size_t)snprintf(many, sizeof many, "[{\"children\":[");
    for (int i = 1; i <= 300; i++)
        n += (size_t)snprintf(many + n, sizeof many - n, "%s%d", i > 1 ? "," : "", i);
    n += (size_t)snprintf(many + n, sizeof many - n, "]}");
    for (int i = 1; i <= 300; i++)
        n += (size_t)snprintf(many + n, sizeof many - n, ",{\"mesh\":0}");
    snprintf(many + n, sizeof many - n, "]");
    o.max_triangles = 500;
    T(import(mesh_doc(square, 4, tri, 6, 4, many), &b, &o, &e) == 0 && b.triangles.count == 2 &&
      b.instances.count == 300 && b.meshes.count == 1);
    bld_free(&b);
    o.max_triangles = 1;
    T(import(mesh_doc(square, 4, tri, 6, 4, many), &b, &o, &e) < 0 && contains(e.msg, "more than 1 triangles"));
    bld_free(&b);
}

static void test_camera(void)
{
    fr_builder b;
    fr_error e;
    gltf_options o;
    gltf_options_default(&o);
    const unsigned short tri[6] = {0, 1, 2, 0, 2, 3};
    /* a camera turned 90 degrees about y looks along -x; yfov 0.5 */
    char nodes[512];
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\":0},{\"camera\":0,\"name\":\"side\",\"translation\":[1,2,3],\"rotation\":[0,%.17g,0,%.17g]}]",
             sqrt(0.5), sqrt(0.5));
    char text[65536];
    snprintf(text, sizeof text, "%s", mesh_doc(square, 4, tri, 6, 4, nodes));
    char *end = strrchr(text, '}');
    snprintf(end, sizeof text - (size_t)(end - text),
             ",\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"aspectRatio\":1.5,\"znear\":0.1}}]}");
    /* the camera node is not in the scene: no camera */
    T(import(text, &b, &o, &e) == 0 && b.camera.vfov == 0.0f);
    bld_free(&b);
    char *s = strstr(text, "\"scenes\":[{\"nodes\":[0]}]");
    T(s != NULL);
    if (s)
        s[20] = '1';
    gltf_result r;
    bld_init(&b);
    T(gltf_import_mem(text, strlen(text), "t.gltf", NULL, &o, &b, &r, &e) == 0 && r.camera_found);
    T(close3(b.camera.position, 1, 2, 3) && close3(b.camera.forward, -1, 0, 0) && close3(b.camera.upv, 0, 1, 0));
    T(b.camera.vfov == 0.5f && fabsf(r.aspect - 1.5f) < 1e-7f);
    bld_free(&b);
    o.camera = "front";
    bld_init(&b);
    T(gltf_import_mem(text, strlen(text), "t.gltf", NULL, &o, &b, &r, &e) < 0 &&
          contains(e.msg, "no perspective camera named 'front' in the scene (camera nodes: 'side')"));
    bld_free(&b);
    o.camera = "side";
    bld_init(&b);
    T(gltf_import_mem(text, strlen(text), "t.gltf", NULL, &o, &b, &r, &e) == 0 && r.camera_found);
    bld_free(&b);
}

static void test_documents(void)
{
    fr_builder b;
    fr_error e;
    gltf_options o;
    gltf_options_default(&o);
    T(import("{\"asset\":{}}", &b, &o, &e) < 0 && contains(e.msg, "t.gltf: /asset/version: missing"));
    bld_free(&b);
    T(import("[1]", &b, &o, &e) < 0 && contains(e.msg, "(top level): expected an object"));
    bld_free(&b);
    T(import("{\"asset\":{\"version\":\"2.0\"},\"extensionsRequired\":[\"EXT_meshopt_compression\"]}", &b, &o,
                 &e) < 0 && contains(e.msg, "requires extension EXT_meshopt_compression"));
    bld_free(&b);
    T(import("{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":10,\"uri\":\"/etc/passwd\"}]}", &b, &o,
                 &e) < 0 && contains(e.msg, "/buffers/0: uri '/etc/passwd'"));
    bld_free(&b);
    T(import("{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":10,\"uri\":\"http://x/y.bin\"}]}", &b,
                 &o, &e) < 0 && contains(e.msg, "only relative file names and data: URIs"));
    bld_free(&b);
    T(import("{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":1000,"
                 "\"uri\":\"data:application/octet-stream;base64,AAAA\"}]}", &b, &o, &e) < 0 &&
          contains(e.msg, "/buffers/0: byteLength 1000, but its data: URI holds 3 bytes"));
    bld_free(&b);
    /* warnings: one per feature, however often it occurs */
    const unsigned short tri[6] = {0, 1, 2, 0, 2, 3};
    T(import(mesh_doc(square, 4, tri, 6, 4, "[{\"mesh\":0,\"children\":[1]},{\"mesh\":0}],"
                                                 "\"animations\":[{}],\"extensionsUsed\":[\"EXT_made_up\"]"),
                 &b, &o, &e) == 0);
    T(n_warnings == 2 && b.triangles.count == 2 && b.instances.count == 2);
    bld_free(&b);
}

/* KHR_lights_punctual: point, spot and directional lights, candela and lux
 * over 683, placed and aimed by their nodes (-z of the node). */
static void test_lights(void)
{
    fr_builder b;
    fr_error e;
    gltf_options o;
    gltf_options_default(&o);
    const unsigned short tri[6] = {0, 1, 2, 0, 2, 3};
    char nodes[1024];
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\":0,\"children\":[1,2,3]},"
             "{\"translation\":[1,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
             "{\"translation\":[0,5,0],\"rotation\":[%.17g,0,0,%.17g],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
             "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
             "{\"type\":\"point\",\"color\":[1,0.5,0],\"intensity\":1366},"
             "{\"type\":\"spot\",\"intensity\":683,\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.5}},"
             "{\"type\":\"directional\",\"intensity\":6830}]}}",
             -sqrt(0.5), sqrt(0.5)); /* the spot turned to look down -y */
    T(import(mesh_doc(square, 4, tri, 6, 4, nodes), &b, &o, &e) == 0);
    const fr_light *l = b.lights.data;
    T(b.lights.count == 3);
    if (b.lights.count == 3) {
        T(l[0].kind == FR_LIGHT_POINT && close3(l[0].position, 1, 2, 3) && close3(l[0].intensity, 2, 1, 0));
        T(l[1].kind == FR_LIGHT_SPOT && close3(l[1].position, 0, 5, 0) && close3(l[1].intensity, 1, 1, 1) &&
          close3(l[1].axis, 0, -1, 0));
        T(l[2].kind == FR_LIGHT_SUN && close3(l[2].axis, 0, 0, 1) && close3(l[2].intensity, 10, 10, 10));
    }
    bld_free(&b);
    o.take_lights = 0;
    T(import(mesh_doc(square, 4, tri, 6, 4, nodes), &b, &o, &e) == 0 && b.lights.count == 0);
    bld_free(&b);
}

/* An image decoder for tests: any bytes give a 2x2 RGB image of 0.5. */
static int fake_image(const void *data, size_t len, const char *mime, scene_image *img, fr_error *err)
{
    (void)data;
    (void)len;
    (void)mime;
    (void)err;
    img->width = img->height = 2;
    img->channels = 3;
    img->pixels = malloc(12 * sizeof(float));
    for (int i = 0; img->pixels && i < 12; i++)
        img->pixels[i] = 0.5f;
    return img->pixels ? 0 : -1;
}

/* Materials, each the principled model: emission with
 * KHR_materials_emissive_strength, transmission (factor and texture) with
 * KHR_materials_ior, a
 * base colour texture (sRGB-decoded) with its sampler and
 * KHR_texture_transform rewritten for Franja's flipped v, metallic and
 * roughness factors with the metallicRoughness texture (linear), glTF's
 * default material. */
static void test_materials(void)
{
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const char *t = docf(tri, sizeof tri,
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0},"
        "{\"attributes\":{\"POSITION\":0},\"material\":1},{\"attributes\":{\"POSITION\":0},\"material\":2},"
        "{\"attributes\":{\"POSITION\":0}}]}],"
        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
        "\"materials\":[{\"emissiveFactor\":[1,0.5,0],\"doubleSided\":true,"
        "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}},"
        "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"baseColorTexture\":{\"index\":0,"
        "\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.25,0.5],\"scale\":[2,4]}}}},"
        "\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":0.75,\"transmissionTexture\":{\"index\":1}},"
        "\"KHR_materials_ior\":{\"ior\":1.3}}},"
        "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.9,0.6,0.3,1],\"metallicFactor\":0.75,"
        "\"roughnessFactor\":0.25,\"metallicRoughnessTexture\":{\"index\":1}}}],"
        "\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":0}],"
        "\"samplers\":[{\"magFilter\":9728,\"wrapS\":33071,\"wrapT\":33071}],"
        "\"images\":[{\"uri\":\"data:image/png;base64,AAAA\"}]");
    scene_hooks h = {.image_mem = fake_image, .warn = on_warn};
    gltf_options o;
    gltf_options_default(&o);
    fr_builder b;
    gltf_result r;
    fr_error e;
    bld_init(&b);
    T(gltf_import_mem(t, strlen(t), "t.gltf", &h, &o, &b, &r, &e) == 0);
    /* a texture per use: base colour, transmission, metallicRoughness */
    T(b.materials.count == 4 && b.textures.count == 3);
    if (b.materials.count == 4 && b.textures.count == 3) {
        const fr_material *m = b.materials.data;
        /* glTF's default material (the last primitive's): white, metallic 1, roughness 1 */
        for (int i = 0; i < 4; i++)
            T(m[i].model == FR_MAT_PRINCIPLED && m[i].mf_flags == 0);
        T(close3(m[0].emission, 4, 2, 0) && m[0].two_sided == 1 && close3(m[0].diffuse, 1, 1, 1) &&
          m[0].metallic == 1.0f && m[0].roughness == 1.0f);
        T(close3(m[3].diffuse, 1, 1, 1) && m[3].metallic == 1.0f && m[3].roughness == 1.0f &&
          v3_is_zero(m[3].emission) && m[3].ior == 1.5f && m[3].transmission == 0.0f);
        /* transmission and ior: the share of the dielectric that refracts */
        T(close3(m[1].diffuse, 0.5, 0.5, 0.5) && m[1].transmission == 0.75f && m[1].ior == 1.3f);
        /* transmissionTexture: the factor scales its R channel, read linearly */
        T(m[1].tex_transmission == 1 && m[0].tex_transmission == FR_NONE && m[2].tex_transmission == FR_NONE);
        T(m[1].tex_diffuse == 0 && m[1].tex_roughness == FR_NONE && m[1].tex_metallic == FR_NONE &&
          v3_is_zero(m[1].emission) && v3_is_zero(m[1].transmit));
        /* metallicRoughnessTexture: the factors scale its G (roughness) and
         * B (metallic) channels, read linearly (texture.c) */
        T(close3(m[2].diffuse, 0.9, 0.6, 0.3) && m[2].metallic == 0.75f && m[2].roughness == 0.25f &&
          m[2].tex_diffuse == FR_NONE && m[2].tex_roughness == 2 && m[2].tex_metallic == 2 &&
          m[2].transmission == 0.0f);
        const fr_texture *x = b.textures.data;
        T(x->kind == FR_TEX_IMAGE && x->width == 2 && x->channels == 3);
        T(x->filter == FR_FILTER_NEAREST && x->wrap == FR_WRAP_CLAMP);
        /* v' = 4 v' + (1 - 4 - 0.5) */
        T(x->scale.u == 2.0f && x->scale.v == 4.0f && x->offset.u == 0.25f && x->offset.v == -3.5f);
        float v[3];
        tex_texel(b.texels.data, &x[0], 0, 0, 0, v);
        T(fabsf(v[0] - 0.2140411f) < 1e-4f); /* 0.5 sRGB-decoded */
        T(x[1].wrap == FR_WRAP_REPEAT && x[1].filter == FR_FILTER_BILINEAR && x[1].first != x[0].first);
        tex_texel(b.texels.data, &x[1], 0, 0, 0, v);
        T(v[0] == 0.5f); /* data: not decoded */
        tex_texel(b.texels.data, &x[2], 0, 0, 0, v);
        T(x[2].wrap == FR_WRAP_REPEAT && v[0] == 0.5f);
    }
    bld_free(&b);
    /* without a decoder, the texture is dropped with a warning */
    bld_init(&b);
    n_warnings = 0;
    T(gltf_import_mem(t, strlen(t), "t.gltf", &warn_hooks, &o, &b, &r, &e) == 0 && b.textures.count == 0 &&
      n_warnings == 1 && contains(last_warning, "images are not decoded"));
    bld_free(&b);
}

/* A KHR_texture_transform with a rotation, shared by a material's
 * textures, moves the vertices' UVs (rotation counter-clockwise in glTF's
 * UV space: (1, 0) -> (0, -1) for a quarter turn), then v is flipped. */
static void test_uv_rotation(void)
{
    float bin[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* UVs: */ 0, 0, 1, 0, 0, 1};
    char body[2048];
    for (int mixed = 0; mixed < 2; mixed++) {
        snprintf(body, sizeof body,
            "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
            "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],"
            "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
            "\"materials\":[{\"emissiveFactor\":[1,1,1],\"emissiveTexture\":{\"index\":0%s},"
            "\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,"
            "\"extensions\":{\"KHR_texture_transform\":{\"rotation\":1.5707963267948966,\"offset\":[0,0.5]}}}}}],"
            "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,AAAA\"}]",
            mixed ? "" : ",\"extensions\":{\"KHR_texture_transform\":{\"rotation\":1.5707963267948966,\"offset\":[0,0.5]}}");
        const char *t = docf(bin, sizeof bin, body);
        scene_hooks h = {.image_mem = fake_image, .warn = on_warn};
        gltf_options o;
        gltf_options_default(&o);
        fr_builder b;
        gltf_result r;
        fr_error e;
        bld_init(&b);
        n_warnings = 0;
        T(gltf_import_mem(t, strlen(t), "t.gltf", &h, &o, &b, &r, &e) == 0 && b.uvs.count == 3);
        if (b.uvs.count == 3 && b.textures.count == 2) {
            const vec2 *uv = b.uvs.data;
            const fr_texture *x = b.textures.data;
            if (!mixed) {
                /* (0,0) -> (0,0.5) -> (0,0.5); (1,0) -> (0,-0.5) -> (0,1.5); (0,1) -> (1,0.5) -> (1,0.5) */
                T(fabsf(uv[0].u) < 1e-6f && fabsf(uv[0].v - 0.5f) < 1e-6f);
                T(fabsf(uv[1].u) < 1e-6f && fabsf(uv[1].v - 1.5f) < 1e-6f);
                T(fabsf(uv[2].u - 1.0f) < 1e-6f && fabsf(uv[2].v - 0.5f) < 1e-6f);
                T(x[0].scale.u == 1.0f && x[0].scale.v == 1.0f && x[0].offset.u == 0.0f && x[0].offset.v == 0.0f);
                T(x[1].scale.v == 1.0f && x[1].offset.v == 0.0f && n_warnings == 0);
            } else {
                /* different transforms: UVs as in the file (v flipped), rotation warned */
                T(uv[1].u == 1.0f && uv[1].v == 1.0f && n_warnings == 1 && contains(last_warning, "rotation"));
            }
        } else {
            T(0);
        }
        bld_free(&b);
    }
}

int main(void)
{
    test_data_uri();
    test_accessors();
    test_modes();
    test_transforms();
    test_camera();
    test_documents();
    test_lights();
    test_materials();
    test_uv_rotation();
    return check_done();
}
