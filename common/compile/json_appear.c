/* json_appear.c -- the JSON scene's textures, bump and normal maps, media and
 * lens (see json_appear.h). */

#include "compile/json_appear.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "file.h"
#include "geom.h"
#include "compile/jsonval.h"
#include "compile/texstore.h"
#include "texture.h"

/* The largest image file a texture may come from (a 16k x 8k float RGBA
 * image is 2 GiB). */
#define IMAGE_MAX_BYTES ((size_t)4 << 30)

#define PATHLEN 200

/* ---- small readers ------------------------------------------------------ */

/* A number (grey) or [r, g, b], each >= 0. */
static int read_coefficients(const cJSON *obj, const char *key, const char *where, vec3 *out, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = v3s(0.0f);
    if (!v)
        return 0;
    if (cJSON_IsNumber(v)) {
        float x;
        if (jv_number(obj, key, where, 1, 0, &x, err) < 0)
            return -1;
        *out = v3s(x);
    } else if (jv_vec3(obj, key, where, 1, v3s(0), out, err) < 0) {
        return fr_fail(err, "%s.%s: expected a number or [r, g, b] in inverse scene units", where, key);
    }
    if (v3_min(*out) < 0.0f)
        return fr_fail(err, "%s.%s: coefficients must be >= 0", where, key);
    return 0;
}

/* ---- textures ----------------------------------------------------------- */

static const char *const tex_types[] = {"image", "checker", NULL};
static const char *const colorspaces[] = {"auto", "srgb", "linear", NULL};
static const char *const wraps[] = {"repeat", "clamp", NULL};
static const char *const filters[] = {"bilinear", "nearest", NULL};

/* Image formats the compiler reads (through OpenImageIO), by extension;
 * `linear` ones hold linear radiance, the others sRGB-encoded values. */
static const struct { const char *ext; int linear; } formats[] = {
    {"png", 0}, {"jpg", 0}, {"jpeg", 0}, {"tif", 0}, {"tiff", 0}, {"bmp", 0}, {"tga", 0},
    {"ppm", 0}, {"pgm", 0}, {"exr", 1}, {"hdr", 1}, {"pfm", 1},
};

/* Index into formats of path's extension, or -1. */
static int image_format(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return -1;
    char ext[8];
    size_t n = strlen(dot + 1);
    if (n == 0 || n >= sizeof ext)
        return -1;
    for (size_t i = 0; i <= n; i++)
        ext[i] = (char)tolower((unsigned char)dot[1 + i]);
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (!strcmp(ext, formats[i].ext))
            return (int)i;
    return -1;
}

static void resolve(const json_appear *a, const char *file, char *out, size_t cap)
{
    if (file[0] == '/' || !a->dir || !a->dir[0])
        snprintf(out, cap, "%s", file);
    else
        snprintf(out, cap, "%s/%s", a->dir, file);
}

