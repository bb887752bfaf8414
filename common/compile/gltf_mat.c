/* gltf_mat.c -- glTF materials, textures and images (gltf_mat.h). */
#include "compile/gltf_mat.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "file.h"
#include "fmath.h"
#include "compile/json_appear.h"
#include "compile/texstore.h"

enum { WRAP_CLAMP = 33071, WRAP_MIRROR = 33648, WRAP_REPEAT = 10497, FILTER_NEAREST = 9728 };

int gmat_begin(gmat_ctx *c, gltf_doc *d, const scene_hooks *hooks, fr_builder *b, fr_error *err)
{
    memset(c, 0, sizeof *c);
    c->doc = d;
    c->hooks = hooks;
    c->b = b;
    uint32_t n = d->materials.n + 1, ni = d->images.n ? d->images.n : 1;
    c->mat_of = malloc(n * sizeof *c->mat_of);
    c->uvxf = malloc(n * sizeof *c->uvxf);
    c->has_uvxf = calloc(n, 1);
    for (int k = 0; k < 2; k++) {
        c->img[k] = calloc(ni, sizeof *c->img[k]);
        c->img_done[k] = calloc(ni, 1);
    }
    if (!c->mat_of || !c->uvxf || !c->has_uvxf || !c->img[0] || !c->img[1] || !c->img_done[0] || !c->img_done[1]) {
        gmat_end(c);
        return gdoc_fail(d, err, NULL, "out of memory");
    }
    for (uint32_t i = 0; i < n; i++)
        c->mat_of[i] = FR_NONE;
    return 0;
}

void gmat_end(gmat_ctx *c)
{
    free(c->mat_of);
    free(c->uvxf);
    free(c->has_uvxf);
    for (int k = 0; k < 2; k++) {
        free(c->img[k]);
        free(c->img_done[k]);
    }
    memset(c, 0, sizeof *c);
}

/* ---- images ----------------------------------------------------------- */

/* Decodes image `i` (once per colour space) into *t's image fields.
 * Returns 0, 1 when it could not be decoded for want of a decoder (warned),
 * or -1. */
static int image(gmat_ctx *c, uint32_t i, int srgb, fr_texture *t, fr_error *err)
{
    gltf_doc *d = c->doc;
    if (c->img_done[srgb][i]) {
        *t = c->img[srgb][i];
        return 0;
    }
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/images/%u", i);
    const cJSON *o = d->images.v[i];
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(o, "uri");
    const cJSON *mime = cJSON_GetObjectItemCaseSensitive(o, "mimeType");
    uint32_t view;
    if (gdoc_index(d, o, ptr, "bufferView", 0, d->buffer_views.n, "bufferViews", &view, err) < 0)
        return -1;
    if (!uri == (view == UINT32_MAX))
        return gdoc_fail(d, err, ptr, "expected exactly one of uri and bufferView");
    if (uri && !cJSON_IsString(uri))
        return gdoc_fail(d, err, ptr, "uri: expected a string");
    if (mime && !cJSON_IsString(mime))
        return gdoc_fail(d, err, ptr, "mimeType: expected a string");
    scene_image img;
    memset(&img, 0, sizeof img);
    texstore_target into;
    texstore_target_init(&into, c->b, srgb);
    img.dest = &into.dest;
    fr_error e;
    int rc;
    int in_memory = !uri || !strncmp(uri->valuestring, "data:", 5);
    if (!c->hooks || (in_memory ? !c->hooks->image_mem : !c->hooks->texture)) {
        gdoc_warn(d, "images", "images are not decoded here (no image decoder): textures ignored");
        return 1;
    }
    if (!uri) {
        const unsigned char *bytes;
        size_t len;
        if (gdoc_view_bytes(d, view, ptr, &bytes, &len, err) < 0)
            return -1;
        rc = c->hooks->image_mem(bytes, len, mime ? mime->valuestring : "", &img, &e);
    } else if (in_memory) {
        unsigned char *bytes;
        size_t len;
        char type[64];
        if (gdoc_data_uri(uri->valuestring, &bytes, &len, type, sizeof type, &e) < 0)
            return gdoc_fail(d, err, ptr, "uri: %s", e.msg);
        rc = c->hooks->image_mem(bytes, len, type, &img, &e);
        free(bytes);
    } else {
        char path[4096], *data;
        size_t len;
        if (gdoc_uri_path(d, uri->valuestring, ptr, path, sizeof path, err) < 0 ||
            budget_take_file(d->budget, path, path, err) < 0)
            return -1;
        if (confine_read(d->scope, path, FILE_READ_MAX, &data, &len, &e) < 0)
            return gdoc_fail(d, err, ptr, "uri: %s", e.msg);
        rc = c->hooks->texture(path, data, len, &img, &e);
        free(data);
    }
    if (rc < 0) {
        if (!img.borrowed)
            free(img.pixels);
        return gdoc_fail(d, err, ptr, "%s", e.msg);
    }
    fr_texture tex;
    memset(&tex, 0, sizeof tex);
    rc = texstore_image(c->b, &img, srgb, &tex, ptr, &e);
    if (!img.borrowed)
        free(img.pixels);
    if (rc < 0)
        return gdoc_fail(d, err, NULL, "%s", e.msg);
    c->img[srgb][i] = tex;
    c->img_done[srgb][i] = 1;
    *t = tex;
    return 0;
}

