/** @file geom.h
 * Rays and ray/primitive intersection.
 *
 * Every test returns the parametric distance t of the nearest hit in
 * (0, tmax), or 0 when there is none, so callers compare with a single
 * `if (t > 0)`.  Hits are reported from both sides of every surface.
 *
 * Every test rejects a hit whose t is not larger than a bound on the
 * rounding error of its own computation of t (Pharr, Jakob, Humphreys,
 * "Physically Based Rendering", 4th ed., section 6.8): a ray whose origin
 * lies on the surface, or on its far side, does not find that surface
 * again however the arithmetic rounds.  With geo_offset this keeps rays
 * from re-hitting the surface they leave, at any scale and position.
 */
#ifndef FRANJA_GEOM_H
#define FRANJA_GEOM_H

#include "scene.h"

/** A ray: origin o, direction d (need not be unit length), and the time
 * across the shutter, in [0, 1), of the sample that traces it (scene.h's
 * fr_motion; 0 when nothing moves, as `{o, d}` leaves it). */
typedef struct { vec3 o, d; float time; } fr_ray;

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

/** A bound on the rounding error of the triangle test's t, from the test's
 * intermediate values: the vertices' sheared coordinates relative to the
 * ray origin (x, y per vertex and the unscaled z per vertex), the edge
 * functions u, v, w, their sum det and the ray's 1/dz.  A sheared x or y
 * is off by at most gamma(3) (|x| + 2 |z|) (difference, shear product and
 * difference; |sx|, |sy| <= 1), within gamma(6) (mx + mz); an edge
 * function by 2 (gamma(2) mx my + dy mx + dx my); u az + v bz + w cz by
 * three times gamma(5) me mz + de mz; then the scale by 1/dz and the
 * division by det.  The BVH's four-lane test evaluates the same
 * expression, so both reject the same hits. */
#define GEO_TRI_ERROR(T, ABS, MAX, ax, bx, cx, ay, by, cy, az, bz, cz, u, v, w, sz, det) \
    ({                                                                             \
        T mx_ = MAX(ABS(ax), MAX(ABS(bx), ABS(cx)));                               \
        T my_ = MAX(ABS(ay), MAX(ABS(by), ABS(cy)));                               \
        T mz_ = MAX(ABS(az), MAX(ABS(bz), ABS(cz)));                               \
        T me_ = MAX(ABS(u), MAX(ABS(v), ABS(w)));                                  \
        T dx_ = (mx_ + mz_) * GEO_GAMMA(6), dy_ = (my_ + mz_) * GEO_GAMMA(6);      \
        T de_ = (mx_ * my_ * GEO_GAMMA(2) + dy_ * mx_ + dx_ * my_) * 2.0f;         \
        (me_ * mz_ * GEO_GAMMA(5) + de_ * mz_) * 3.0f * ABS(sz) / ABS(det);        \
    })

/** gamma(n) = n u / (1 - n u) with u = 2^-24: |x - fl(x)| <= gamma(n) |x|
 * for a result of n rounded float operations (Higham 2002, ch. 3). */
#define GEO_GAMMA(n) ((float)(n) * 0x1p-24f / (1.0f - (float)(n) * 0x1p-24f))

/** Hit points rebuilt from a hit's local coordinates, each with *err, a
 * bound on each coordinate's distance from the exact point of the surface
 * (the input to geo_offset).  Triangle: barycentrics b1, b2 of p1, p2.
 * Sphere: n is the unit direction from the centre.  Rectangle: the edge
 * coordinates s, t.  Plane: the point t along ray r. */
vec3 geo_triangle_point(vec3 p0, vec3 p1, vec3 p2, float b1, float b2, vec3 *err);
vec3 geo_sphere_point(const fr_sphere *s, vec3 n, vec3 *err);
vec3 geo_rect_point(const fr_rect *q, float s, float t, vec3 *err);
vec3 geo_plane_point(const fr_plane *p, const fr_ray *r, float t, vec3 *err);

/** The origin for a ray leaving surface point p (with the error bound err
 * from geo_*_point), pushed off the surface along the geometric normal ng
 * toward the side `dir` goes to: by the error bound projected on the
 * normal, each coordinate rounded away from p.  So the origin lies on the
 * side of the exact surface the ray leaves to, and the tests above, which
 * reject t within their own error, do not hit that surface again; no
 * fixed epsilon, whatever the scene's scale or distance from the origin.
 * A non-finite err or normal gives p unchanged. */
vec3 geo_offset(vec3 p, vec3 err, vec3 ng, vec3 dir);
/** geo_offset for every direction on one side of the surface: below = 1
 * for a dir with v3_dot(ng, dir) < 0, 0 otherwise (geo_offset depends on
 * dir through that side only, and gives these bits). */
vec3 geo_offset_side(vec3 p, vec3 err, vec3 ng, int below);

#endif
