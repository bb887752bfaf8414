/* test_crypto.c -- the Cryptomatte pass: ids are the specification's
 * hashes of names, a render's ranks decode back to its materials' names
 * through the manifest, and each pixel's coverages sum to one.
 *
 * The specification (Cryptomatte 1.1.0) gives ids of known names in its
 * example manifests: "bunny" 13851a76, "default" 42c9679f,
 * "bunny_porcelain_mat" b24b26d4 (the float bits after uint32_to_float32).
 * The same for objects (crypto_object, object_id), and object_id of known
 * pixels of a scene of named and unnamed shapes. */
#include <cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compile/json_scene.h"
#include "crypto.h"
#include "passes.h"
#include "pathtrace.h"
#include "scenes.h"

#define W 40
#define H 30

static uint32_t id_bits(const char *name)
{
    float f = crypto_float(crypto_murmur3(name, strlen(name), 0));
    uint32_t b;
    memcpy(&b, &f, 4);
    return b;
}

static void check_spec(void)
{
    CHECK(id_bits("bunny") == 0x13851a76u, "bunny: %08x, the specification's 13851a76", id_bits("bunny"));
    CHECK(id_bits("default") == 0x42c9679fu, "default: %08x, the specification's 42c9679f", id_bits("default"));
    CHECK(id_bits("bunny_porcelain_mat") == 0xb24b26d4u, "bunny_porcelain_mat: %08x, the specification's b24b26d4",
          id_bits("bunny_porcelain_mat"));
    /* The exponent is kept in 1..254: no NaN, infinity, zero or denormal. */
    CHECK(isnormal(crypto_float(0xffffffffu)) && isnormal(crypto_float(0)) && isnormal(crypto_float(0x7f800001u)),
          "uint32_to_float32 gives normal floats at the ends");
}

/* The manifest's entry whose hex is the bits of id, or NULL. */
static const char *lookup(const cJSON *manifest, float id)
{
    uint32_t b;
    memcpy(&b, &id, 4);
    char hex[16];
    snprintf(hex, sizeof hex, "%08x", b);
    for (const cJSON *e = manifest ? manifest->child : NULL; e; e = e->next)
        if (cJSON_IsString(e) && !strcmp(e->valuestring, hex))
            return e->string;
    return NULL;
}

/* Scene s (loaded from path) rendered with the id and Cryptomatte passes
 * of its materials, or with `objects` of its objects: the ranks decode to
 * their names. */
static void check_ranks(const char *path, fr_scene *s, int objects)
{
    fr_error err;
    s->settings.width = W;
    s->settings.height = H;
    s->settings.spp = 16;
    uint32_t mask = objects ? 1u << PASS_OBJECT_ID | 1u << PASS_CRYPTO_OBJECT
                            : 1u << PASS_MATERIAL_ID | 1u << PASS_CRYPTO_MATERIAL, nch = pass_channels(mask);
    CHECK(nch == 13, "the id and Cryptomatte passes: 13 channels, got %u", nch);
    float *rgb = malloc((size_t)W * H * 3 * sizeof *rgb), *pass = malloc((size_t)W * H * nch * sizeof *pass);
    pt_render_rows_passes(s, PT_MIS, 0, H, rgb, mask, pass);
    crypto_names names = {s->material_names, s->n_material_names, NULL};
    uint32_t count = s->n_materials;
    if (objects)
        names = (crypto_names){s->object_names, s->n_object_names, "object"}, count = s->n_object_names;
    CHECK(names.n == count && names.n > 0, "%s: %u names for %u materials or objects", path, names.n, count);
    crypto_ids(pass + 1, (size_t)W * H, nch, &names);
    const char *attrs[8], *layer = objects ? "CryptoObject" : "CryptoMaterial";
    char *buf = NULL;
    CHECK(crypto_metadata(layer, &names, count, attrs, &buf, &err) == 0, "metadata: %s", err.msg);
    CHECK(buf && !strcmp(attrs[1], layer) && !strcmp(attrs[3], "MurmurHash3_32") &&
              !strcmp(attrs[5], "uint32_to_float32") && !strncmp(attrs[0], "cryptomatte/", 12) &&
              strstr(attrs[6], "/manifest"),
          "metadata names the layer, the hash and the conversion");
    cJSON *manifest = buf ? cJSON_Parse(attrs[7]) : NULL;
    CHECK(cJSON_IsObject(manifest), "the manifest is a JSON object: %s", buf ? attrs[7] : "(none)");
    int sum_bad = 0, unknown = 0, order_bad = 0, first_bad = 0, named = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        const float *p = pass + i * nch;
        double sum = 0;
        for (int r = 0; r < PASS_CRYPTO_RANKS; r++) {
            float id = p[1 + 2 * r], cov = p[2 + 2 * r];
            sum += cov;
            if (r > 0 && cov > p[2 * r])
                order_bad++;
            if (id == 0.0f)
                continue; /* nothing hit, or an unused rank */
            const char *name = lookup(manifest, id);
            int known = 0;
            for (uint32_t m = 0; name && m < count; m++)
                known |= !strcmp(name, names.v[m].name);
            unknown += !known;
            named += known;
        }
        sum_bad += fabs(sum - 1.0) > 1e-6;
        /* The pixel's first sample hit material_id: it is one of the ranks. */
        if (p[0] > 0) {
            char want[64];
            crypto_name(&names, (uint32_t)p[0] - 1, want);
            int found = 0;
            for (int r = 0; r < PASS_CRYPTO_RANKS; r++) {
                const char *name = lookup(manifest, p[1 + 2 * r]);
                found |= name && !strcmp(name, want);
            }
            first_bad += !found;
        }
    }
    CHECK(named > W * H / 2, "%s: %d ranks decode to %s names", path, named, objects ? "object" : "material");
    CHECK(unknown == 0, "%s: %d ranks whose id is not in the manifest", path, unknown);
    CHECK(sum_bad == 0, "%s: %d pixels whose coverages do not sum to 1", path, sum_bad);
    CHECK(order_bad == 0, "%s: %d ranks with more coverage than the rank before", path, order_bad);
    CHECK(first_bad == 0, "%s: %d pixels whose first sample's id is not ranked", path, first_bad);
    char *table = NULL;
    CHECK(crypto_name_table(&names, count, &table, &err) == 0 && table && table[0] == '[',
          "the id pass's name table: %s", table ? table : err.msg);
    cJSON *t = table ? cJSON_Parse(table) : NULL;
    CHECK(cJSON_IsArray(t) && (uint32_t)cJSON_GetArraySize(t) == count &&
              !strcmp(cJSON_GetArrayItem(t, 0)->valuestring, names.v[0].name),
          "the name table lists the names in order");
    cJSON_Delete(t);
    cJSON_Delete(manifest);
    free(table);
    free(buf);
    free(rgb);
    free(pass);
}