/* ---- textures --------------------------------------------------------- */

static int wrap_mode(gltf_doc *d, uint64_t w, const char *ptr, fr_error *err)
{
    if (w == WRAP_REPEAT)
        return FR_WRAP_REPEAT;
    if (w == WRAP_CLAMP)
        return FR_WRAP_CLAMP;
    if (w == WRAP_MIRROR) {
        gdoc_warn(d, "mirror", "%s: MIRRORED_REPEAT wrapping is not supported: repeated instead", ptr);
        return FR_WRAP_REPEAT;
    }
    return gdoc_fail(d, err, ptr, "wrap mode %llu: expected 33071, 33648 or 10497", (unsigned long long)w);
}

/* The sampler's wrap and filter into *t. */
static int sampler(gltf_doc *d, uint32_t s, fr_texture *t, fr_error *err)
{
    t->wrap = FR_WRAP_REPEAT;
    t->filter = FR_FILTER_BILINEAR;
    if (s == UINT32_MAX)
        return 0;
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/samplers/%u", s);
    const cJSON *o = d->samplers.v[s];
    uint64_t ws, wt, mag, mn;
    if (gdoc_uint(d, o, ptr, "wrapS", WRAP_REPEAT, 65535, &ws, err) < 0 ||
        gdoc_uint(d, o, ptr, "wrapT", WRAP_REPEAT, 65535, &wt, err) < 0 ||
        gdoc_uint(d, o, ptr, "magFilter", 9729, 65535, &mag, err) < 0 ||
        gdoc_uint(d, o, ptr, "minFilter", 9729, 65535, &mn, err) < 0)
        return -1;
    int a = wrap_mode(d, ws, ptr, err), b = a < 0 ? -1 : wrap_mode(d, wt, ptr, err);
    if (a < 0 || b < 0)
        return -1;
    if (a != b)
        gdoc_warn(d, "wrapST", "%s: different wrap modes along S and T are not supported: wrapS used for both", ptr);
    t->wrap = (uint32_t)a;
    t->filter = mag == FILTER_NEAREST ? FR_FILTER_NEAREST : FR_FILTER_BILINEAR;
    return 0;
}

/* A textureInfo object (member `key` of o at `ptr`) as a Franja texture;
 * *scale receives normalTexture's scale when wanted. */
