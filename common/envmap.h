/** @file envmap.h
 * The environment light on the render path: the radiance arriving from a
 * direction, sampling a direction in proportion to it, and that sampling's
 * density.
 *
 * The mapping from directions to the equirectangular map, its rotation and
 * the sampling tables are described with fr_world in scene.h; lookups wrap
 * around in u and clamp in v, nearest or bilinear as the texture's filter
 * says.  A constant environment is sampled uniformly over the sphere.
 * Everything is + - * / sqrt and fmath.h (invariant 2).  Directions are
 * unit vectors pointing away from the scene (toward the sky).  Callers
 * check that the scene has an environment (s->world.env != FR_ENV_NONE).
 */
#ifndef FRANJA_ENVMAP_H
#define FRANJA_ENVMAP_H

#include "scene.h"

/** Radiance arriving from direction `dir`. */
vec3 env_radiance(const fr_scene *s, vec3 dir);

/** Solid-angle density with which env_sample picks `dir` (0 where the map
 * is black all around, and at the poles of a map). */
float env_pdf(const fr_scene *s, vec3 dir);

/** env_radiance and env_pdf of `dir` at once (its map coordinates found
 * once): the radiance, and the density in *pdf. */
vec3 env_eval(const fr_scene *s, vec3 dir, float *pdf);

/** A direction from two uniform numbers in [0, 1), with its solid-angle
 * density in *pdf (0 when the sample is unusable: leave it) and the
 * radiance arriving from it in *radiance. */
vec3 env_sample(const fr_scene *s, float u1, float u2, float *pdf, vec3 *radiance);

/** Texture coordinates of direction `dir` after the rotation: u (from 0 at
 * -x through 0.25 at -z, 0.5 at +x, 0.75 at +z) and v (1 at +y, 0 at -y),
 * both in [0, 1]. */
vec2 env_uv(const fr_scene *s, vec3 dir);

#endif
