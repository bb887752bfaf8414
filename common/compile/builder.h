/** @file builder.h
 * Assembling a scene in memory at compile time, before it is frozen.
 *
 * The scene readers (JSON, meshes) append to a builder; frz_scene()
 * (freeze.h) then derives the light table, builds the BVH, serializes
 * everything into the binary-scene layout and hands back a ready fr_scene
 * that owns those bytes.  So a scene read from JSON and one mapped from a
 * .fbin file are the same thing, with the same content hash.
 *
 * The builder owns its arrays; bld_free() releases them (also after
 * frz_scene, which copies what it needs, and after frz_scene_file, which
 * has released them already: bld_free leaves a zeroed builder).
 */
#ifndef FRANJA_BUILDER_H
#define FRANJA_BUILDER_H

#include "compile/budget.h"
#include "error.h"
#include "scene.h"

/** A growable array of fixed-size elements. */
typedef struct {
    void *data;                /**< count elements of elem bytes (malloc'd) */
    uint32_t count, cap;       /**< elements used, elements allocated */
    uint32_t elem;             /**< bytes per element */
} fr_array;

/** A mesh under construction (builder_instance.h): prims [first, first +
 * count) of the builder, triangles only, placed by instances only. */
typedef struct {
    uint32_t first, count;
    vec3 lo, hi;               /**< bounds of its vertices (set by bld_mesh_end) */
} bld_mesh;

/** Where an object's geometry starts (builder_object.h): the counts of
 * triangles, spheres, rects and instances (indexed by FR_PRIM_*) and of
 * planes (index FR_PRIM_KINDS) when it began. */
typedef struct {
    uint32_t object;           /**< index into object_names */
    uint32_t start[FR_PRIM_KINDS + 1];
} bld_object_run;

/** A scene under construction: the sections of fr_scene as growable
 * arrays, in the same element types. */
typedef struct {
    fr_settings settings;
    fr_camera camera;
    fr_array materials, prims, spheres, rects, triangles;
    fr_array positions, normals, uvs, planes;
    fr_array lights;           /**< point, spot, sun and environment lights (builder_light.h); frz_scene
                                    orders them and adds the area lights */
    fr_array textures, texels, media;   /**< fr_texture, uint32_t (words of texels), fr_medium */
    fr_volume volume;
    fr_tonemap tonemap;
    fr_world world;            /**< the environment (bld_environment); frz_scene sets the bounds and tables */
    fr_array distrib;          /**< float: filled by frz_scene */
    fr_array meshes;           /**< bld_mesh: meshes that instances place (builder_instance.h) */
    fr_array instances;        /**< fr_instance: meshes placed (builder_instance.h) */
    fr_array inst_motions;     /**< fr_inst_motion: how moving instances move (builder_motion.h) */
    fr_budget *budget;         /**< the compile's limits (budget.h), not owned; NULL: none */
    void (*warn)(void *user, const char *msg); /**< where readers of the scene's files report warnings
                                                    (scene_hooks.h); NULL: nowhere */
    void *warn_user;           /**< passed back to warn */
    fr_array light_nodes;      /**< fr_light_node: the light tree, built by frz_scene */
    int no_light_tree;         /**< 1: no light tree, next-event estimation picks by the power table alone */
    fr_array material_names;   /**< fr_name: the materials' names as far as given (bld_material_name) */
    fr_motion motion;          /**< what moves while the shutter is open (scene.h); zero: nothing.  frz_scene
                                    finishes camera_close as it does the camera */
    fr_array object_names;     /**< fr_name: the objects begun (builder_object.h) */
    fr_array object_runs;      /**< bld_object_run: where each object's geometry starts (builder_object.h) */
    fr_array inst_objects;     /**< uint32_t: each instance's object, once bld_flatten has set it */
    fr_array group_names;      /**< fr_name: the light groups (builder_group.h), "default" first */
    fr_array given_groups;     /**< uint32_t: the group of each light the readers added, as far as given */
    fr_array material_groups;  /**< uint32_t: the group of each emissive material, as far as given */
    fr_array light_groups;     /**< uint32_t: each light's group in the frozen light table (frz_lights) */
} fr_builder;

/** An empty builder: every array empty, settings and camera zero, no
 * budget. */
void bld_init(fr_builder *b);
/** Free every array and zero *b. */
void bld_free(fr_builder *b);

/** Names material `material` (an index into b->materials) `name`, cut to
 * 63 bytes at a character boundary, control characters as '?'; materials
 * not named are "".  -1 when memory runs out. */
int bld_material_name(fr_builder *b, uint32_t material, const char *name);

/** Sets *n to name, cut to 63 bytes at a character boundary, control
 * characters as '?', the rest zeros. */
void bld_name_set(fr_name *n, const char *name);

/** Append one element (copied); return its index, or FR_NONE when memory or
 * the 32-bit index space runs out. */
uint32_t bld_push(fr_array *a, const void *elem);

/** Add a shape; `material` must already be an index into b->materials.
 * Returns the new prim's index, or FR_NONE when memory runs out.
 * Emissive materials make the shape an area light when the scene is
 * frozen. */
uint32_t bld_sphere(fr_builder *b, vec3 center, float radius, uint32_t material);
/** A parallelogram (fr_rect); as bld_sphere. */
uint32_t bld_rect(fr_builder *b, vec3 origin, vec3 edge_u, vec3 edge_v, uint32_t material);
/** A triangle with its own three vertices; as bld_sphere. */
uint32_t bld_triangle(fr_builder *b, vec3 p0, vec3 p1, vec3 p2, uint32_t material);
/** A triangle with texture coordinates at its vertices; as bld_sphere. */
uint32_t bld_triangle_uv(fr_builder *b, const vec3 p[3], const vec2 uv[3], uint32_t material);

/** Append zeroed elements until the array holds `count` (vertex attribute
 * arrays are indexed like positions, so they are padded before use).
 * Returns 0, or -1 when memory runs out. */
int bld_pad(fr_array *a, uint32_t count);

/** Drops the vertices no triangle uses (a mesh file may hold many more
 * than its triangles need): the kept ones stay in their order, with their
 * normals and UVs, and triangles are renumbered to them, so the geometry,
 * and every image of it, is unchanged.  A builder whose vertices are all
 * used is left as it is.  Returns 0, or -1 when memory runs out (the
 * builder then unchanged). */
int bld_drop_unused_vertices(fr_builder *b, fr_error *err);

/** A material with no lobe, no emission and no texture (every texture index
 * FR_NONE, ior 1.5, normal-map strength 1): start every material here, and
 * once its colours are set, call bsdf_lobe_probs() (bsdf.h). */
void bld_material_init(fr_material *m);

/** Derive the camera's basis and tan_half from position, target, up and
 * vfov.  Returns 0, or -1 with *err set when they are degenerate. */
int bld_camera_finish(fr_camera *c, fr_error *err);

#endif