static int texture_info(gmat_ctx *c, const cJSON *o, const char *ptr, const char *key, int srgb, gmat_texref *r,
                        double *scale, fr_error *err)
{
    gltf_doc *d = c->doc;
    r->tex = FR_NONE;
    const cJSON *ti;
    if (gdoc_object(d, o, ptr, key, &ti, err) < 0)
        return -1;
    if (!ti)
        return 0;
    char p[160], tp[48];
    snprintf(p, sizeof p, "%s/%s", ptr, key);
    uint32_t t, src, smp;
    uint64_t texcoord;
    if (gdoc_index(d, ti, p, "index", 1, d->textures.n, "textures", &t, err) < 0 ||
        gdoc_uint(d, ti, p, "texCoord", 0, 255, &texcoord, err) < 0 ||
        (scale && gdoc_number(d, ti, p, "scale", 1.0, scale, err) < 0))
        return -1;
    snprintf(tp, sizeof tp, "/textures/%u", t);
    if (gdoc_index(d, d->textures.v[t], tp, "source", 0, d->images.n, "images", &src, err) < 0 ||
        gdoc_index(d, d->textures.v[t], tp, "sampler", 0, d->samplers.n, "samplers", &smp, err) < 0)
        return -1;
    if (src == UINT32_MAX) {
        gdoc_warn(d, "nosource", "%s: a texture without a core image source (PNG or JPEG) is ignored", tp);
        return 0;
    }
    fr_texture tex;
    memset(&tex, 0, sizeof tex);
    tex.kind = FR_TEX_IMAGE;
    tex.scale = (vec2){1.0f, 1.0f};
    if (sampler(d, smp, &tex, err) < 0)
        return -1;
    /* KHR_texture_transform, in glTF's UV (v down): t = offset + scale * uv.
     * With Franja's v' = 1 - v on both sides: v' -> sv v' + 1 - sv - ov. */
    double off[2] = {0, 0}, sc[2] = {1, 1}, rot = 0;
    const cJSON *ext, *tt = NULL;
    if (gdoc_object(d, ti, p, "extensions", &ext, err) < 0)
        return -1;
    if (ext) {
        char ep[200];
        snprintf(ep, sizeof ep, "%s/extensions", p);
        if (gdoc_object(d, ext, ep, "KHR_texture_transform", &tt, err) < 0)
            return -1;
    }
    if (tt) {
        char ep[240];
        int has;
        snprintf(ep, sizeof ep, "%s/extensions/KHR_texture_transform", p);
        if (gdoc_numbers(d, tt, ep, "offset", 2, off, &has, err) < 0 ||
            gdoc_numbers(d, tt, ep, "scale", 2, sc, &has, err) < 0 || gdoc_number(d, tt, ep, "rotation", 0, &rot, err) < 0 ||
            gdoc_uint(d, tt, ep, "texCoord", texcoord, 255, &texcoord, err) < 0)
            return -1;
    }
    /* The material's textures' transforms: one with a rotation is applied
     * to the vertices' UVs instead, if they all share it (gmat_material). */
    const double xf[5] = {off[0], off[1], sc[0], sc[1], rot};
    if (!c->xf_seen)
        memcpy(c->xf, xf, sizeof xf);
    else if (memcmp(c->xf, xf, sizeof xf) != 0)
        c->xf_mixed = 1;
    c->xf_seen = 1;
    c->xf_rot |= rot != 0.0;
    if (texcoord != 0)
        gdoc_warn(d, "texcoord", "%s: texCoord %llu: only TEXCOORD_0 is used", p, (unsigned long long)texcoord);
    tex.scale = (vec2){(float)sc[0], (float)sc[1]};
    tex.offset = (vec2){(float)off[0], (float)(1.0 - sc[1] - off[1])};
    fr_texture img;
    memset(&img, 0, sizeof img);
    int rc = image(c, src, srgb, &img, err);
    if (rc != 0)
        return rc < 0 ? -1 : 0;
    tex.width = img.width;
    tex.height = img.height;
    tex.channels = img.channels;
    tex.format = img.format;
    tex.levels = img.levels;
    memcpy(tex.first, img.first, sizeof tex.first);
    if ((r->tex = bld_push(&c->b->textures, &tex)) == FR_NONE)
        return gdoc_fail(d, err, p, "out of memory");
    return 0;
}

/* ---- materials -------------------------------------------------------- */

static float unit(double x) { return x < 0.0 ? 0.0f : x > 1.0 ? 1.0f : (float)x; }

/* Reads glTF material `index` (UINT32_MAX: the default) into *v, making
 * the textures it uses. */
