/** @file light.h
 * Lights seen from the scene and lights as the start of paths.
 *
 * For next-event estimation from a point: lgt_choose picks a light by the
 * light tree (scene.h, fr_light_node), a walk from the root that goes to
 * each child with probability its importance from that point over the sum
 * of both (distance, the cone of the lights' emission, the node's bounds
 * and power); the distant lights (sun, environment) keep the share the
 * power table gives them, split among them in proportion to power.
 * lgt_sample picks a light so and a point or direction on it and gives the
 * solid-angle pdf of having done so; lgt_pdf and lgt_distant give the same
 * pdf (lgt_pick_pdf the same pick, bit for bit) for a point or direction
 * that a BSDF sample found, for multiple importance sampling.  Where no
 * point is known when the light is picked (paths that start on a light,
 * equiangular sampling in media) the pick is the power table's: lgt_pick,
 * lgt_sample_table, lgt_pdf_table.
 * lgt_sample and lgt_sample_chosen choose directions uniformly in the
 * solid angle that a rectangle or triangle subtends (spherical.h) where it
 * is near enough and not seen edge-on or from behind a one-sided emitter,
 * else points uniformly by area; lgt_sample_table always by area (the
 * density that the strategies of bidirectional path tracing and
 * equiangular sampling count for the point, lgt_pdf_table's); uniformly in
 * the visible cone on spheres seen from outside and on a sun's disk, in
 * proportion to the map (times sin theta) on an environment.
 *
 * For paths that start on a light (light tracing, bidirectional methods):
 * lgt_sample_emit starts a ray on a light with the densities of its origin
 * and direction, and lgt_pdf_emit gives those densities for a given ray.
 *
 * Light kinds and units are in scene.h (fr_light, fr_world).  Delta lights
 * (point, spot, a sun without a disk) cannot be hit by a ray: they are
 * reached by light sampling only.  Distant lights (sun, environment) are
 * hit by rays that leave the scene; they come first in s->lights, and
 * lgt_n_distant counts them.
 */
#ifndef FRANJA_LIGHT_H
#define FRANJA_LIGHT_H

#include "trace.h"

/** A point sampled on a light, as seen from a shading point. */
typedef struct {
    vec3 wi;                   /**< unit direction from the shading point to the light */
    float dist;                /**< distance to the sampled point; INFINITY for distant lights */
    vec3 radiance;             /**< incident radiance (area, sun disk, environment), intensity/dist^2 (point, spot)
                                    or irradiance (sun without a disk) */
    float pdf;                 /**< solid-angle pdf including the pick; for a delta light the pick alone */
    float pick;                /**< the probability with which the light was picked */
    vec3 p, n;                 /**< sampled point and its light's normal (local lights only) */
    uint32_t light;            /**< index into lights */
    uint32_t prim;             /**< the emitting prim, FR_NONE for other lights */
    int delta;                 /**< 1 for point, spot and a sun without a disk: no MIS */
    int distant;               /**< 1 for sun and environment: the shadow ray is unbounded */
} fr_light_sample;

/** The light that the power table picks with number u (the scene has
 * lights): the first whose cdf exceeds u. */
uint32_t lgt_pick(const fr_scene *s, float u);

/** The light that next-event estimation from point `from` (unit normal
 * nrm there, the shading normal; zero in a medium) picks with number *u: a distant light by the power table, or a local one by the
 * light tree; *pick receives the probability of that pick, and *u the
 * number rescaled within the pick (uniform in [0, 1) again, with about
 * log2(1 / *pick) fewer significant bits).  FR_NONE when the scene has no
 * lights or no light of the tree can reach `from` (every importance 0). */
uint32_t lgt_choose(const fr_scene *s, vec3 from, vec3 nrm, float *u, float *pick);

/** The probability that lgt_choose picks light `light` from `from` (normal
 * nrm): the
 * product of its path's branch probabilities, the same float as *pick
 * there; 0 where lgt_choose never picks it. */
float lgt_pick_pdf(const fr_scene *s, uint32_t light, vec3 from, vec3 nrm);

/** Number of distant lights: lights[0 .. n) are the sun and environment lights. */
uint32_t lgt_n_distant(const fr_scene *s);

/** Sample a light as seen from point `from` (normal nrm, as lgt_choose
 * takes it): lgt_choose with upick, then
 * lgt_sample_chosen.  Returns 0 if no light is picked or the sample
 * carries no light (back side of a one-sided emitter, outside a spot's
 * cone, a black part of a map). */
int lgt_sample(const fr_scene *s, vec3 from, vec3 nrm, float upick, float u1, float u2, fr_light_sample *out);

/** A point or direction on light li, picked with probability `pick`, seen
 * from `from`, with (u1, u2); returns as lgt_sample. */
int lgt_sample_chosen(const fr_scene *s, uint32_t li, float pick, vec3 from, float u1, float u2,
                      fr_light_sample *out);