/* Everything about one texture definition but its pixels. */
static int check_texture(const json_appear *a, const cJSON *t, const char *where, fr_texture *tex, int *colorspace,
                         char *path, size_t cap, fr_error *err)
{
    static const char *const image_fields[] = {"type", "file", "colorspace", "wrap", "filter", "scale", "offset", NULL};
    static const char *const checker_fields[] = {"type", "colors", "scale", "offset", NULL};
    memset(tex, 0, sizeof *tex);
    if (!cJSON_IsObject(t))
        return fr_fail(err, "%s: expected an object", where);
    int kind;
    if (!cJSON_GetObjectItemCaseSensitive(t, "type"))
        return fr_fail(err, "%s.type: missing (expected image or checker)", where);
    if (jv_choice(t, "type", where, tex_types, 0, &kind, err) < 0)
        return -1;
    tex->kind = (uint32_t)kind;
    if (jv_only_fields(t, where, kind == FR_TEX_IMAGE ? image_fields : checker_fields, err) < 0 ||
        jv_vec2(t, "scale", where, (vec2){1, 1}, &tex->scale, err) < 0 ||
        jv_vec2(t, "offset", where, (vec2){0, 0}, &tex->offset, err) < 0)
        return -1;
    if (kind == FR_TEX_CHECKER) {
        const cJSON *c = cJSON_GetObjectItemCaseSensitive(t, "colors");
        if (!cJSON_IsArray(c) || cJSON_GetArraySize(c) != 2)
            return fr_fail(err, "%s.colors: expected two colours [[r, g, b], [r, g, b]]", where);
        char p[PATHLEN];
        snprintf(p, sizeof p, "%s.colors", where);
        vec3 col[2];
        for (int i = 0; i < 2; i++) {
            char pi[PATHLEN + 16];
            snprintf(pi, sizeof pi, "%s[%d]", p, i);
            if (jv_vec3_value(cJSON_GetArrayItem(c, i), pi, &col[i], err) < 0)
                return -1;
            for (int k = 0; k < 3; k++)
                if (v3_get(col[i], k) < 0.0f)
                    return fr_fail(err, "%s[%d]: expected a finite number >= 0", pi, k);
        }
        tex->color0 = col[0];
        tex->color1 = col[1];
        *colorspace = 2;
        return 0;
    }
    int wrap, filter;
    if (jv_choice(t, "colorspace", where, colorspaces, 0, colorspace, err) < 0 ||
        jv_choice(t, "wrap", where, wraps, 0, &wrap, err) < 0 ||
        jv_choice(t, "filter", where, filters, 0, &filter, err) < 0)
        return -1;
    tex->wrap = (uint32_t)wrap;
    tex->filter = (uint32_t)filter;
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(t, "file");
    if (!cJSON_IsString(f) || !f->valuestring[0])
        return fr_fail(err, "%s.file: missing (expected an image file name)", where);
    resolve(a, f->valuestring, path, cap);
    if (image_format(path) < 0)
        return fr_fail(err, "%s.file: '%s': unsupported image format (expected png, jpg, exr, tif, hdr, bmp, tga, "
                       "ppm, pgm or pfm)", where, f->valuestring);
    /* The file must be a regular file in the scene's folders (a FIFO
     * would block a reader, a device feed it forever, a name outside the
     * folder read another file): checked now, read when first used. */
    fr_error e;
    int fd;
    size_t size;
    if (confine_open(a->scope, path, IMAGE_MAX_BYTES, &fd, &size, &e) < 0)
        return fr_fail(err, "%s.file: cannot read %s", where, e.msg);
    close(fd);
    return 0;
}

/* Index of texture `name` decoded for colour (as_colour) or data use,
 * decoding it on first use.  `where` is the referring member's path. */
static int texture_ref(json_appear *a, const char *name, int as_colour, const char *where, uint32_t *out,
                       fr_error *err)
{
    const cJSON *def = a->textures ? cJSON_GetObjectItemCaseSensitive(a->textures, name) : NULL;
    if (!def)
        return fr_fail(err, "%s: no texture named '%s'", where, name);
    char tw[PATHLEN], path[4096];
    snprintf(tw, sizeof tw, "textures.%s", name);
    fr_texture tex;
    int cs;
    if (check_texture(a, def, tw, &tex, &cs, path, sizeof path, err) < 0)
        return -1;
    /* sRGB decoding applies to colours from integer formats, unless the
     * definition says otherwise; data (heights, normals) stays linear. */
    int from_srgb = 0;
    if (tex.kind == FR_TEX_IMAGE)
        from_srgb = cs == 1 || (cs == 0 && as_colour && !formats[image_format(path)].linear);
    for (uint32_t i = 0; i < a->n_loaded; i++) {
        if (!strcmp(a->loaded[i].name, name) && a->loaded[i].from_srgb == from_srgb) {
            *out = a->loaded[i].index;
            return 0;
        }
    }
    if (tex.kind == FR_TEX_IMAGE) {
        if (!a->hooks || !a->hooks->texture)
            return fr_fail(err, "%s: image textures need the scene compiler: run `franja compile` and render the "
                           ".fbin", tw);
        scene_image img;
        memset(&img, 0, sizeof img);
        texstore_target into;
        texstore_target_init(&into, a->b, from_srgb);
        img.dest = &into.dest;
        fr_error e;
        char *data;
        size_t len;
        if (budget_take_file(a->b->budget, path, tw, err) < 0)
            return -1;
        if (confine_read(a->scope, path, IMAGE_MAX_BYTES, &data, &len, &e) < 0)
            return fr_fail(err, "%s.file: cannot read %s", tw, e.msg);
        int bad = a->hooks->texture(path, data, len, &img, &e);
        free(data);
        if (bad < 0) {
            if (!img.borrowed)
                free(img.pixels);
            return fr_fail(err, "%s.file: %s", tw, e.msg);
        }
        char iw[PATHLEN + 4096];
        snprintf(iw, sizeof iw, "%s.file '%s'", tw, path);
        int rc = texstore_image(a->b, &img, from_srgb, &tex, iw, err);
        if (!img.borrowed)
            free(img.pixels);
        if (rc < 0)
            return -1;
    }
    if (a->n_loaded == a->cap_loaded) {
        uint32_t cap = a->cap_loaded ? 2 * a->cap_loaded : 8;
        json_tex_entry *p = realloc(a->loaded, cap * sizeof *p);
        if (!p)
            return fr_fail(err, "%s: out of memory", tw);
        a->loaded = p;
        a->cap_loaded = cap;
    }
    *out = bld_push(&a->b->textures, &tex);
    if (*out == FR_NONE)
        return fr_fail(err, "%s: out of memory", tw);
    a->loaded[a->n_loaded++] = (json_tex_entry){def->string, from_srgb, *out};
    return 0;
}