static int gmat_read(gmat_ctx *c, uint32_t index, gmat_values *v, fr_error *err)
{
    gltf_doc *d = c->doc;
    memset(v, 0, sizeof *v);
    v->base = v3s(1.0f);
    v->alpha = 1.0f;
    v->metallic = v->roughness = 1.0f;
    v->normal_scale = 1.0f;
    v->ior = 1.5f;
    v->t_base.tex = v->t_metal_rough.tex = v->t_normal.tex = v->t_emissive.tex = v->t_transmission.tex = FR_NONE;
    if (index == UINT32_MAX)
        return 0;
    char ptr[48], pp[96];
    snprintf(ptr, sizeof ptr, "/materials/%u", index);
    snprintf(pp, sizeof pp, "%s/pbrMetallicRoughness", ptr);
    const cJSON *o = d->materials.v[index], *pbr, *ext;
    double bc[4] = {1, 1, 1, 1}, em[3] = {0, 0, 0}, metal = 1, rough = 1, nscale = 1, strength = 1;
    int has;
    if (gdoc_object(d, o, ptr, "pbrMetallicRoughness", &pbr, err) < 0 || gdoc_object(d, o, ptr, "extensions", &ext, err) < 0 ||
        gdoc_numbers(d, o, ptr, "emissiveFactor", 3, em, &has, err) < 0 ||
        texture_info(c, o, ptr, "normalTexture", 0, &v->t_normal, &nscale, err) < 0 ||
        texture_info(c, o, ptr, "emissiveTexture", 1, &v->t_emissive, NULL, err) < 0)
        return -1;
    if (pbr && (gdoc_numbers(d, pbr, pp, "baseColorFactor", 4, bc, &has, err) < 0 ||
                gdoc_number(d, pbr, pp, "metallicFactor", 1, &metal, err) < 0 ||
                gdoc_number(d, pbr, pp, "roughnessFactor", 1, &rough, err) < 0 ||
                texture_info(c, pbr, pp, "baseColorTexture", 1, &v->t_base, NULL, err) < 0 ||
                texture_info(c, pbr, pp, "metallicRoughnessTexture", 0, &v->t_metal_rough, NULL, err) < 0))
        return -1;
    if (cJSON_GetObjectItemCaseSensitive(o, "occlusionTexture"))
        gdoc_warn(d, "occlusion", "%s/occlusionTexture: ambient occlusion maps are not used (the renderer traces "
                  "occlusion)", ptr);
    const cJSON *am = cJSON_GetObjectItemCaseSensitive(o, "alphaMode");
    if (cJSON_IsString(am) && strcmp(am->valuestring, "OPAQUE") != 0)
        gdoc_warn(d, "alpha", "%s/alphaMode: %s is not supported: surfaces are opaque", ptr, am->valuestring);
    const cJSON *ds = cJSON_GetObjectItemCaseSensitive(o, "doubleSided");
    if (ds && !cJSON_IsBool(ds))
        return gdoc_fail(d, err, ptr, "doubleSided: expected true or false");
    v->double_sided = cJSON_IsTrue(ds);
    if (ext) {
        char ep[160];
        const cJSON *x;
        double t = 0, ior = 1.5;
        snprintf(ep, sizeof ep, "%s/extensions/KHR_materials_emissive_strength", ptr);
        if (gdoc_object(d, ext, ptr, "KHR_materials_emissive_strength", &x, err) < 0 ||
            (x && gdoc_number(d, x, ep, "emissiveStrength", 1, &strength, err) < 0))
            return -1;
        snprintf(ep, sizeof ep, "%s/extensions/KHR_materials_transmission", ptr);
        if (gdoc_object(d, ext, ptr, "KHR_materials_transmission", &x, err) < 0 ||
            (x && (gdoc_number(d, x, ep, "transmissionFactor", 0, &t, err) < 0 ||
                   texture_info(c, x, ep, "transmissionTexture", 0, &v->t_transmission, NULL, err) < 0)))
            return -1;
        snprintf(ep, sizeof ep, "%s/extensions/KHR_materials_ior", ptr);
        if (gdoc_object(d, ext, ptr, "KHR_materials_ior", &x, err) < 0 ||
            (x && gdoc_number(d, x, ep, "ior", 1.5, &ior, err) < 0))
            return -1;
        if (strength < 0)
            return gdoc_fail(d, err, ep, "emissiveStrength: expected a number >= 0");
        if (!(ior == 0.0 || (ior >= 1.0 && ior <= 16.0)))
            return gdoc_fail(d, err, ep, "ior: expected 0 or a number in [1, 16]");
        v->transmission = unit(t);
        v->ior = ior == 0.0 || ior == 1.0 ? 1.5f : (float)ior;
        if (ior == 0.0 || ior == 1.0)
            gdoc_warn(d, "ior1", "%s: ior %g (no refraction) is not supported: 1.5 used", ep, ior);
    }
    v->base = v3(unit(bc[0]), unit(bc[1]), unit(bc[2]));
    v->alpha = unit(bc[3]);
    v->metallic = unit(metal);
    v->roughness = unit(rough);
    v->normal_scale = (float)fabs(nscale);
    for (int k = 0; k < 3; k++)
        if (!(em[k] >= 0.0))
            return gdoc_fail(d, err, ptr, "emissiveFactor: expected numbers >= 0");
    v->emissive = v3((float)(em[0] * strength), (float)(em[1] * strength), (float)(em[2] * strength));
    return 0;
}

