/* fbin.c -- the binary scene: serialized, written, and loaded and checked by
 * mapping (see fbin.h). */

#include "fbin.h"

#include "bvh.h"
#include "file.h"
#include "fmath.h"
#include "le.h"
#include "motion.h"
#include "passes.h"
#include "proto_limits.h"
#include "scene_pages.h"
#include "texture.h"

#include <errno.h>
#include <stdint.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

static const unsigned char fbin_magic[8] = {0x89, 'F', 'R', 'J', 'S', 'C', 'N', '\n'};
enum { HEADER_SIZE = 64, ENTRY_SIZE = 32, ALIGN = 64 };

enum {
    SEC_SETTINGS = 1, SEC_CAMERA, SEC_MATERIALS, SEC_PRIMS, SEC_SPHERES, SEC_RECTS,
    SEC_TRIANGLES, SEC_POSITIONS, SEC_NORMALS, SEC_UVS, SEC_PLANES, SEC_LIGHTS, SEC_NODES, SEC_LEAVES,
    SEC_TEXTURES, SEC_TEXELS, SEC_MEDIA, SEC_VOLUME, SEC_TONEMAP, SEC_WORLD, SEC_DISTRIB,
    SEC_MESHES, SEC_INSTANCES, SEC_MESH_NODES, SEC_MESH_LEAVES, SEC_LIGHTTREE, SEC_NAMES, SEC_MOTION,
    SEC_OBJECTS, SEC_OBJECT_NAMES,
    SEC_LIGHT_GROUPS, SEC_GROUP_NAMES, SEC_INST_MOTIONS, SEC_COUNT = SEC_INST_MOTIONS
};

_Static_assert(SEC_COUNT == FBIN_SECTIONS, "fbin.h's FBIN_SECTIONS is the number of sections");

/* Where each section lives in an fr_scene, so serialize and open share one
 * table instead of thirteen copies of the same lines. */
typedef struct {
    const char *name;
    uint32_t elem;
    size_t data_off, count_off; /* offsetof into fr_scene; count_off 0 = exactly one element */
} section_desc;

