/* builder.c -- a scene under construction: arrays of shapes, materials and the
 * camera (see builder.h). */

#include "compile/builder.h"

#include <stdlib.h>
#include <string.h>

#include "fmath.h"
#include "geom.h"

static void array_init(fr_array *a, uint32_t elem) { memset(a, 0, sizeof *a); a->elem = elem; }

void bld_init(fr_builder *b)
{
    memset(b, 0, sizeof *b);
    array_init(&b->materials, sizeof(fr_material));
    array_init(&b->prims, sizeof(fr_prim));
    array_init(&b->spheres, sizeof(fr_sphere));
    array_init(&b->rects, sizeof(fr_rect));
    array_init(&b->triangles, sizeof(fr_triangle));
    array_init(&b->positions, sizeof(vec3));
    array_init(&b->normals, sizeof(vec3));
    array_init(&b->uvs, sizeof(vec2));
    array_init(&b->planes, sizeof(fr_plane));
    array_init(&b->lights, sizeof(fr_light));
    array_init(&b->textures, sizeof(fr_texture));
    array_init(&b->texels, sizeof(uint32_t));
    array_init(&b->media, sizeof(fr_medium));
    array_init(&b->distrib, sizeof(float));
    array_init(&b->meshes, sizeof(bld_mesh));
    array_init(&b->instances, sizeof(fr_instance));
    array_init(&b->inst_motions, sizeof(fr_inst_motion));
    array_init(&b->light_nodes, sizeof(fr_light_node));
    array_init(&b->material_names, sizeof(fr_name));
    array_init(&b->object_names, sizeof(fr_name));
    array_init(&b->object_runs, sizeof(bld_object_run));
    array_init(&b->inst_objects, sizeof(uint32_t));
    array_init(&b->group_names, sizeof(fr_name));
    array_init(&b->given_groups, sizeof(uint32_t));
    array_init(&b->material_groups, sizeof(uint32_t));
    array_init(&b->light_groups, sizeof(uint32_t));
    b->world.env_light = b->world.env_texture = FR_NONE;
    b->world.rot_cos = 1.0f;
}

void bld_free(fr_builder *b)
{
    fr_array *all[] = {&b->materials, &b->prims, &b->spheres, &b->rects, &b->triangles,
                       &b->positions, &b->normals, &b->uvs, &b->planes, &b->lights,
                       &b->textures, &b->texels, &b->media, &b->distrib, &b->meshes, &b->instances,
                       &b->inst_motions,                       &b->light_nodes, &b->material_names,
                       &b->object_names, &b->object_runs, &b->inst_objects, &b->group_names,
                       &b->given_groups, &b->material_groups, &b->light_groups};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        free(all[i]->data);
    memset(b, 0, sizeof *b);
}

int bld_material_name(fr_builder *b, uint32_t material, const char *name)
{
    fr_name empty;
    memset(&empty, 0, sizeof empty);
    while (b->material_names.count <= material)
        if (bld_push(&b->material_names, &empty) == FR_NONE)
            return -1;
    bld_name_set((fr_name *)b->material_names.data + material, name);
    return 0;
}

void bld_name_set(fr_name *n, const char *name)
{
    size_t k = strlen(name);
    if (k > sizeof n->name - 1) {
        k = sizeof n->name - 1;
        while (k > 0 && ((unsigned char)name[k] & 0xc0) == 0x80)
            k--; /* not inside a UTF-8 character */
    }
    memset(n->name, 0, sizeof n->name);
    for (size_t i = 0; i < k; i++) {
        unsigned char ch = (unsigned char)name[i];
        n->name[i] = ch < 0x20 || ch == 0x7f ? '?' : (char)ch;
    }
}

uint32_t bld_push(fr_array *a, const void *elem)
{
    if (a->count == a->cap) {
        uint32_t cap = a->cap ? a->cap * 2 : 16;
        if (cap <= a->cap || cap >= FR_NONE / 2)
            return FR_NONE;
        void *p = realloc(a->data, (size_t)cap * a->elem);
        if (!p)
            return FR_NONE;
        a->data = p;
        a->cap = cap;
    }
    memcpy((char *)a->data + (size_t)a->count * a->elem, elem, a->elem);
    return a->count++;
}

static uint32_t push_prim(fr_builder *b, uint32_t kind, uint32_t index, uint32_t material)
{
    if (index == FR_NONE)
        return FR_NONE;
    fr_prim p = {kind, index, material, FR_NONE};
    return bld_push(&b->prims, &p);
}

uint32_t bld_sphere(fr_builder *b, vec3 center, float radius, uint32_t material)
{
    fr_sphere s = {center, radius};
    return push_prim(b, FR_PRIM_SPHERE, bld_push(&b->spheres, &s), material);
}