static void check_render(const char *path)
{
    fr_scene s;
    fr_error err;
    if (json_scene_load(path, NULL, &s, &err) < 0) {
        CHECK(0, "%s: %s", path, err.msg);
        return;
    }
    check_ranks(path, &s, 0);
    check_ranks(path, &s, 1);
    scn_free(&s);
}

/* Objects: named shapes by their names, the others by their place;
 * object_id of known pixels. */
static void check_objects(void)
{
    static const char json[] =
        "{\"image\": {\"width\": 40, \"height\": 30, \"spp\": 4},"
        " \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0], \"fov\": 50},"
        " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
        " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 3], \"normal\": [0, 0, -1], \"material\": \"m\"},"
        " {\"type\": \"sphere\", \"name\": \"left ball\", \"center\": [-1.2, 0, 0], \"radius\": 1, \"material\": \"m\"},"
        " {\"type\": \"quad\", \"name\": \"right quad\", \"material\": \"m\","
        "  \"vertices\": [[0.5, -1, 0], [2, -1, 0], [2, 1, 0], [0.5, 1, 0]]}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [0, 3, -3], \"intensity\": [5, 5, 5]}]}";
    fr_scene s;
    test_scene(json, &s);
    CHECK(s.n_object_names == 3 && !strcmp(s.object_names[0].name, "shapes[0]") &&
              !strcmp(s.object_names[1].name, "left ball") && !strcmp(s.object_names[2].name, "right quad"),
          "objects: shapes[0], left ball, right quad (%u names)", s.n_object_names);
    CHECK(s.n_objects == s.n_prims + s.n_planes + s.n_instances, "one object per prim, plane and instance");
    uint32_t mask = 1u << PASS_OBJECT_ID;
    float rgb[W * H * 3], id[W * H];
    pt_render_rows_passes(&s, PT_MIS, 0, H, rgb, mask, id);
    /* Looking along +z with y up, world -x is the image's right: the ball
     * right of the centre, the quad left of it, the wall in the corners. */
    float ball = id[(H / 2) * W + W / 2 + 8], quad = id[(H / 2) * W + W / 2 - 8], wall = id[0];
    CHECK(ball == 2.0f && quad == 3.0f && wall == 1.0f, "object_id: ball %g (2), quad %g (3), wall %g (1)", ball,
          quad, wall);
    static const char bad[] = "{\"image\": {\"width\": 4, \"height\": 4},"
                              " \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0], \"fov\": 50},"
                              " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
                              " \"shapes\": [{\"type\": \"sphere\", \"name\": 3, \"center\": [0, 0, 0],"
                              " \"radius\": 1, \"material\": \"m\"}]}";
    const char *msg;
    CHECK(test_scene_refused(bad, "shapes[0].name", &msg), "a name that is not a string is refused: %s", msg);
    scn_free(&s);
}

int main(void)
{
    check_spec();
    check_render("scenes/cornell.json");
    check_render("scenes/spheres.json");
    check_objects();
    return check_done();
}