/* ---- media -------------------------------------------------------------- */

static int parse_medium(const cJSON *o, const char *where, fr_medium *m, fr_error *err)
{
    static const char *const fields[] = {"sigma_a", "sigma_s", "g", NULL};
    memset(m, 0, sizeof *m);
    if (!cJSON_IsObject(o))
        return fr_fail(err, "%s: expected an object", where);
    if (jv_only_fields(o, where, fields, err) < 0 || read_coefficients(o, "sigma_a", where, &m->sigma_a, err) < 0 ||
        read_coefficients(o, "sigma_s", where, &m->sigma_s, err) < 0 ||
        jv_number(o, "g", where, 0, 0.0f, &m->g, err) < 0)
        return -1;
    if (!(m->g >= -0.99f && m->g <= 0.99f))
        return fr_fail(err, "%s.g: expected a Henyey-Greenstein asymmetry in [-0.99, 0.99]", where);
    if (v3_is_zero(m->sigma_a) && v3_is_zero(m->sigma_s))
        return fr_fail(err, "%s: sigma_a and sigma_s are both zero (the medium would be empty)", where);
    return 0;
}

/* 1 + index of medium named by string member `key` of obj, 0 if absent. */
static int medium_ref(const json_appear *a, const cJSON *obj, const char *key, const char *where, uint32_t *out,
                      fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = 0;
    if (!v)
        return 0;
    if (!cJSON_IsString(v))
        return fr_fail(err, "%s.%s: expected the name of a medium", where, key);
    int i = jv_member_index(a->media, v->valuestring);
    if (i < 0)
        return fr_fail(err, "%s.%s: no medium named '%s'", where, key, v->valuestring);
    *out = (uint32_t)i + 1;
    return 0;
}

/* ---- the interface ------------------------------------------------------- */

int json_appear_begin(json_appear *a, const cJSON *root, const char *dir, const confine *scope, const scene_hooks *hooks,
                     fr_builder *b, fr_error *err)
{
    memset(a, 0, sizeof *a);
    a->dir = dir;
    a->scope = scope;
    a->hooks = hooks;
    a->b = b;
    a->textures = cJSON_GetObjectItemCaseSensitive(root, "textures");
    a->media = cJSON_GetObjectItemCaseSensitive(root, "media");
    if (a->textures && !cJSON_IsObject(a->textures))
        return fr_fail(err, "textures: expected an object (name -> texture)");
    if (a->media && !cJSON_IsObject(a->media))
        return fr_fail(err, "media: expected an object (name -> medium)");
    for (const cJSON *t = a->textures ? a->textures->child : NULL; t; t = t->next) {
        char where[PATHLEN], path[4096];
        snprintf(where, sizeof where, "textures.%s", t->string);
        fr_texture tex;
        int cs;
        if (check_texture(a, t, where, &tex, &cs, path, sizeof path, err) < 0)
            return -1;
    }
    for (const cJSON *m = a->media ? a->media->child : NULL; m; m = m->next) {
        char where[PATHLEN];
        snprintf(where, sizeof where, "media.%s", m->string);
        fr_medium med;
        if (parse_medium(m, where, &med, err) < 0)
            return -1;
        if (bld_push(&b->media, &med) == FR_NONE)
            return fr_fail(err, "%s: out of memory", where);
    }
    return 0;
}

void json_appear_free(json_appear *a)
{
    free(a->loaded);
    memset(a, 0, sizeof *a);
}

