/** @file light.h
 * Sampling lights for next-event estimation, and the pdf of
 * having done so, for multiple importance sampling.
 *
 * A light is picked with probability `pick` (proportional to its power);
 * then a point on it: uniform by area on rectangles and triangles, uniform
 * in the visible cone (solid angle) on spheres seen from outside.
 */
#ifndef FRANJA_LIGHT_H
#define FRANJA_LIGHT_H

#include "trace.h"

/** A point sampled on a light, as seen from a shading point. */
typedef struct {
    vec3 wi;                   /**< unit direction from the shading point to the light */
    float dist;                /**< distance to the sampled point */
    vec3 radiance;             /**< incident radiance (area) or intensity/dist^2 (point) */
    float pdf;                 /**< solid-angle pdf including the pick; for a point light the pick alone */
    vec3 p, n;                 /**< sampled point and its light's normal */
    uint32_t prim;             /**< the emitting prim, FR_NONE for a point light */
    int delta;                 /**< 1 for point lights: no MIS */
} fr_light_sample;

/** The light that lgt_sample picks with number u (the scene has lights). */
uint32_t lgt_pick(const fr_scene *s, float u);

/** Sample a light as seen from point `from`.  Returns 0 if the scene has no
 * lights or the sample carries no light (back side of a one-sided emitter). */
int lgt_sample(const fr_scene *s, vec3 from, float upick, float u1, float u2, fr_light_sample *out);

/** Solid-angle pdf that lgt_sample would have produced the point `p` (normal
 * `n`) of area light `light` from `from`. */
float lgt_pdf(const fr_scene *s, uint32_t light, vec3 from, vec3 p, vec3 n);

/** Radiance an emissive material sends toward direction `w` from a surface
 * with geometric normal `ng` (front side only unless two-sided). */
vec3 lgt_emitted(const fr_material *m, vec3 ng, vec3 w);

#endif
