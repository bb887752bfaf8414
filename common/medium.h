/** @file medium.h
 * Homogeneous participating media: transmittance, the
 * Henyey-Greenstein phase function, free-flight (distance) sampling,
 * equiangular sampling toward a point (Kulla and Fajardo 2012, "Importance
 * sampling techniques for path tracing in participating media"), and
 * shadow rays through the invisible boundaries of media.
 *
 * A medium is named by 1 + its index into s->media; 0 is vacuum.  A shape
 * whose material has an interior medium bounds it: a ray that crosses the
 * shape's surface against its geometric normal enters the medium, one that
 * crosses along it returns to the fog (s->volume.fog).  Directions are
 * propagation directions: d is where the light travels before scattering,
 * wi after it.  Everything here uses fmath.h, never libm transcendentals.
 */
#ifndef FRANJA_MEDIUM_H
#define FRANJA_MEDIUM_H

#include "trace.h"

/** e^(-sigma_t d) per channel; d may be INFINITY (then 0 where sigma_t > 0). */
vec3 med_transmittance(const fr_medium *m, float d);

/** Henyey-Greenstein phase function for the cosine between d and wi, per
 * steradian: integrates to 1 over the sphere; g = 0 is isotropic. */
float med_phase(float g, float cos_theta);

/** A direction wi around unit d whose density is med_phase(g, dot(d, wi)). */
vec3 med_sample_phase(float g, vec3 d, float u1, float u2);

/** Free-flight sampling along a segment of length tmax (INFINITY if the ray
 * leaves the scene), for a path of throughput beta: a colour channel is
 * picked by uch with probability proportional to beta (uniformly if beta
 * is 0), a distance by u from that channel's exponential.  The density is
 * the mixture over channels (single-sample MIS with the balance heuristic,
 * so chromatic media stay unbiased; weighting by throughput keeps the sum
 * of beta's channels from drifting over many scatterings).  Returns 1 and
 * *t < tmax if the path scatters there, with *weight = Tr(t) sigma_s /
 * pdf(t); 0 if it reaches the segment's end, with *weight = Tr(tmax) /
 * P(reach).  A medium that does not scatter (sigma_s = 0) never scatters:
 * *weight is then the exact Tr(tmax). */
int med_sample_distance(const fr_medium *m, float tmax, vec3 beta, float uch, float u, float *t, vec3 *weight);

/** The density with which med_sample_distance scatters at t (< tmax). */
float med_distance_pdf(const fr_medium *m, vec3 beta, float t);

/** Equiangular sampling of t in [0, tmax) on the ray o + t d (d unit) for
 * light from point c: density proportional to 1 / |c - x(t)|^2.  Returns 0
 * when the ray passes through c (degenerate) or the sample falls outside. */
int med_equiangular(vec3 o, vec3 d, float tmax, vec3 c, float u, float *t, float *pdf);

/** The density of med_equiangular at t. */
float med_equiangular_pdf(vec3 o, vec3 d, float tmax, vec3 c, float t);

/** The medium a ray leaving a surface (material m, geometric normal ng)
 * along dir travels in, if it was in `current` before. */
uint32_t med_after(const fr_scene *s, uint32_t current, const fr_material *m, vec3 ng, vec3 dir);

/** Transmittance from r->o along unit r->d over distance tmax, starting in
 * `medium`: crosses interface surfaces (media boundaries), multiplies the
 * transmittance of every medium on the way, and is 0 if any other surface
 * than primitive `skip` (the light aimed at, or FR_NONE) is in the way. */
vec3 med_shadow(const fr_scene *s, uint32_t medium, const fr_ray *r, float tmax, uint32_t skip);

#endif