uint32_t bld_rect(fr_builder *b, vec3 origin, vec3 edge_u, vec3 edge_v, uint32_t material)
{
    fr_rect r = geo_rect_make(origin, edge_u, edge_v);
    return push_prim(b, FR_PRIM_RECT, bld_push(&b->rects, &r), material);
}

uint32_t bld_triangle(fr_builder *b, vec3 p0, vec3 p1, vec3 p2, uint32_t material)
{
    uint32_t i0 = bld_push(&b->positions, &p0);
    uint32_t i1 = bld_push(&b->positions, &p1);
    uint32_t i2 = bld_push(&b->positions, &p2);
    if (i0 == FR_NONE || i1 == FR_NONE || i2 == FR_NONE)
        return FR_NONE;
    fr_triangle t = {{i0, i1, i2}, 0};
    return push_prim(b, FR_PRIM_TRIANGLE, bld_push(&b->triangles, &t), material);
}

void bld_material_init(fr_material *m)
{
    memset(m, 0, sizeof *m);
    m->tex_diffuse = m->tex_glossy = m->tex_specular = m->tex_transmit = m->tex_emission = FR_NONE;
    m->tex_bump = m->tex_normal = m->tex_roughness = m->tex_metallic = m->tex_transmission = FR_NONE;
    m->ior = 1.5f;
    m->normal_strength = 1.0f;
}

int bld_pad(fr_array *a, uint32_t count)
{
    if (a->count >= count)
        return 0;
    /* A zeroed element of the array's own size (light-tree nodes are 64
     * bytes, BVH nodes 256). */
    void *zero = calloc(1, a->elem);
    int rc = zero ? 0 : -1;
    while (rc == 0 && a->count < count)
        if (bld_push(a, zero) == FR_NONE)
            rc = -1;
    free(zero);
    return rc;
}

uint32_t bld_triangle_uv(fr_builder *b, const vec3 p[3], const vec2 uv[3], uint32_t material)
{
    if (bld_pad(&b->uvs, b->positions.count) < 0)
        return FR_NONE;
    for (int k = 0; k < 3; k++)
        if (bld_push(&b->uvs, &uv[k]) == FR_NONE)
            return FR_NONE;
    uint32_t t = bld_triangle(b, p[0], p[1], p[2], material);
    if (t != FR_NONE)
        ((fr_triangle *)b->triangles.data)[((fr_prim *)b->prims.data)[t].index].flags |= FR_TRI_UVS;
    return t;
}

int bld_camera_finish(fr_camera *c, fr_error *err)
{
    vec3 f = v3_sub(c->target, c->position);
    if (!(v3_len2(f) > 0.0f))
        return fr_fail(err, "camera: target equals position");
    f = v3_norm(f);
    vec3 r = v3_cross(f, c->up);
    if (!(v3_len2(r) > 1e-12f * v3_len2(c->up)))
        return fr_fail(err, "camera: up is parallel to the viewing direction (or zero)");
    r = v3_norm(r);
    /* Image +x is right = forward x up seen from behind the camera; with
     * +y up and view along +z that is world -x, as the Cornell convention says. */
    c->forward = f;
    c->right = r;
    c->upv = v3_cross(r, f);
    if (!(c->vfov > 0.0f && c->vfov < FM_PI))
        return fr_fail(err, "camera: fov must be in (0, 180) degrees");
    c->tan_half = fm_tanf(0.5f * c->vfov);
    return 0;
}

/* Moves the elements of a whose index i (below a->count) has keep[i] set
 * to the front, in order. */
static void compact(fr_array *a, const uint32_t *keep, uint32_t n)
{
    uint32_t o = 0, lim = a->count < n ? a->count : n;
    char *d = a->data;
    for (uint32_t i = 0; i < lim; i++)
        if (keep[i] != FR_NONE) {
            if (o != i)
                memcpy(d + (size_t)o * a->elem, d + (size_t)i * a->elem, a->elem);
            o++;
        }
    a->count = o;
}

int bld_drop_unused_vertices(fr_builder *b, fr_error *err)
{
    uint32_t n = b->positions.count;
    if (n == 0)
        return 0;
    uint32_t *to = malloc((size_t)n * sizeof *to);
    if (!to)
        return fr_fail(err, "out of memory (%u vertices)", n);
    for (uint32_t i = 0; i < n; i++)
        to[i] = FR_NONE;
    fr_triangle *t = b->triangles.data;
    for (uint32_t k = 0; k < b->triangles.count; k++)
        for (int c = 0; c < 3; c++)
            to[t[k].v[c]] = 0;
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++)
        if (to[i] != FR_NONE)
            to[i] = m++;
    if (m < n) {
        compact(&b->positions, to, n);
        compact(&b->normals, to, n);
        compact(&b->uvs, to, n);
        for (uint32_t k = 0; k < b->triangles.count; k++)
            for (int c = 0; c < 3; c++)
                t[k].v[c] = to[t[k].v[c]];
    }
    free(to);
    return 0;
}
