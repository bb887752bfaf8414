/* builder.h -- assembling a scene in memory before it is frozen.
 *
 * The scene parsers (JSON, meshes) append to a builder; bld_finish() then
 * derives the light list, builds the BVH, serializes everything into the
 * binary-scene layout and hands back a ready fr_scene that owns those
 * bytes.  So a scene read from JSON and one mapped from a .fbin file are
 * the same thing, with the same content hash.
 *
 * The builder owns its arrays; bld_free() releases them (also after
 * bld_finish, which copies what it needs). */
#ifndef FRANJA_BUILDER_H
#define FRANJA_BUILDER_H

#include "error.h"
#include "scene.h"

/* A growable array of fixed-size elements. */
typedef struct { void *data; uint32_t count, cap; uint32_t elem; } fr_array;

typedef struct {
    fr_settings settings;
    fr_camera camera;
    fr_array materials, prims, spheres, rects, triangles;
    fr_array positions, normals, uvs, planes, lights;
    fr_array textures, texels, media;   /* fr_texture, float, fr_medium */
    fr_volume volume;
    fr_tonemap tonemap;
} fr_builder;

void bld_init(fr_builder *b);
void bld_free(fr_builder *b);

/* Append one element (copied); return its index, or FR_NONE when memory or
 * the 32-bit index space runs out. */
uint32_t bld_push(fr_array *a, const void *elem);

/* Add a shape; material must already be an index into b->materials.
 * Emissive materials make the shape an area light at bld_finish(). */
uint32_t bld_sphere(fr_builder *b, vec3 center, float radius, uint32_t material);
uint32_t bld_rect(fr_builder *b, vec3 origin, vec3 edge_u, vec3 edge_v, uint32_t material);
uint32_t bld_triangle(fr_builder *b, vec3 p0, vec3 p1, vec3 p2, uint32_t material);
/* A triangle with texture coordinates at its vertices. */
uint32_t bld_triangle_uv(fr_builder *b, const vec3 p[3], const vec2 uv[3], uint32_t material);

/* Append zeroed elements until the array holds `count` (vertex attribute
 * arrays are indexed like positions, so they are padded before use).
 * Returns -1 when memory runs out. */
int bld_pad(fr_array *a, uint32_t count);

/* A material with no lobe, no emission and no texture (every texture index
 * FR_NONE, ior 1.5, normal-map strength 1): start every material here. */
void bld_material_init(fr_material *m);

/* Fill p_lobe of a material from its lobe colours.  Returns -1 if the
 * material has no lobe at all and no emission (it would be black). */
void bld_material_finish(fr_material *m);

/* Derive camera basis and tan_half.  -1 if degenerate. */
int bld_camera_finish(fr_camera *c, fr_error *err);

/* Freeze the builder into *out (lights, BVH, binary layout, hash).  The
 * builder is left intact (free it with bld_free). */
int bld_finish(fr_builder *b, fr_scene *out, fr_error *err);

#endif