/** lgt_sample with the power table's pick (lgt_pick) instead of the tree's,
 * and rectangles and triangles sampled by area (lgt_fixed_point's point
 * for the same numbers): for strategies whose other densities count the
 * table's pick and the area density (the connections of bidirectional
 * path tracing, whose MIS weights take the light vertex's density as a
 * light subpath's origin, lgt_pdf_emit's; equiangular sampling). */
int lgt_sample_table(const fr_scene *s, vec3 from, float upick, float u1, float u2, fr_light_sample *out);

/** The point lgt_sample picks on light `light` with (u1, u2) wherever it is
 * seen from, into *p: a point or spot light's position, or the point
 * uniform by area on a rectangle or triangle.  Returns 0 for lights whose
 * sampled point depends on where they are seen from (spheres) or that have
 * none (sun, environment).  Equiangular sampling in media picks the light
 * point first and the scattering point after it. */
int lgt_fixed_point(const fr_scene *s, uint32_t light, float u1, float u2, vec3 *p);

/** Whether lgt_fixed_point has a point for light `light` (it fails for a
 * kind of light, never for a point). */
int lgt_has_fixed_point(const fr_scene *s, uint32_t light);

/** Solid-angle pdf that lgt_sample would have produced the point `p` (normal
 * `n`) of area light `light` from `from` (normal nrm there): for
 * rectangles and triangles the same choice between solid angle and area
 * as the sampler's, from the same (from, light), and the same density. */
float lgt_pdf(const fr_scene *s, uint32_t light, vec3 from, vec3 nrm, vec3 p, vec3 n);

/** The same for lgt_sample_table (the power table's pick, points by area;
 * no normal). */
float lgt_pdf_table(const fr_scene *s, uint32_t light, vec3 from, vec3 p, vec3 n);

/** Radiance that distant light `light` sends along -dir toward the scene
 * (dir: unit, from the scene toward the sky), and in *pdf the solid-angle
 * pdf, including the pick, with which lgt_sample picks that direction of
 * that light (the tree and the table pick distant lights alike).  Both 0 for a sun without a disk, and outside the disk. */
vec3 lgt_distant(const fr_scene *s, uint32_t light, vec3 dir, float *pdf);

/** Radiance an emissive material sends toward direction `w` from a surface
 * with geometric normal `ng` (front side only unless two-sided). */
vec3 lgt_emitted(const fr_material *m, vec3 ng, vec3 w);

/** glTF's spot falloff at cosine `c` from the axis: 1 inside the inner cone,
 * 0 outside the outer one, ((c - cos_outer) / (cos_inner - cos_outer))^2
 * between them (KHR_lights_punctual's reference, its denominator at least
 * 0.001). */
float lgt_spot_falloff(const fr_light *l, float c);

/** A ray leaving a light. */
typedef struct {
    fr_ray ray;                /**< origin on the light, unit direction; for distant lights the origin lies on
                                    a disk of the world's radius, facing the scene from outside its bounds */
    vec3 perr;                 /**< area lights: a bound on the origin's error per coordinate (geom.h), for
                                    geo_offset; 0 for the other kinds */
    vec3 n;                    /**< the surface normal at the origin (area lights, on the side emitted into);
                                    ray.d for the other kinds */
    vec3 Le;                   /**< radiance along the ray (area, sun disk, environment), intensity toward
                                    ray.d (point, spot) or irradiance (sun without a disk) */
    float pdf_pos;             /**< area density of the origin including the pick; the pick alone for point and
                                    spot lights; pick / (pi r^2) for distant lights */
    float pdf_dir;             /**< solid-angle density of ray.d; 1 for a sun without a disk */
    uint32_t light;            /**< index into lights */
    uint32_t prim;             /**< the emitting prim, FR_NONE for other lights */
    int delta_pos;             /**< point and spot lights */
    int delta_dir;             /**< a sun without a disk */
    int distant;               /**< sun, environment */
} fr_light_emit;

/** Start a ray on a light: the light picked by upick as lgt_pick does,
 * the origin from (u1, u2), the direction from (u3, u4): cosine-weighted
 * about the normal for area lights (two-sided ones pick a side with u3),
 * uniform over the sphere (point) or the outer cone (spot), from the disk
 * (sun) or the map (environment).  Returns 0 when the ray carries no
 * light. */
int lgt_sample_emit(const fr_scene *s, float upick, float u1, float u2, float u3, float u4, fr_light_emit *out);

/** The densities lgt_sample_emit gives a ray of light `light` leaving point
 * p (with the light's normal n there; both ignored by distant lights) in
 * unit direction dir.  Zero where it never starts one; pdf_dir is 0 for a
 * sun without a disk. */
void lgt_pdf_emit(const fr_scene *s, uint32_t light, vec3 p, vec3 n, vec3 dir, float *pdf_pos, float *pdf_dir);

#endif
