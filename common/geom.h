/** @file geom.h
 * Rays and ray/primitive intersection.
 *
 * Every test returns the parametric distance t of the nearest hit in
 * (0, tmax), or 0 when there is none, so callers compare with a single
 * `if (t > 0)`.  Hits are reported from both sides of every surface.
 */
#ifndef FRANJA_GEOM_H
#define FRANJA_GEOM_H

#include "scene.h"

typedef struct { vec3 o, d; } fr_ray;   /**< d need not be unit length */

float geo_sphere(const fr_sphere *s, const fr_ray *r, float tmax);
float geo_plane(const fr_plane *p, const fr_ray *r, float tmax);
/** The rectangle origin + s*edge_u + t*edge_v with its derived fields. */
fr_rect geo_rect_make(vec3 origin, vec3 edge_u, vec3 edge_v);
/** Parallelogram; *s,*t receive the hit's coordinates along edge_u, edge_v. */
float geo_rect(const fr_rect *q, const fr_ray *r, float tmax, float *s, float *t);
/** Triangle by the watertight test (Woop, Benthin, Wald 2013): rays through
 * a shared edge or vertex hit exactly one of the triangles that share it.
 * *b1,*b2 receive the barycentrics of p1 and p2. */
float geo_triangle(vec3 p0, vec3 p1, vec3 p2, const fr_ray *r, float tmax, float *b1, float *b2);

/** The origin for a ray leaving surface point p, pushed off the surface
 * along the geometric normal ng toward the side `dir` goes to.  The push is
 * a few ulps of p's coordinates (larger for larger coordinates), so it
 * clears the rounding error of the hit point at any scene scale without a
 * fixed epsilon on t (Wächter and Binder, Ray Tracing Gems ch. 6). */
vec3 geo_offset(vec3 p, vec3 ng, vec3 dir);

#endif
