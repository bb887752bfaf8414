/** @file vertex.h
 * The vertices of a light path, as path-space integrators build them:
 * finding where a ray's path goes next through media (a surface, a
 * scattering point in a medium, or nowhere), next-event estimation at a
 * vertex (a light sample with its pdfs, MIS weight and contribution), and
 * scattering onward from a vertex.
 *
 * pathtrace.c composes these into unidirectional path tracing (pbrt's
 * Li); a bidirectional integrator reuses them for its subpaths and its
 * light-sampling connections.  Random numbers are passed in, or drawn from
 * the caller's sampler in the order documented here, so the caller decides
 * which sampler dimensions each decision consumes: images depend on it
 * (invariant 1).  Directions are propagation directions (medium.h) for
 * rays, and point away from the vertex for wo and wi (bsdf.h).
 */
#ifndef FRANJA_VERTEX_H
#define FRANJA_VERTEX_H

#include "bsdf.h"
#include "light.h"
#include "sampler.h"

/** What vtx_next found. */
enum { VTX_ESCAPED = 0, VTX_SURFACE = 1, VTX_MEDIUM = 2, VTX_LOST = 3 };

/** The next vertex of a path. */
typedef struct {
    int kind;                  /**< VTX_ESCAPED (the ray left the scene along its direction: distant lights),
                                    VTX_SURFACE, VTX_MEDIUM, or VTX_LOST (caught between interfaces: no light) */
    fr_surface sf;             /**< VTX_SURFACE: the surface (never a media interface); uv, dpdu and dpdv
                                    only where its material reads them (textures, anisotropy), else 0 */
    vec3 p;                    /**< VTX_MEDIUM: the scattering point */
    fr_ray seg;                /**< VTX_MEDIUM: the segment scattered on (origin, unit direction) */
    float seg_tmax;            /**< VTX_MEDIUM: the segment's length (INFINITY: no surface behind) */
    float t;                   /**< VTX_MEDIUM: distance along seg to p */
    vec3 seg_beta;             /**< VTX_MEDIUM: the path throughput at the segment's start */
} vtx_vertex;

/** Which estimators next-event estimation is weighed against (multiple
 * importance sampling, power heuristic); a technique not weighed gets
 * weight 1. */
typedef struct {
    int area;                  /**< lights a ray can hit (area lights, sun disks, the environment) against the
                                    vertex's own scattering (BSDF or phase) */
    int equiangular;           /**< lights seen from a medium (point and spot lights, rectangles and triangles):
                                    distance sampling against equiangular */
} vtx_mis;

/** Power heuristic with beta = 2 (Veach 1997): the weight of a sample of
 * density a against a technique of density b; 0 when both are 0. */
float vtx_power_heuristic(float a, float b);

/** Follow *ray, travelling in *medium (1 + index into media, 0: vacuum)
 * with path throughput *beta, to the path's next vertex, into *v; returns
 * v->kind.
 *
 * Without media in the scene: the closest surface, and nothing is drawn
 * from smp.  With media: every segment inside a medium draws three pairs
 * from smp, (colour channel, distance) for free-flight sampling
 * (med_sample_distance), then (light pick, distance) and (the light point)
 * for equiangular sampling; the path scatters on the segment (VTX_MEDIUM)
 * or reaches its end, and *beta takes the segment's weight.  Interface
 * surfaces are crossed (updating *medium and ray->o; at most 64, then the
 * path is lost: VTX_LOST).  When equi_L is not NULL, each medium segment
 * also adds to *equi_L the single-scattering estimate of a light by
 * equiangular sampling (Kulla and Fajardo 2012): a point or spot light, or
 * a point of a rectangle or triangle light chosen first (lgt_fixed_point),
 * the distance then chosen toward it.  It is weighted against the
 * free-flight sampling this walk does (mis: for area lights also against
 * the phase sample that hits the light); vtx_direct_medium and
 * vtx_medium_hit_weight give the complementary weights.  The numbers are
 * drawn either way. */
int vtx_next(const fr_scene *s, fr_sampler *smp, fr_ray *ray, uint32_t *medium, vec3 *beta, vtx_mis mis,
             vec3 *equi_L, vtx_vertex *v);

/** The origin of the rays that leave a surface vertex on one side of its
 * surface (geo_offset depends on a ray's direction only through the side
 * it leaves to), made once for a vertex's shadow ray and scattered ray. */
