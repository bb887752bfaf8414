/** @file trace.h
 * Finding what a ray hits in a scene, and describing the hit.
 *
 * trace_closest walks the BVH (or every primitive when the scene has no
 * BVH) and the infinite planes; trace_occluded stops at the first hit, for
 * shadow rays.
 */
#ifndef FRANJA_TRACE_H
#define FRANJA_TRACE_H

#include "error.h"
#include "geom.h"

/** Where a ray hit, before shading: which primitive and its local
 * coordinates, enough to rebuild the surface with trace_surface(). */
typedef struct {
    float t;
    uint32_t prim;             /**< index into prims, or FR_NONE for a plane */
    uint32_t plane;            /**< index into planes when prim == FR_NONE */
    float a, b;                /**< barycentrics (triangle) or edge coords (rect) */
    uint32_t inst;             /**< 1 + index into instances when prim is a triangle of an instanced mesh
                                    (a, b then in object space), else 0 */
} fr_hit;

/** The local geometry at a hit, for shading. */
typedef struct {
    vec3 p;                    /**< position */
    vec3 perr;                 /**< bound on p's error per coordinate (for geo_offset) */
    vec3 ng;                   /**< geometric normal (unit, front side) */
    vec3 ns;                   /**< shading normal (unit, same hemisphere as ng) */
    vec2 uv;                   /**< texture coordinates */
    vec3 dpdu, dpdv;           /**< how p moves with u and v (tangents for bump and normal maps) */
    uint32_t material;
    uint32_t light;            /**< FR_NONE unless an area light */
    /** What was hit, as an index into the scene's objects section: the
     * prim, n_prims + the plane, or n_prims + n_planes + the instance
     * (trace_surface* set it; the object_id passes read it). */
    uint32_t element;
    /** Width (scene units) of the ray's footprint on the surface, from
     * which image lookups pick a mip level (texture.h); 0 (as every
     * trace_surface* leaves it): the finest level. */
    float footprint;
    /** The time across the shutter of the ray that found it (fr_ray.time):
     * rays leaving the surface carry it on. */
    float time;
} fr_surface;

/** Nearest hit in (0, tmax).  Returns 1 and fills *hit, or 0.  The result
 * is exactly what testing every plane and then every primitive in index
 * order with trace_prim would give: of hits at the same t the plane or the
 * lowest primitive index wins, whatever order the BVH visits them in.  A
 * ray with a non-finite origin or direction hits no primitive. */
int trace_closest(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit);
/** 1 if anything but prim `skip` (FR_NONE: nothing skipped) is hit in
 * (0, tmax).  Shadow rays skip the light they aim at: a convex emitter
 * cannot hide its own sampled point, and near its silhouette rounding would
 * make it seem to. */
int trace_occluded(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip);
/** The BVH walks, each the same traversal compiled for an instruction set:
 * the portable one (SSE2, NEON or plain C) everywhere, and on x86-64 one
 * for AVX2 and one for AVX-512 (x86-64-v4: F, VL, BW, DQ).  All give the
 * same bits; the fastest one the processor and its OS can run is used
 * unless another is chosen. */
enum { TRACE_WALK_PORTABLE, TRACE_WALK_AVX2, TRACE_WALK_AVX512, TRACE_WALKS };
/** The walks this processor and its OS can run: bit k set for walk k. */
unsigned trace_walks(void);
/** The walk in use. */
int trace_walk(void);
/** Use walk k from now on, if trace_walks() has it (otherwise nothing
 * changes).  Returns the walk now in use.  Not thread-safe: call it
 * before tracing starts; tests and benchmarks use it to compare walks. */
int trace_set_walk(int k);
/** "portable", "avx2" or "avx512" for walk k; NULL for another k. */
const char *trace_walk_name(int k);
/** Use the walk `name` names (the value of FRANJA_WALK; NULL or empty
 * keeps the default).  Returns 0, or -1 with *err set when the name is
 * unknown or the processor cannot run that walk. */
int trace_walk_choose(const char *name, fr_error *err);
/** Nearest hit on one primitive, for tests and the BVH: t or 0. */
float trace_prim(const fr_scene *s, uint32_t prim, const fr_ray *r, float tmax, float *a, float *b);
/** Rebuild the surface at a hit. */
void trace_surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit, fr_surface *out);
/** trace_surface, except that with `uv` 0 the fields uv, dpdu and dpdv
 * are left 0 instead of computed (the others are the same bits): for a
 * caller whose shading of the hit's material (trace_hit_material) reads
 * none of them. */
void trace_surface_uv(const fr_scene *s, const fr_ray *r, const fr_hit *hit, fr_surface *out, int uv);
/** Index into materials of what a hit found (a primitive's or a plane's). */
static inline uint32_t trace_hit_material(const fr_scene *s, const fr_hit *hit)
{
    return hit->prim == FR_NONE ? s->planes[hit->plane].material : s->prims[hit->prim].material;
}

#endif