/* Maps read values onto a Franja material (initialized here). */
static void gmat_to_franja(gmat_ctx *c, const gmat_values *v, fr_material *m)
{
    bld_material_init(m);
    m->bump_strength = 1.0f;   /* as the JSON reader leaves a material without bump map */
    /* glTF's metallic-roughness model is Franja's principled material:
     * the base colour and its texture, the metallic and roughness factors,
     * the metallicRoughness texture's B and G channels (texture.c reads
     * them so), KHR_materials_transmission and KHR_materials_ior. */
    m->model = FR_MAT_PRINCIPLED;
    m->diffuse = v->base;
    m->tex_diffuse = v->t_base.tex;
    m->metallic = v->metallic;
    m->roughness = v->roughness;
    m->tex_roughness = m->tex_metallic = v->t_metal_rough.tex;
    m->transmission = v->transmission;
    m->ior = v->ior;
    m->tex_transmission = v->t_transmission.tex;
    m->emission = v->emissive;
    if (!v3_is_zero(v->emissive))
        m->tex_emission = v->t_emissive.tex;
    m->two_sided = (uint32_t)v->double_sided;
    if (v->t_normal.tex != FR_NONE) {
        const fr_texture *t = (const fr_texture *)c->b->textures.data + v->t_normal.tex;
        if (t->channels == 3) {
            m->tex_normal = v->t_normal.tex;
            m->normal_strength = v->normal_scale;
        } else {
            gdoc_warn(c->doc, "normal1", "a normal texture without three channels is ignored");
        }
    }
    bsdf_material_finish(m);
}

int gmat_material(gmat_ctx *c, uint32_t index, uint32_t *out, const double **uvxf, fr_error *err)
{
    uint32_t slot = index == UINT32_MAX ? c->doc->materials.n : index;
    if (c->mat_of[slot] == FR_NONE) {
        gmat_values v;
        fr_material m;
        uint32_t first_tex = c->b->textures.count;
        c->xf_seen = c->xf_mixed = c->xf_rot = 0;
        if (gmat_read(c, index, &v, err) < 0)
            return -1;
        if (c->xf_rot) {
            if (c->xf_mixed) {
                gdoc_warn(c->doc, "rotation", "/materials/%u: KHR_texture_transform rotation is not supported when "
                          "a material's textures have different transforms: ignored", index);
            } else {
                /* u' = ou + cos(r) su u + sin(r) sv v, v' = ov - sin(r) su u + cos(r) sv v:
                 * the extension's translation x rotation x scale, its rotation
                 * matrix written in rows (cos, sin; -sin, cos): counter-
                 * clockwise in glTF's UV space, whose v runs down the image. */
                float snf, csf;        /* fmath: the worker links this module (JSON scenes) */
                fm_sincosf((float)c->xf[4], &snf, &csf);
                double sn = snf, cs = csf, *x = c->uvxf[slot];
                x[0] = cs * c->xf[2];
                x[1] = sn * c->xf[3];
                x[2] = c->xf[0];
                x[3] = -sn * c->xf[2];
                x[4] = cs * c->xf[3];
                x[5] = c->xf[1];
                c->has_uvxf[slot] = 1;
                fr_texture *t = c->b->textures.data;
                for (uint32_t k = first_tex; k < c->b->textures.count; k++) {
                    t[k].scale = (vec2){1.0f, 1.0f};
                    t[k].offset = (vec2){0.0f, 0.0f};
                }
            }
        }
        gmat_to_franja(c, &v, &m);
        const cJSON *name = index == UINT32_MAX ? NULL
                                                : cJSON_GetObjectItemCaseSensitive(c->doc->materials.v[index], "name");
        if ((c->mat_of[slot] = bld_push(&c->b->materials, &m)) == FR_NONE ||
            (cJSON_IsString(name) && bld_material_name(c->b, c->mat_of[slot], name->valuestring) < 0))
            return gdoc_fail(c->doc, err, NULL, "out of memory");
    }
    *out = c->mat_of[slot];
    *uvxf = c->has_uvxf[slot] ? c->uvxf[slot] : NULL;
    return 0;
}