#define ARR(id, name, field, type) \
    [id] = {name, sizeof(type), offsetof(fr_scene, field), offsetof(fr_scene, n_##field)}
static const section_desc sections[SEC_COUNT + 1] = {
    [SEC_SETTINGS] = {"settings", sizeof(fr_settings), offsetof(fr_scene, settings), 0},
    [SEC_CAMERA] = {"camera", sizeof(fr_camera), offsetof(fr_scene, camera), 0},
    ARR(SEC_MATERIALS, "materials", materials, fr_material),
    ARR(SEC_PRIMS, "prims", prims, fr_prim),
    ARR(SEC_SPHERES, "spheres", spheres, fr_sphere),
    ARR(SEC_RECTS, "rects", rects, fr_rect),
    ARR(SEC_TRIANGLES, "triangles", triangles, fr_triangle),
    ARR(SEC_POSITIONS, "positions", positions, vec3),
    ARR(SEC_NORMALS, "normals", normals, vec3),
    ARR(SEC_UVS, "uvs", uvs, vec2),
    ARR(SEC_PLANES, "planes", planes, fr_plane),
    ARR(SEC_LIGHTS, "lights", lights, fr_light),
    ARR(SEC_NODES, "nodes", nodes, fr_bvh_node),
    ARR(SEC_LEAVES, "leaves", leaves, fr_bvh_leaf),
    ARR(SEC_TEXTURES, "textures", textures, fr_texture),
    ARR(SEC_TEXELS, "texels", texels, uint32_t),
    ARR(SEC_MEDIA, "media", media, fr_medium),
    [SEC_VOLUME] = {"volume", sizeof(fr_volume), offsetof(fr_scene, volume), 0},
    [SEC_TONEMAP] = {"tonemap", sizeof(fr_tonemap), offsetof(fr_scene, tonemap), 0},
    [SEC_WORLD] = {"world", sizeof(fr_world), offsetof(fr_scene, world), 0},
    ARR(SEC_DISTRIB, "distrib", distrib, float),
    ARR(SEC_MESHES, "meshes", meshes, fr_mesh),
    ARR(SEC_INSTANCES, "instances", instances, fr_instance),
    ARR(SEC_MESH_NODES, "mesh_nodes", mesh_nodes, fr_bvh_node),
    ARR(SEC_MESH_LEAVES, "mesh_leaves", mesh_leaves, fr_bvh_leaf),
    ARR(SEC_LIGHTTREE, "lighttree", light_nodes, fr_light_node),
    ARR(SEC_NAMES, "material_names", material_names, fr_name),
    [SEC_MOTION] = {"motion", sizeof(fr_motion), offsetof(fr_scene, motion), 0},
    ARR(SEC_OBJECTS, "objects", objects, uint32_t),
    ARR(SEC_OBJECT_NAMES, "object_names", object_names, fr_name),
    ARR(SEC_LIGHT_GROUPS, "light_groups", light_groups, uint32_t),
    ARR(SEC_GROUP_NAMES, "group_names", group_names, fr_name),
    ARR(SEC_INST_MOTIONS, "inst_motions", inst_motions, fr_inst_motion),
};
#undef ARR


static size_t align_up(size_t x) { return (x + ALIGN - 1) & ~(size_t)(ALIGN - 1); }

static const void *sec_data(const fr_scene *s, int id, uint64_t *count)
{
    const section_desc *d = &sections[id];
    if (!d->count_off) {
        *count = 1;
        return (const char *)s + d->data_off;
    }
    *count = *(const uint32_t *)((const char *)s + d->count_off);
    return *(const void *const *)((const char *)s + d->data_off);
}

void fbin_hash_hex(uint64_t hash, char buf[17]) { snprintf(buf, 17, "%016llx", (unsigned long long)hash); }

void fbin_put_header(unsigned char *head, uint64_t size)
{
    memcpy(head, fbin_magic, 8);
    le_put32(head + 8, FBIN_VERSION);
    le_put32(head + 12, 0x01020304u);
    le_put32(head + 16, HEADER_SIZE);
    le_put32(head + 20, SEC_COUNT);
    le_put64(head + 24, size);
}

/* The bytes before the first section: header (hash still zero) and
 * table, then zeros to the first section's alignment. */
enum { HEAD_SIZE = (HEADER_SIZE + ENTRY_SIZE * SEC_COUNT + ALIGN - 1) & ~(ALIGN - 1) };

/* Lays the sections of `view` out: head[HEAD_SIZE] filled, offsets[id]
 * the byte of each section; returns the file's size. */
static size_t layout(const fr_scene *view, unsigned char head[HEAD_SIZE], size_t offsets[SEC_COUNT + 1])
{
    size_t off = HEAD_SIZE;
    memset(head, 0, HEAD_SIZE);
    for (int id = 1; id <= SEC_COUNT; id++) {
        uint64_t count;
        sec_data(view, id, &count);
        offsets[id] = off;
        unsigned char *e = head + HEADER_SIZE + (size_t)ENTRY_SIZE * (id - 1);
        le_put32(e, (uint32_t)id);
        le_put32(e + 4, sections[id].elem);
        le_put64(e + 8, off);
        le_put64(e + 16, count);
        le_put64(e + 24, count * sections[id].elem);
        off = align_up(off + count * sections[id].elem);
    }
    fbin_put_header(head, off);
    return off;
}

static int little_endian(fr_error *err)
{
    if (*(const uint32_t *)"\1\0\0\0" != 1)
        return fr_fail(err, "binary scenes are little-endian; this host is not");
    return 0;
}

int fbin_serialize(const fr_scene *view, void **blob, size_t *size, fr_error *err)
{
    if (little_endian(err) < 0)
        return -1;
    unsigned char head[HEAD_SIZE];
    size_t offsets[SEC_COUNT + 1];
    size_t off = layout(view, head, offsets);
    unsigned char *p = calloc(1, off);
    if (!p)
        return fr_fail(err, "out of memory serializing the scene (%zu bytes)", off);
    memcpy(p, head, HEAD_SIZE);
    for (int id = 1; id <= SEC_COUNT; id++) {
        uint64_t count;
        const void *data = sec_data(view, id, &count);
        if (count)
            memcpy(p + offsets[id], data, count * sections[id].elem);
    }
    le_put64(p + 32, XXH3_64bits(p + HEADER_SIZE, off - HEADER_SIZE));
    *blob = p;
    *size = off;
    return 0;
}

int fbin_write_view(const fr_scene *view, const char *path, uint64_t *hash, size_t *size, fr_error *err)
{
    if (little_endian(err) < 0)
        return -1;
    static const unsigned char zeros[ALIGN];
    unsigned char head[HEAD_SIZE];
    size_t offsets[SEC_COUNT + 1];
    size_t off = layout(view, head, offsets);
    /* The hash first (the header holds it), over the bytes the file will
     * hold: XXH3's streaming form gives the one-shot value. */
    XXH3_state_t *st = XXH3_createState();
    if (!st || XXH3_64bits_reset(st) != XXH_OK) {
        XXH3_freeState(st);
        return fr_fail(err, "%s: out of memory hashing the scene", path);
    }
    XXH3_64bits_update(st, head + HEADER_SIZE, HEAD_SIZE - HEADER_SIZE);
    for (int id = 1; id <= SEC_COUNT; id++) {
        uint64_t count;
        const void *data = sec_data(view, id, &count);
        size_t bytes = count * sections[id].elem, end = id < SEC_COUNT ? offsets[id + 1] : off;
        if (bytes)
            XXH3_64bits_update(st, data, bytes);
        XXH3_64bits_update(st, zeros, end - offsets[id] - bytes);
    }
    uint64_t h = XXH3_64bits_digest(st);
    XXH3_freeState(st);
    le_put64(head + 32, h);
    file_out o;
    if (file_out_open(path, &o, err))
        return -1;
    int rc = file_out_write(&o, head, HEAD_SIZE, err);
    for (int id = 1; id <= SEC_COUNT && rc == 0; id++) {
        uint64_t count;
        const void *data = sec_data(view, id, &count);
        size_t bytes = count * sections[id].elem, end = id < SEC_COUNT ? offsets[id + 1] : off;
        rc = file_out_write(&o, data, bytes, err);
        if (rc == 0)
            rc = file_out_write(&o, zeros, end - offsets[id] - bytes, err);
    }
    if (rc) {
        file_out_abort(&o);
        return -1;
    }
    if (file_out_commit(&o, path, err))
        return -1;
    *hash = h;
    *size = off;
    return 0;
}

static int finite3(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* A camera a ray can be made from: finite position and basis, a field of
 * view, a lens that is a pinhole or focused. */
static int camera_ok(const fr_camera *c)
{
    return finite3(c->position) && finite3(c->forward) && finite3(c->right) && finite3(c->upv) &&
           c->tan_half > 0.0f && isfinite(c->tan_half) && c->aperture >= 0.0f && isfinite(c->aperture) &&
           (c->focus > 0.0f || c->aperture == 0.0f);
}

/* Byte offset of an element inside the blob, for messages; sections of a
 * single element are copied out of the blob, so theirs come from the table
 * (off[id]) plus the field's offset. */
#define AT(ptr) ((size_t)((const char *)(ptr) - (const char *)base))
#define AT1(id, type, field) ((size_t)(off[id] + offsetof(type, field)))

static int tex_ref_ok(const fr_scene *s, uint32_t t) { return t == FR_NONE || t < s->n_textures; }

/* Textures, texels, media and the material fields that refer to them. */
static int validate_appearance(const fr_scene *s, const void *base, const uint64_t *off, fr_error *err)
{
    for (uint32_t i = 0; i < s->n_textures; i++) {
        const fr_texture *t = &s->textures[i];
        if (t->kind > FR_TEX_CHECKER || t->wrap > FR_WRAP_CLAMP || t->filter > FR_FILTER_NEAREST ||
            !isfinite(t->scale.u) || !isfinite(t->scale.v) || !isfinite(t->offset.u) || !isfinite(t->offset.v) ||
            !finite3(t->color0) || !finite3(t->color1))
            return fr_fail(err, "section textures, byte %zu: texture %u: bad kind, wrap, filter or non-finite parameter",
                           AT(t), i);
        if (t->kind != FR_TEX_IMAGE)
            continue;
        if (t->width == 0 || t->height == 0 || t->width > FR_TEX_MAX_SIDE || t->height > FR_TEX_MAX_SIDE ||
            (t->channels != 1 && t->channels != 3) || t->format >= FR_TEXEL_FORMATS)
            return fr_fail(err, "section textures, byte %zu: texture %u: image %ux%u with %u channels of format %u "
                           "(at most %ux%u, 1 or 3 channels, formats 0 to %u)", AT(t), i, t->width, t->height,
                           t->channels, t->format, FR_TEX_MAX_SIDE, FR_TEX_MAX_SIDE, FR_TEXEL_FORMATS - 1);
        uint32_t side = t->width > t->height ? t->width : t->height, chain = 1;
        while (side >> chain)
            chain++;
        if (t->levels == 0 || t->levels > chain)
            return fr_fail(err, "section textures, byte %zu: texture %u: %u mip levels (a %ux%u image has 1 to %u)",
                           AT(t), i, t->levels, t->width, t->height, chain);
        uint32_t bytes = tex_format_bytes(t->format);
        for (uint32_t k = 0; k < FR_TEX_MAX_LEVELS; k++) {
            if (k >= t->levels) {
                if (t->first[k] != 0)
                    return fr_fail(err, "section textures, byte %zu: texture %u: level %u is not stored but has "
                                   "an offset", AT(t), i, k);
                continue;
            }
            /* The level's words inside texels (64-bit sums: no wrap). */
            uint32_t w, h;
            tex_level_size(t, k, &w, &h);
            uint64_t words = ((uint64_t)w * h * t->channels * bytes + 3) / 4;
            if ((uint64_t)t->first[k] + words > s->n_texels)
                return fr_fail(err, "section textures, byte %zu: texture %u: level %u (%ux%u, %u channels, format "
                               "%u) does not fit in the %u words of texels from word %u", AT(t), i, k, w,
                               h, t->channels, t->format, s->n_texels, t->first[k]);
            /* Floating-point formats: every value finite. */
            const unsigned char *p = (const unsigned char *)(s->texels + t->first[k]);
            size_t nv = (size_t)w * h * t->channels;
            if (t->format == FR_TEXEL_F32) {
                for (size_t j = 0; j < nv; j++) {
                    float f;
                    memcpy(&f, p + 4 * j, 4);
                    if (!isfinite(f))
                        return fr_fail(err, "section texels, byte %zu: texture %u, level %u: value %zu is not a "
                                       "finite number", AT(p + 4 * j), i, k, j);
                }
            } else if (t->format == FR_TEXEL_F16) {
                for (size_t j = 0; j < nv; j++)
                    if ((p[2 * j + 1] & 0x7c) == 0x7c)
                        return fr_fail(err, "section texels, byte %zu: texture %u, level %u: value %zu is not a "
                                       "finite number", AT(p + 2 * j), i, k, j);
            }
        }
    }
    for (uint32_t i = 0; i < s->n_media; i++) {
        const fr_medium *m = &s->media[i];
        if (!finite3(m->sigma_a) || !finite3(m->sigma_s) || v3_min(m->sigma_a) < 0.0f || v3_min(m->sigma_s) < 0.0f ||
            !(m->g > -1.0f && m->g < 1.0f))
            return fr_fail(err, "section media, byte %zu: medium %u: negative or non-finite coefficient, or |g| >= 1",
                           AT(m), i);
    }
    if (s->volume.fog > s->n_media || s->volume.camera_medium > s->n_media)
        return fr_fail(err, "section volume, byte %zu: medium index out of range", AT1(SEC_VOLUME, fr_volume, fog));
    if (!(s->tonemap.exposure >= -64.0f && s->tonemap.exposure <= 64.0f) || s->tonemap.curve > FR_CURVE_FILMIC)
        return fr_fail(err, "section tonemap, byte %zu: exposure outside [-64, 64] or unknown curve",
                       AT1(SEC_TONEMAP, fr_tonemap, exposure));
    for (uint32_t i = 0; i < s->n_materials; i++) {
        const fr_material *m = &s->materials[i];
        if (!tex_ref_ok(s, m->tex_diffuse) || !tex_ref_ok(s, m->tex_glossy) || !tex_ref_ok(s, m->tex_specular) ||
            !tex_ref_ok(s, m->tex_transmit) || !tex_ref_ok(s, m->tex_emission) || !tex_ref_ok(s, m->tex_bump) ||
            !tex_ref_ok(s, m->tex_normal) || !tex_ref_ok(s, m->tex_roughness) || !tex_ref_ok(s, m->tex_metallic) ||
            !tex_ref_ok(s, m->tex_transmission))
            return fr_fail(err, "section materials, byte %zu: material %u: texture index out of range",
                           AT(&m->tex_diffuse), i);
        if (!isfinite(m->bump_strength) || !isfinite(m->normal_strength) || m->medium > s->n_media ||
            m->interface > 1 || (m->interface && m->medium == 0))
            return fr_fail(err, "section materials, byte %zu: material %u: bad bump or normal strength, medium or interface",
                           AT(m), i);
    }
    return 0;
}

static int unit3(vec3 v) { return finite3(v) && fabsf(v3_len2(v) - 1.0f) < 1e-4f; }

/* A cumulative table of n + 1 entries: 0 first, 1 last, non-decreasing. */
static int cdf_ok(const float *c, uint32_t n)
{
    if (c[0] != 0.0f || c[n] != 1.0f)
        return 0;
    for (uint32_t i = 1; i <= n; i++)
        if (!(c[i] >= c[i - 1]))
            return 0;
    return 1;
}

/* The environment's map and sampling tables (fr_world in scene.h). */
static int validate_envmap(const fr_scene *s, const void *base, const uint64_t *off, fr_error *err)
{
    const fr_world *w = &s->world;
    size_t at = AT1(SEC_WORLD, fr_world, env_texture);
    if (w->env_texture >= s->n_textures || s->textures[w->env_texture].kind != FR_TEX_IMAGE)
        return fr_fail(err, "section world, byte %zu: environment texture %u is not an image texture", at,
                       w->env_texture);
    const fr_texture *t = &s->textures[w->env_texture];
    uint64_t n = (uint64_t)t->width * t->height, need = n + t->height + 1 + (uint64_t)t->height * (t->width + 1);
    if (w->dist_first > s->n_distrib || need > (uint64_t)s->n_distrib - w->dist_first)
        return fr_fail(err, "section world, byte %zu: environment tables (%llu values) outside distrib",
                       AT1(SEC_WORLD, fr_world, dist_first), (unsigned long long)need);
    const float *pdf = s->distrib + w->dist_first, *marg = pdf + n, *cond = marg + t->height + 1;
    for (uint64_t i = 0; i < n; i++)
        if (!(pdf[i] >= 0.0f) || !isfinite(pdf[i]))
            return fr_fail(err, "section distrib, byte %zu: environment density %llu negative or not finite",
                           AT(pdf + i), (unsigned long long)i);
    if (!cdf_ok(marg, t->height))
        return fr_fail(err, "section distrib, byte %zu: environment row table is not cumulative from 0 to 1",
                       AT(marg));
    for (uint32_t r = 0; r < t->height; r++)
        if (!cdf_ok(cond + (size_t)r * (t->width + 1), t->width))
            return fr_fail(err, "section distrib, byte %zu: environment table of row %u is not cumulative from 0 to 1",
                           AT(cond + (size_t)r * (t->width + 1)), r);
    return 0;
}

/* Lights and the world: kinds and their parameters, distant lights first,
 * one environment light that the world points at. */
static int validate_lights(const fr_scene *s, const void *base, const uint64_t *off, fr_error *err)
{
    const fr_world *w = &s->world;
    if (!finite3(w->center) || !(w->radius > 0.0f) || !isfinite(w->radius) || w->env > FR_ENV_MAP ||
        !finite3(w->env_color) || v3_min(w->env_color) < 0.0f || !isfinite(w->rot_cos) || !isfinite(w->rot_sin) ||
        fabsf(w->rot_cos * w->rot_cos + w->rot_sin * w->rot_sin - 1.0f) > 1e-4f)
        return fr_fail(err, "section world, byte %zu: bad bounds, environment kind, colour or rotation",
                       AT1(SEC_WORLD, fr_world, center));
    if ((w->env == FR_ENV_NONE) != (w->env_light == FR_NONE) ||
        (w->env_light != FR_NONE && (w->env_light >= s->n_lights || s->lights[w->env_light].kind != FR_LIGHT_ENV)))
        return fr_fail(err, "section world, byte %zu: environment light %u missing or not an environment",
                       AT1(SEC_WORLD, fr_world, env_light), w->env_light);
    if (w->env == FR_ENV_MAP && validate_envmap(s, base, off, err) < 0)
        return -1;
    int local = 0;
    for (uint32_t i = 0; i < s->n_lights; i++) {
        const fr_light *l = &s->lights[i];
        int distant = l->kind == FR_LIGHT_SUN || l->kind == FR_LIGHT_ENV;
        if (l->kind >= FR_LIGHT_KINDS || (l->kind == FR_LIGHT_PRIM) != (l->prim != FR_NONE) ||
            (l->kind == FR_LIGHT_PRIM && (l->prim >= s->n_prims || s->prims[l->prim].light != i)))
            return fr_fail(err, "section lights, byte %zu: light %u: bad kind or primitive", AT(l), i);
        if (distant && local)
            return fr_fail(err, "section lights, byte %zu: light %u: a distant light after a local one", AT(l), i);
        local |= !distant;
        if (l->kind == FR_LIGHT_ENV && i != w->env_light)
            return fr_fail(err, "section lights, byte %zu: light %u: a second environment", AT(l), i);
        if (!(l->pick > 0.0f && l->pick <= 1.0f) || !(l->cdf >= 0.0f && l->cdf <= 1.0f))
            return fr_fail(err, "section lights, byte %zu: light %u: bad pick probability", AT(l), i);
        if (i > 0 && !(l->cdf >= s->lights[i - 1].cdf))
            return fr_fail(err, "section lights, byte %zu: light %u: cumulative pick probability below the light "
                           "before it", AT(l), i);
        if (!finite3(l->position) || !finite3(l->intensity) || v3_min(l->intensity) < 0.0f)
            return fr_fail(err, "section lights, byte %zu: light %u: non-finite position or bad intensity", AT(l), i);
        if (l->kind == FR_LIGHT_SPOT &&
            (!unit3(l->axis) || !(l->cone_cos >= -1.0f && l->cone_cos < l->cone_aux && l->cone_aux <= 1.0f)))
            return fr_fail(err, "section lights, byte %zu: spot light %u: axis not unit or cone cosines not "
                           "-1 <= outer < inner <= 1", AT(l), i);
        if (l->kind == FR_LIGHT_SUN &&
            (!unit3(l->axis) || !(l->cone_cos >= 0.0f && l->cone_cos <= 1.0f) ||
             !(l->cone_aux >= 0.0f && l->cone_aux <= 1.0f) || (l->cone_aux == 0.0f && l->cone_cos != 1.0f)))
            return fr_fail(err, "section lights, byte %zu: sun %u: axis not unit or bad disk", AT(l), i);
    }
    return 0;
}

/* The instanced meshes and their instances: each mesh's ranges follow the
 * last one's, its prims fill the end of prims, and each instance names a
 * mesh through finite transforms that are each other's inverse (to a
 * tolerance: a wrong pair would only draw wrong, never read out of
 * bounds).  bvh_validate checks each mesh's tree. */
static int validate_instances(const fr_scene *s, const void *base, fr_error *err)
{
    uint64_t node = 0, leaf = 0, prim = s->n_meshes ? s->meshes[0].prim_first : s->n_prims;
    for (uint32_t k = 0; k < s->n_meshes; k++) {
        const fr_mesh *m = &s->meshes[k];
        if (m->node_first != node || m->leaf_first != leaf || m->prim_first != prim || m->n_nodes == 0 ||
            m->n_leaves == 0 || m->n_prims == 0 || m->pad[0] || m->pad[1])
            return fr_fail(err, "section meshes, byte %zu: mesh %u: its ranges do not follow the last mesh's, or "
                           "one is empty", AT(m), k);
        node += m->n_nodes;
        leaf += m->n_leaves;
        prim += m->n_prims;
    }
    if (node != s->n_mesh_nodes || leaf != s->n_mesh_leaves || prim != s->n_prims)
        return fr_fail(err, "section meshes: the meshes cover %llu nodes, %llu leaf blocks and prims up to %llu, "
                       "the scene has %u, %u and %u", (unsigned long long)node, (unsigned long long)leaf,
                       (unsigned long long)prim, s->n_mesh_nodes, s->n_mesh_leaves, s->n_prims);
    for (uint32_t i = 0; i < s->n_instances; i++) {
        const fr_instance *in = &s->instances[i];
        if (in->mesh >= s->n_meshes || in->pad[0] || in->pad[1])
            return fr_fail(err, "section instances, byte %zu: instance %u: mesh %u of %u", AT(&in->mesh), i,
                           in->mesh, s->n_meshes);
        if (in->motion > s->n_inst_motions || (in->motion && !(s->motion.flags & FR_MOTION_INSTANCES)))
            return fr_fail(err, "section instances, byte %zu: instance %u: motion %u of %u (or the motion section "
                           "does not say instances move)", AT(&in->motion), i, in->motion, s->n_inst_motions);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                if (!isfinite(in->xf[r][c]) || !isfinite(in->inv[r][c]) || fabsf(in->xf[r][c]) > 1e30f ||
                    fabsf(in->inv[r][c]) > 1e30f)
                    return fr_fail(err, "section instances, byte %zu: instance %u: transform not finite",
                                   AT(&in->xf[r][c]), i);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double sum = 0.0, mag = 0.0;
                for (int k = 0; k < 3; k++) {
                    sum += (double)in->xf[r][k] * in->inv[k][c];
                    mag += fabs((double)in->xf[r][k] * in->inv[k][c]);
                }
                if (!(fabs(sum - (r == c)) <= 1e-3 * (mag + 1.0)))
                    return fr_fail(err, "section instances, byte %zu: instance %u: the inverse is not the "
                                   "transform's inverse", AT(in->inv), i);
            }
    }
    return 0;
}

/* The moving instances' motions (scene.h's fr_inst_motion): finite
 * numbers of a sane size, unit quaternions on the same side (q0 . q1 >= 0)
 * whose angle and its inverse sine are the ones stored (to a tolerance: a
 * wrong pair only draws wrong); the motion flag set when there are any. */
static int validate_motions(const fr_scene *s, const void *base, fr_error *err)
{
    if (s->n_inst_motions && !(s->motion.flags & FR_MOTION_INSTANCES))
        return fr_fail(err, "section inst_motions: %u motions, but the motion section does not say instances move",
                       s->n_inst_motions);
    for (uint32_t i = 0; i < s->n_inst_motions; i++) {
        const fr_inst_motion *m = &s->inst_motions[i];
        const float *f = &m->t0.x;
        for (size_t k = 0; k < offsetof(fr_inst_motion, pad) / sizeof(float); k++)
            if (!isfinite(f[k]) || fabsf(f[k]) > 1e30f)
                return fr_fail(err, "section inst_motions, byte %zu: motion %u: a number not finite or above 1e30",
                               AT(&f[k]), i);
        if (m->pad[0] || m->pad[1])
            return fr_fail(err, "section inst_motions, byte %zu: motion %u: pad not zero", AT(m->pad), i);
        double n0 = 0.0, n1 = 0.0, dot = 0.0;
        for (int k = 0; k < 4; k++) {
            n0 += (double)m->q0[k] * m->q0[k];
            n1 += (double)m->q1[k] * m->q1[k];
            dot += (double)m->q0[k] * m->q1[k];
        }
        if (!(fabs(n0 - 1.0) <= 1e-4 && fabs(n1 - 1.0) <= 1e-4 && dot >= -1e-6))
            return fr_fail(err, "section inst_motions, byte %zu: motion %u: rotations not unit quaternions with "
                           "q0 . q1 >= 0", AT(m->q0), i);
        double ang = fm_acosf((float)dot);
        int slerp = m->inv_sin > 0.0f;
        if (!(m->angle >= 0.0f && m->angle <= 1.5708f && fabs(ang - m->angle) <= 1e-3) ||
            !(m->inv_sin >= 0.0f) || slerp != (m->angle >= MOTION_SLERP_MIN) ||
            (slerp && !(fabs((double)m->inv_sin * fm_sinf(m->angle) - 1.0) <= 1e-4)))
            return fr_fail(err, "section inst_motions, byte %zu: motion %u: angle or its inverse sine not the "
                           "quaternions'", AT(&m->angle), i);
    }
    return 0;
}

/* The light tree: none (next-event estimation picks by the power table),
 * or one leaf per local light (light nd + j is node j),
 * inner nodes after the leaves, each after its children, the root last;
 * parents and children agree, so the nodes form one tree; no leaf deeper
 * than FR_BVH_MAX_DEPTH levels (light.c walks a leaf's path on a fixed
 * stack); finite bounds and cones, power >= 0. */
static int validate_light_tree(const fr_scene *s, const void *base, fr_error *err)
{
    uint32_t nd = 0;
    while (nd < s->n_lights && (s->lights[nd].kind == FR_LIGHT_SUN || s->lights[nd].kind == FR_LIGHT_ENV))
        nd++;
    uint32_t nl = s->n_lights - nd, n = s->n_light_nodes;
    if (n != 0 && n != 2 * nl - 1)
        return fr_fail(err, "section lighttree: %u nodes for %u local lights, expected 0 or %u", n, nl,
                       nl ? 2 * nl - 1 : 0);
    if (n == 0)
        return 0;
    for (uint32_t i = 0; i < n; i++) {
        const fr_light_node *t = &s->light_nodes[i];
        if (!finite3(t->lo) || !finite3(t->hi) || !(t->lo.x <= t->hi.x && t->lo.y <= t->hi.y && t->lo.z <= t->hi.z) ||
            !finite3(t->axis) || fabsf(v3_len2(t->axis) - 1.0f) > 1e-3f || !(t->cos_o >= -1.0f && t->cos_o <= 1.0f) ||
            !(t->cos_e >= -1.0f && t->cos_e <= 1.0f) || !(t->power >= 0.0f) || !isfinite(t->power) ||
            (t->flags & ~(uint32_t)FR_LNODE_TWO_SIDED))
            return fr_fail(err, "section lighttree, byte %zu: node %u: bad bounds, cone, power or flags", AT(t), i);
        int leaf = i < nl;
        if (leaf != (t->child[0] == FR_NONE) || leaf != (t->child[1] == FR_NONE) ||
            (!leaf && !(t->child[0] < i && t->child[1] < i && t->child[0] != t->child[1] &&
                        s->light_nodes[t->child[0]].parent == i && s->light_nodes[t->child[1]].parent == i)))
            return fr_fail(err, "section lighttree, byte %zu: node %u: children missing, out of order or not "
                           "pointing back", AT(t->child), i);
        uint32_t p = t->parent;
        if ((i + 1 == n) != (p == FR_NONE) ||
            (p != FR_NONE && !(p > i && p < n && (s->light_nodes[p].child[0] == i || s->light_nodes[p].child[1] == i))))
            return fr_fail(err, "section lighttree, byte %zu: node %u: parent %u out of order or not its parent",
                           AT(&t->parent), i, p);
    }
    for (uint32_t j = 0; j < nl; j++) {
        uint32_t depth = 1;
        for (uint32_t k = j; s->light_nodes[k].parent != FR_NONE; k = s->light_nodes[k].parent)
            if (++depth > FR_BVH_MAX_DEPTH)
                return fr_fail(err, "section lighttree, byte %zu: leaf %u deeper than %d levels",
                               AT(s->light_nodes + j), j, FR_BVH_MAX_DEPTH);
    }
    return 0;
}

/* Check every cross-reference so that rendering can index without checks. */
/* A names section (material_names, object_names): each entry
 * NUL-terminated within its 64 bytes, no control character. */
static int names_validate(const char *what, const fr_name *v, uint32_t n, const void *base, fr_error *err)
{
    for (uint32_t i = 0; i < n; i++) {
        const char *t = v[i].name;
        size_t k = strnlen(t, sizeof v[i].name);
        int ok = k < sizeof v[i].name;
        for (size_t j = 0; ok && j < k; j++)
            ok = (unsigned char)t[j] >= 0x20 && t[j] != 0x7f;
        if (!ok)
            return fr_fail(err, "section %s, byte %zu: name %u: not NUL-terminated text of at most 63 bytes "
                           "without control characters", what, (size_t)((const char *)t - (const char *)base), i);
    }
    return 0;
}

static int validate(const fr_scene *s, const void *base, const uint64_t *off, fr_error *err)
{
    const fr_settings *st = &s->settings;
    if (st->width == 0 || st->height == 0 || st->width > PROTO_MAX_SIZE || st->height > PROTO_MAX_SIZE ||
        st->spp == 0 || st->spp > PROTO_MAX_SPP || st->max_depth > PROTO_MAX_DEPTH || st->integrator >= FR_INTEGRATORS)
        return fr_fail(err, "section settings, byte %zu: bad image size, sample count, depth or integrator",
                       AT1(SEC_SETTINGS, fr_settings, width));
    if (!(st->noise_threshold >= 0.0f && st->noise_threshold <= 1.0f))
        return fr_fail(err, "section settings, byte %zu: noise threshold not in [0, 1]",
                       AT1(SEC_SETTINGS, fr_settings, noise_threshold));
    if (st->passes & ~PASS_ALL)
        return fr_fail(err, "section settings, byte %zu: unknown render passes %#x",
                       AT1(SEC_SETTINGS, fr_settings, passes), st->passes & ~PASS_ALL);
    if (!camera_ok(&s->camera))
        return fr_fail(err, "section camera, byte %zu: degenerate or non-finite camera", AT1(SEC_CAMERA, fr_camera, position));
    const fr_motion *mo = &s->motion;
    if (mo->flags & ~(uint32_t)(FR_MOTION_CAMERA | FR_MOTION_INSTANCES) || !(mo->shutter >= 0.0f && mo->shutter <= 1e6f))
        return fr_fail(err, "section motion, byte %zu: unknown flags or a shutter not a time in seconds",
                       AT1(SEC_MOTION, fr_motion, flags));
    if ((mo->flags & FR_MOTION_CAMERA) && !camera_ok(&mo->camera_close))
        return fr_fail(err, "section motion, byte %zu: degenerate or non-finite camera at shutter close",
                       AT1(SEC_MOTION, fr_motion, camera_close));
    if (validate_appearance(s, base, off, err) < 0)
        return -1;
    for (uint32_t i = 0; i < s->n_materials; i++) {
        const fr_material *m = &s->materials[i];
        int ok = m->p_lobe[0] >= 0.0f && m->p_lobe[3] <= 1.0f;
        for (int k = 1; k < 4; k++)
            ok &= m->p_lobe[k] >= m->p_lobe[k - 1];
        if (!ok || !(m->ior > 0.0f) || !(m->exponent >= 0.0f) || !finite3(m->emission))
            return fr_fail(err, "section materials, byte %zu: material %u: bad lobe probabilities, ior, exponent "
                           "or emission", AT(m), i);
        if (m->model >= FR_MAT_MODELS || m->mf_flags > FR_MF_ALL || m->fresnel >= FR_FRESNEL_MODES ||
            !(m->roughness >= 0.0f && m->roughness <= 1.0f) || !(m->anisotropy >= -1.0f && m->anisotropy <= 1.0f) ||
            !(m->metallic >= 0.0f && m->metallic <= 1.0f) || !(m->transmission >= 0.0f && m->transmission <= 1.0f) ||
            !finite3(m->eta) || !finite3(m->k) || !finite3(m->fresnel_avg) ||
            (m->model == FR_MAT_CONDUCTOR && m->fresnel == FR_FRESNEL_EXACT && !(v3_min(m->eta) > 0.0f && v3_min(m->k) >= 0.0f)))
            return fr_fail(err, "section materials, byte %zu: material %u: bad microfacet model, flags, Fresnel mode, "
                           "roughness, anisotropy, metallic, transmission or index", AT(&m->model), i);
    }
    if (s->n_prims > 0 && s->n_materials == 0)
        return fr_fail(err, "section materials: primitives but no material");
    if (s->n_material_names && s->n_material_names != s->n_materials)
        return fr_fail(err, "section material_names: %u names for %u materials (expected 0 or one each)",
                       s->n_material_names, s->n_materials);
    if (names_validate("material_names", s->material_names, s->n_material_names, base, err) < 0 ||
        names_validate("object_names", s->object_names, s->n_object_names, base, err) < 0)
        return -1;
    uint64_t n_obj = (uint64_t)s->n_prims + s->n_planes + s->n_instances;
    if (s->n_objects && s->n_objects != n_obj)
        return fr_fail(err, "section objects: %u entries for %llu primitives, planes and instances (expected 0 or "
                       "one each)", s->n_objects, (unsigned long long)n_obj);
    for (uint32_t i = 0; i < s->n_objects; i++)
        if (s->objects[i] >= s->n_object_names)
            return fr_fail(err, "section objects, byte %zu: object %u of %u names", AT(&s->objects[i]),
                           s->objects[i], s->n_object_names);
    if (names_validate("group_names", s->group_names, s->n_group_names, base, err) < 0)
        return -1;
    if (s->n_group_names > PASS_LIGHT_GROUPS || (s->n_light_groups && s->n_light_groups != s->n_lights))
        return fr_fail(err, "section light_groups: %u entries for %u lights, %u groups (expected 0 or one per "
                       "light, at most %d groups)", s->n_light_groups, s->n_lights, s->n_group_names,
                       PASS_LIGHT_GROUPS);
    for (uint32_t i = 0; i < s->n_light_groups; i++)
        if (s->light_groups[i] >= s->n_group_names)
            return fr_fail(err, "section light_groups, byte %zu: group %u of %u names", AT(&s->light_groups[i]),
                           s->light_groups[i], s->n_group_names);
    if (validate_motions(s, base, err) < 0 || validate_instances(s, base, err) < 0)
        return -1;
    uint32_t top = s->n_meshes ? s->meshes[0].prim_first : s->n_prims;
    uint32_t kind_count[FR_PRIM_KINDS] = {s->n_triangles, s->n_spheres, s->n_rects, s->n_instances};
    for (uint32_t i = 0; i < s->n_prims; i++) {
        const fr_prim *p = &s->prims[i];
        if (p->kind >= FR_PRIM_KINDS || p->index >= kind_count[p->kind])
            return fr_fail(err, "section prims, byte %zu: primitive %u: bad kind %u or index %u",
                           AT(p->kind >= FR_PRIM_KINDS ? &p->kind : &p->index), i, p->kind,
                           p->index);
        if (p->material >= s->n_materials)
            return fr_fail(err, "section prims, byte %zu: primitive %u: material %u out of range", AT(&p->material), i,
                           p->material);
        if (i >= top && (p->kind != FR_PRIM_TRIANGLE || p->light != FR_NONE))
            return fr_fail(err, "section prims, byte %zu: primitive %u: a mesh's primitive must be a triangle and "
                           "not a light", AT(p), i);
        if (p->kind == FR_PRIM_INSTANCE && p->light != FR_NONE)
            return fr_fail(err, "section prims, byte %zu: primitive %u: an instance is not a light", AT(&p->light), i);
        if (p->light != FR_NONE && (p->light >= s->n_lights || s->lights[p->light].kind != FR_LIGHT_PRIM ||
                                    s->lights[p->light].prim != i))
            return fr_fail(err, "section prims, byte %zu: primitive %u: light %u does not point back", AT(&p->light), i,
                           p->light);
    }
    /* Vertex indices must be below the size of every array the triangle's
     * flags say it uses; one bound per flag combination keeps this loop
     * cheap for millions of triangles. */
    uint32_t bound[4] = {s->n_positions, s->n_positions, s->n_positions, s->n_positions};
    bound[FR_TRI_NORMALS] = bound[FR_TRI_NORMALS | FR_TRI_UVS] = s->n_positions < s->n_normals ? s->n_positions : s->n_normals;
    if (s->n_uvs < bound[FR_TRI_UVS]) bound[FR_TRI_UVS] = s->n_uvs;
    if (s->n_uvs < bound[FR_TRI_NORMALS | FR_TRI_UVS]) bound[FR_TRI_NORMALS | FR_TRI_UVS] = s->n_uvs;
    for (uint32_t i = 0; i < s->n_triangles; i++) {
        const fr_triangle *t = &s->triangles[i];
        uint32_t hi = t->v[0] > t->v[1] ? t->v[0] : t->v[1];
        hi = hi > t->v[2] ? hi : t->v[2];
        if (t->flags & ~(uint32_t)(FR_TRI_NORMALS | FR_TRI_UVS))
            return fr_fail(err, "section triangles, byte %zu: triangle %u: unknown flags 0x%x", AT(&t->flags), i,
                           t->flags);
        if (hi >= bound[t->flags]) {
            int k = t->v[0] == hi ? 0 : t->v[1] == hi ? 1 : 2;
            return fr_fail(err, "section triangles, byte %zu: triangle %u: vertex index %u out of range (%u usable)",
                           AT(t->v + k), i, hi, bound[t->flags]);
        }
    }
    for (uint32_t i = 0; i < s->n_planes; i++)
        if (s->planes[i].material >= s->n_materials || !finite3(s->planes[i].normal) ||
            !finite3(s->planes[i].point))
            return fr_fail(err, "section planes, byte %zu: plane %u: material out of range or non-finite geometry",
                           AT(s->planes + i), i);
    if (validate_lights(s, base, off, err) < 0 || validate_light_tree(s, base, err) < 0)
        return -1;
    return bvh_validate(s, base, err);
}

int fbin_open_mem(void *blob, size_t size, int mapped, fr_scene *out, fr_error *err)
{
    const unsigned char *p = blob;
    memset(out, 0, sizeof *out);
    if ((uintptr_t)blob % 16)
        return fr_fail(err, "scene bytes at %p are not 16-byte aligned", blob);
    if (size < HEADER_SIZE)
        return fr_fail(err, "header: file is %zu bytes, shorter than the %d-byte header", size, HEADER_SIZE);
    if (memcmp(p, fbin_magic, 8) != 0)
        return fr_fail(err, "byte 0: not a Franja binary scene (bad magic)");
    if (le_get32(p + 8) != FBIN_VERSION)
        return fr_fail(err, "byte 8: scene format version %u, this program reads version %d", le_get32(p + 8), FBIN_VERSION);
    if (le_get32(p + 12) != 0x01020304u || *(const uint32_t *)"\1\0\0\0" != 1)
        return fr_fail(err, "byte 12: byte order mismatch (binary scenes are little-endian)");
    uint32_t nsec = le_get32(p + 20);
    if (le_get32(p + 16) != HEADER_SIZE || nsec != SEC_COUNT)
        return fr_fail(err, "byte 16: header size %u / section count %u, expected %d / %d", le_get32(p + 16), nsec, HEADER_SIZE, SEC_COUNT);
    if (le_get64(p + 24) != size)
        return fr_fail(err, "byte 24: header says %llu bytes, file has %zu (truncated?)", (unsigned long long)le_get64(p + 24), size);
    if ((size_t)HEADER_SIZE + (size_t)ENTRY_SIZE * nsec > size)
        return fr_fail(err, "byte %d: section table runs past the end of the file", HEADER_SIZE);
    for (int k = 40; k < HEADER_SIZE; k++)
        if (p[k])
            return fr_fail(err, "byte %d: reserved header byte is not zero", k);
    uint64_t hash = XXH3_64bits(p + HEADER_SIZE, size - HEADER_SIZE);
    if (hash != le_get64(p + 32))
        return fr_fail(err, "byte 32: content hash mismatch (file is corrupt)");
    /* Sections follow the table in id order without overlapping. */
    uint64_t next = HEADER_SIZE + (uint64_t)ENTRY_SIZE * nsec, offs[SEC_COUNT + 1] = {0};
    for (uint32_t k = 0; k < nsec; k++) {
        const unsigned char *e = p + HEADER_SIZE + (size_t)ENTRY_SIZE * k;
        size_t at = HEADER_SIZE + (size_t)ENTRY_SIZE * k;
        uint32_t id = le_get32(e), elem = le_get32(e + 4);
        uint64_t off = le_get64(e + 8), count = le_get64(e + 16), bytes = le_get64(e + 24);
        if (id != k + 1)
            return fr_fail(err, "byte %zu: section %u has id %u, expected %u", at, k, id, k + 1);
        const section_desc *d = &sections[id];
        if (elem != d->elem)
            return fr_fail(err, "byte %zu: section %s: element size %u, expected %u", at, d->name, elem, d->elem);
        if (off % ALIGN || off < next || off > size || count > 0xffffffffu || bytes != count * elem ||
            bytes > size - off)
            return fr_fail(err, "byte %zu: section %s: offset %llu / count %llu out of bounds or overlapping", at,
                           d->name, (unsigned long long)off, (unsigned long long)count);
        next = off + bytes;
        offs[id] = off;
        if (!d->count_off) {
            if (count != 1)
                return fr_fail(err, "byte %zu: section %s: count %llu, expected 1", at, d->name, (unsigned long long)count);
            memcpy((char *)out + d->data_off, p + off, elem);
        } else {
            *(const void **)((char *)out + d->data_off) = p + off;
            *(uint32_t *)((char *)out + d->count_off) = (uint32_t)count;
        }
    }
    if (validate(out, p, offs, err) < 0) {
        memset(out, 0, sizeof *out);
        return -1;
    }
    out->hash = hash;
    out->blob = blob;
    out->blob_size = size;
    out->mapped = mapped;
    return 0;
}

int fbin_load(const char *path, fr_scene *out, fr_error *err)
{
    /* Mapped, not read: any size the address space holds. */
    int fd;
    size_t size;
    if (file_open_regular(path, SIZE_MAX, &fd, &size, err) < 0)
        return -1;
    /* MAP_POPULATE: validation reads every page anyway; faulting them in
     * one call is several times cheaper than page by page. */
    void *m = size ? mmap(NULL, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0) : MAP_FAILED;
    close(fd);
    if (m == MAP_FAILED)
        return fr_fail(err, "%s: %s", path, size ? strerror(errno) : "empty file");
    fr_error e;
    if (fbin_open_mem(m, size, 1, out, &e) < 0) {
        munmap(m, size);
        return fr_fail(err, "%s: %s", path, e.msg);
    }
    return 0;
}

int fbin_write(const fr_scene *s, const char *path, fr_error *err)
{
    return file_write_atomic(path, s->blob, s->blob_size, err);
}

void scn_free(fr_scene *s)
{
    scn_bvh_pages_free(s);
    if (s->blob) {
        if (s->mapped)
            munmap(s->blob, s->blob_size);
        else
            free(s->blob);
    }
    memset(s, 0, sizeof *s);
}