typedef struct {
    vec3 o;                    /**< geo_offset_side(sf->p, sf->perr, sf->ng, below) */
    int below;                 /**< the side: 1 below ng, 0 above */
} vtx_origin;

/** The origin at surface vertex sf for rays leaving on the side of wo
 * (unit, away from the surface), which the vertex's rays most often take. */
vtx_origin vtx_origin_at(const fr_surface *sf, vec3 wo);

/** Next-event estimation at a vertex: one light sample and what it adds. */
typedef struct {
    fr_light_sample ls;        /**< the light point: direction, distance, radiance, light pdf, delta */
    float scatter_pdf;         /**< solid-angle pdf of the vertex's own scattering toward ls.wi */
    float weight;              /**< MIS weight of the light sample */
    vec3 L;                    /**< beta * f * Tr * Le * weight / ls.pdf, f with |cos| at a surface or the
                                    phase function in a medium (0 when the shadow ray is blocked) */
    vec3 unshadowed;           /**< vtx_direct_surface: L with the shadow ray unblocked and Tr 1 (set even
                                    when it returns 0; 0 when no light was sampled) */
} vtx_direct;

/** Next-event estimation at surface vertex sf, of material m (as textured
 * there), seen along wo, reached through `medium`: samples a point on
 * light `light` (picked from sf->p by lgt_choose with probability pick;
 * FR_NONE: none) with (u1, u2), evaluates the BSDF and traces the shadow ray (through
 * media and their interfaces when the scene has media), leaving from *org
 * (vtx_origin_at) when it is on that side.  Returns 1 with *out filled when the sample brings light,
 * 0 when it brings none (no smooth lobe, no light sample, a zero BSDF, a
 * blocked shadow ray). */
int vtx_direct_surface(const fr_scene *s, const fr_material *m, const fr_surface *sf, vec3 wo, uint32_t medium,
                       vec3 beta, vtx_mis mis, uint32_t light, float pick, float u1, float u2, const vtx_origin *org,
                       vtx_direct *out);

/** Next-event estimation at medium vertex v (in `medium`), as
 * vtx_direct_surface with the phase function for the BSDF.  When
 * mis.equiangular, a light that equiangular sampling covers (vtx_next) is
 * weighted against the equiangular sampling of v's segment as well (and
 * an area light against the phase sample when mis.area).  Returns 1 when a light was sampled (out->L may still
 * be 0: blocked), 0 when none was. */
int vtx_direct_medium(const fr_scene *s, const vtx_vertex *v, uint32_t medium, vec3 beta, vtx_mis mis, uint32_t light,
                      float pick, float u1, float u2, vtx_direct *out);

/** The MIS weight of light from area light `light`, at its point p, that
 * a path found by sampling the phase function at medium vertex v (in
 * `medium`) with solid-angle pdf phase_pdf, where light sampling from v
 * has pdf light_pdf (lgt_pdf) and light_pdf_table with the power table's
 * pick (lgt_pdf_table, which equiangular sampling picks by): against light sampling alone, or with
 * mis.equiangular and a light that equiangular sampling covers, against
 * both light sampling and equiangular sampling of v's segment toward p. */
float vtx_medium_hit_weight(const fr_scene *s, const vtx_vertex *v, uint32_t medium, vtx_mis mis, uint32_t light,
                            vec3 p, float phase_pdf, float light_pdf, float light_pdf_table);

/** Scatter onward from medium vertex v (in `medium`): *next leaves v->p in
 * a direction sampled from the phase function with (u1, u2); *pdf is its
 * solid-angle density.  The throughput does not change (the phase function
 * is sampled exactly). */
void vtx_scatter_medium(const fr_scene *s, const vtx_vertex *v, uint32_t medium, float u1, float u2, fr_ray *next,
                        float *pdf);

/** Scatter onward from surface vertex sf (material m, seen along wo): the
 * BSDF sampled with (ulobe, u1, u2) into *bs, *next leaving the surface on
 * the side bs->wi goes to (from *org, vtx_origin_at, when it is on that
 * side), *medium updated if the path enters or leaves the shape's medium.  Returns 0 when
 * the path ends here (absorbed or a void sample; *next and *medium
 * untouched). */
int vtx_scatter_surface(const fr_scene *s, const fr_material *m, const fr_surface *sf, vec3 wo, float ulobe,
                        float u1, float u2, const vtx_origin *org, fr_bsdf_sample *bs, fr_ray *next, uint32_t *medium);

#endif