int json_colour(json_appear *a, const cJSON *obj, const char *key, const char *where, int required, vec3 def,
               vec3 *tint, uint32_t *tex, fr_error *err)
{
    static const char *const fields[] = {"texture", "factor", NULL};
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[PATHLEN];
    snprintf(path, sizeof path, "%s.%s", where, key);
    *tex = FR_NONE;
    if (!v || cJSON_IsArray(v))
        return jv_vec3(obj, key, where, required, def, tint, err);
    *tint = v3s(1.0f);
    if (cJSON_IsString(v))
        return texture_ref(a, v->valuestring, 1, path, tex, err);
    if (!cJSON_IsObject(v))
        return fr_fail(err, "%s: expected [r, g, b], a texture name or {\"texture\": name, \"factor\": [r, g, b]}",
                       path);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(v, "texture");
    if (jv_only_fields(v, path, fields, err) < 0)
        return -1;
    if (!cJSON_IsString(name))
        return fr_fail(err, "%s.texture: missing (expected a texture name)", path);
    if (jv_vec3(v, "factor", path, 0, v3s(1.0f), tint, err) < 0)
        return -1;
    return texture_ref(a, name->valuestring, 1, path, tex, err);
}

int json_scalar(json_appear *a, const cJSON *obj, const char *key, const char *where, float def, float lo, float hi,
               float *value, uint32_t *tex, fr_error *err)
{
    static const char *const fields[] = {"texture", "factor", NULL};
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[PATHLEN];
    snprintf(path, sizeof path, "%s.%s", where, key);
    *tex = FR_NONE;
    *value = def;
    if (!v)
        return 0;
    const char *bound = path;
    char fpath[PATHLEN + 8];
    if (cJSON_IsNumber(v)) {
        if (jv_number(obj, key, where, 1, def, value, err) < 0)
            return -1;
    } else if (cJSON_IsString(v)) {
        *value = 1.0f;
        if (texture_ref(a, v->valuestring, 0, path, tex, err) < 0)
            return -1;
    } else if (cJSON_IsObject(v)) {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(v, "texture");
        if (jv_only_fields(v, path, fields, err) < 0 || jv_number(v, "factor", path, 0, 1.0f, value, err) < 0)
            return -1;
        if (!cJSON_IsString(name))
            return fr_fail(err, "%s.texture: missing (expected a texture name)", path);
        if (texture_ref(a, name->valuestring, 0, path, tex, err) < 0)
            return -1;
        snprintf(fpath, sizeof fpath, "%s.factor", path);
        bound = fpath;
    } else {
        return fr_fail(err, "%s: expected a number, a texture name or {\"texture\": name, \"factor\": f}", path);
    }
    if (!(*value >= lo && *value <= hi))
        return fr_fail(err, "%s: expected a number in [%g, %g]", bound, (double)lo, (double)hi);
    return 0;
}

/* "key": name or {"texture": name, "strength": s}: a data texture. */
static int map_ref(json_appear *a, const cJSON *obj, const char *key, const char *where, float def_strength,
                   uint32_t *tex, float *strength, fr_error *err)
{
    static const char *const fields[] = {"texture", "strength", NULL};
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[PATHLEN];
    snprintf(path, sizeof path, "%s.%s", where, key);
    *tex = FR_NONE;
    *strength = def_strength;
    if (!v)
        return 0;
    if (cJSON_IsString(v))
        return texture_ref(a, v->valuestring, 0, path, tex, err);
    if (!cJSON_IsObject(v))
        return fr_fail(err, "%s: expected a texture name or {\"texture\": name, \"strength\": s}", path);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(v, "texture");
    if (jv_only_fields(v, path, fields, err) < 0 ||
        jv_number(v, "strength", path, 0, def_strength, strength, err) < 0)
        return -1;
    if (!cJSON_IsString(name))
        return fr_fail(err, "%s.texture: missing (expected a texture name)", path);
    return texture_ref(a, name->valuestring, 0, path, tex, err);
}

int json_material_appearance(json_appear *a, const cJSON *obj, const char *where, int is_interface, fr_material *m,
                            fr_error *err)
{
    if (map_ref(a, obj, "bump", where, 1.0f, &m->tex_bump, &m->bump_strength, err) < 0 ||
        map_ref(a, obj, "normal_map", where, 1.0f, &m->tex_normal, &m->normal_strength, err) < 0 ||
        medium_ref(a, obj, "medium", where, &m->medium, err) < 0)
        return -1;
    if (m->tex_normal != FR_NONE && !(m->normal_strength >= 0.0f))
        return fr_fail(err, "%s.normal_map.strength: expected a number >= 0", where);
    if (m->tex_normal != FR_NONE && a->b->textures.count > m->tex_normal &&
        ((const fr_texture *)a->b->textures.data)[m->tex_normal].kind == FR_TEX_IMAGE &&
        ((const fr_texture *)a->b->textures.data)[m->tex_normal].channels != 3)
        return fr_fail(err, "%s.normal_map: a normal map needs an RGB image", where);
    m->interface = is_interface ? 1u : 0u;
    if (is_interface) {
        if (!m->medium)
            return fr_fail(err, "%s.medium: missing (an interface material bounds a medium)", where);
        if (!v3_is_zero(m->emission) || m->tex_bump != FR_NONE || m->tex_normal != FR_NONE)
            return fr_fail(err, "%s: an interface is invisible: no emission, bump or normal map", where);
    }
    return 0;
}

