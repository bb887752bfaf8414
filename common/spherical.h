/** @file spherical.h
 * Uniform sampling of the solid angle of rectangles and triangles.
 *
 * Directions uniform in the solid angle that a rectangle or a triangle
 * subtends at a point: next-event estimation from a point near an area
 * light samples these instead of points uniform by area, so that the
 * estimate loses the factor cos_l / d^2 that varies over the light
 * (light.c).
 *
 * Rectangles: the area-preserving parametrisation of Urena, Fajardo and
 * King (2013), "An area-preserving parametrization for spherical
 * rectangles": the first number fixes the solid angle of the slice of the
 * rectangle left of a line parallel to its second edge, the second a height
 * along that line uniform in the sine of its elevation.  Triangles: Arvo
 * (1995), "Stratified sampling of spherical triangles": the first number
 * fixes the area of the sub-triangle with a moved third vertex, the second
 * a point on the arc from the second vertex to it uniform in solid angle.
 *
 * Each setup decides, from the point and the shape alone, whether the
 * sampling is safe; where it is not it returns 0 and the caller samples by
 * area: the shape's solid angle below SPHERICAL_MIN_SOLID_ANGLE (where
 * rounding in the sums of angles would show), the point within
 * SPHERICAL_MIN_HEIGHT of the shape's size of its plane (seen edge-on), or
 * a parallelogram that is not a rectangle.  Whether it is worth its cost
 * is the caller's choice (light.c samples lights far from a point by
 * area).  The solid angle it gives is the sampler's density's inverse; the
 * caller's pdf for a direction found otherwise must run the same setup to
 * take the same decision and the same density (the same bits: + - * /
 * sqrt and fmath.h only).
 */
#ifndef FRANJA_SPHERICAL_H
#define FRANJA_SPHERICAL_H

#include "vec.h"

/** Below this solid angle (steradians) the setups refuse: the spherical
 * rectangle's solid angle is a sum of four angles less 2 pi, whose rounding
 * (about 1e-6 sr in float) would be more than a thousandth of it, and the
 * steps of Arvo's construction lose about 1e-16 / omega of their precision
 * in double; and so small a shape looks the same from all its points
 * within a few percent, where sampling by area is as good. */
#define SPHERICAL_MIN_SOLID_ANGLE 1e-3f

/** The setups refuse a point nearer to the shape's plane than this times
 * the square root of its area (the corners' planes through the point
 * degenerate there). */
#define SPHERICAL_MIN_HEIGHT 1e-3f

/** A rectangle seen from a point, ready to sample. */
typedef struct {
    float x0, x1, y0, y1, z0;  /**< the rectangle in the frame of its edges at the point: [x0,x1] x [y0,y1] at
                                    height z0 < 0 (the frame's third axis points away from it) */
    float ex, ey;              /**< the edges' lengths */
    float b0, b1, k;           /**< the parametrisation's constants (z of two planes' normals, 2 pi less two
                                    angles) */
    float solid;               /**< the solid angle, steradians */
} spherical_rect;

/** Sets *r up for the rectangle origin + s eu + t ev (s, t in [0, 1]) seen
 * from `from`; returns 1, or 0 (r unset) where sampling by area should be
 * used instead (see above; also edges whose cosine exceeds 1e-5). */
int spherical_rect_setup(vec3 from, vec3 origin, vec3 eu, vec3 ev, spherical_rect *r);

/** The point of the rectangle in direction uniform in its solid angle,
 * from (u1, u2) in [0, 1)^2, as its edge coordinates (s, t) in [0, 1]. */
void spherical_rect_sample(const spherical_rect *r, float u1, float u2, float *s, float *t);

/** A triangle seen from a point, ready to sample (in double precision,
 * which Arvo's construction needs for slivers and small triangles). */
typedef struct {
    double v[3][3];            /**< unit directions to its vertices a, b, c */
    double e[3][3];            /**< the cross products of the vertices less the point, b x c, c x a, a x b,
                                    oriented so that their dot products with a direction inside are positive */
    double sin_alpha, cos_alpha; /**< of the spherical triangle's angle at a */
    double omc_ab;             /**< 1 - a . b */
    double c_perp[3];          /**< unit, in the plane of a and c, orthogonal to a, on c's side */
    float solid;               /**< the solid angle, steradians */
} spherical_tri;

/** Sets *t up for the triangle p0 p1 p2 seen from `from`; returns 1, or 0
 * where sampling by area should be used instead. */
int spherical_tri_setup(vec3 from, vec3 p0, vec3 p1, vec3 p2, spherical_tri *t);

/** The point of the triangle in direction uniform in its solid angle, from
 * (u1, u2) in [0, 1)^2, as its barycentrics (b1, b2) of p1 and p2 (the
 * coordinates trace_surface takes), each in [0, 1] with sum at most 1. */
void spherical_tri_sample(const spherical_tri *t, float u1, float u2, float *b1, float *b2);

#endif