int json_camera_lens(const cJSON *o, fr_camera *cam, fr_error *err)
{
    const cJSON *fs = cJSON_GetObjectItemCaseSensitive(o, "fstop");
    const cJSON *fl = cJSON_GetObjectItemCaseSensitive(o, "focal_length");
    if (!fs && !fl)
        return 0;
    if (!fs || !fl)
        return fr_fail(err, "camera.%s: the f-number form needs both fstop and focal_length", fs ? "focal_length" : "fstop");
    if (cJSON_GetObjectItemCaseSensitive(o, "aperture"))
        return fr_fail(err, "camera.aperture: give either aperture or fstop and focal_length, not both");
    float n, f;
    if (jv_number(o, "fstop", "camera", 1, 0, &n, err) < 0 ||
        jv_number(o, "focal_length", "camera", 1, 0, &f, err) < 0)
        return -1;
    if (!(n > 0.0f))
        return fr_fail(err, "camera.fstop: expected an f-number > 0");
    if (!(f > 0.0f))
        return fr_fail(err, "camera.focal_length: expected a length > 0 (scene units)");
    cam->aperture = f / (2.0f * n);
    return 0;
}

/* The medium around point o: cast a ray along d against every primitive
 * whose material has an interior medium; leaving the nearest one's surface
 * means o is inside it. */
static uint32_t medium_around(const fr_builder *b, vec3 o, vec3 d, uint32_t outside)
{
    const fr_material *mats = b->materials.data;
    const fr_prim *prims = b->prims.data;
    const vec3 *pos = b->positions.data;
    fr_ray r = {o, d, 0.0f};
    float best = INFINITY;
    uint32_t found = outside;
    for (uint32_t i = 0; i < b->prims.count; i++) {
        const fr_prim *p = &prims[i];
        uint32_t med = mats[p->material].medium;
        if (!med)
            continue;
        float t, u, v;
        vec3 n;
        if (p->kind == FR_PRIM_SPHERE) {
            const fr_sphere *sp = (const fr_sphere *)b->spheres.data + p->index;
            t = geo_sphere(sp, &r, best);
            n = v3_sub(v3_madd(o, d, t), sp->center);
        } else if (p->kind == FR_PRIM_RECT) {
            const fr_rect *q = (const fr_rect *)b->rects.data + p->index;
            t = geo_rect(q, &r, best, &u, &v);
            n = v3_cross(q->edge_u, q->edge_v);
        } else {
            const fr_triangle *tr = (const fr_triangle *)b->triangles.data + p->index;
            vec3 p0 = pos[tr->v[0]], p1 = pos[tr->v[1]], p2 = pos[tr->v[2]];
            t = geo_triangle(p0, p1, p2, &r, best, &u, &v);
            n = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
        }
        if (t > 0.0f && t < best) {
            best = t;
            found = v3_dot(n, d) > 0.0f ? med : outside;
        }
    }
    return found;
}

int json_appear_finish(json_appear *a, const cJSON *root, fr_error *err)
{
    static const char *const tm_fields[] = {"exposure", "curve", NULL};
    static const char *const curves[] = {"none", "filmic", NULL};
    fr_builder *b = a->b;
    if (medium_ref(a, root, "medium", "(top level)", &b->volume.fog, err) < 0)
        return -1;
    b->volume.camera_medium = medium_around(b, b->camera.position, b->camera.forward, b->volume.fog);
    const cJSON *tm = cJSON_GetObjectItemCaseSensitive(root, "tonemap");
    memset(&b->tonemap, 0, sizeof b->tonemap);
    if (!tm)
        return 0;
    int curve;
    if (!cJSON_IsObject(tm))
        return fr_fail(err, "tonemap: expected an object");
    if (jv_only_fields(tm, "tonemap", tm_fields, err) < 0 ||
        jv_number(tm, "exposure", "tonemap", 0, 0.0f, &b->tonemap.exposure, err) < 0 ||
        jv_choice(tm, "curve", "tonemap", curves, 0, &curve, err) < 0)
        return -1;
    if (!(b->tonemap.exposure >= -64.0f && b->tonemap.exposure <= 64.0f))
        return fr_fail(err, "tonemap.exposure: expected stops in [-64, 64]");
    b->tonemap.curve = (uint32_t)curve;
    return 0;
}
