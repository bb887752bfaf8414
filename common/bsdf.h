/** @file bsdf.h
 * How materials scatter light.
 *
 * Directions point away from the surface: wo toward the viewer (the previous
 * path vertex), wi toward the light or the next vertex.  All unit length.
 * A material is a weighted set of lobes (scene.h): Lambert, normalized Phong,
 * perfect mirror and smooth dielectric; one lobe is picked per sample with
 * the material's lobe probabilities.  Or it is one of the microfacet models
 * of microfacet.h (rough conductor, rough dielectric, glTF
 * metallic-roughness), evaluated in the shading frame: z along the shading
 * normal turned to wo's side, x along dpdu when the roughness is
 * anisotropic.  Their lobes are smooth (not delta), so next-event
 * estimation and MIS treat them like Phong.
 *
 * The shading normal shades; the geometric normal decides sides: a
 * reflected direction must leave on wo's side of the geometric surface and a
 * transmitted one on the other, or the sample is void.  So no light leaks
 * through a surface whatever the shading normal.
 */
#ifndef FRANJA_BSDF_H
#define FRANJA_BSDF_H

#include "trace.h"

/** One sample of a material's BSDF: the direction and how it weighs the path. */
typedef struct {
    vec3 wi;
    vec3 weight;               /**< f * |cos(wi, ns)| / pdf, or the lobe's colour for delta lobes */
    float pdf;                 /**< solid-angle pdf of the smooth lobes; 0 for a delta lobe */
    int delta;                 /**< 1 for mirror and dielectric */
} fr_bsdf_sample;

/** The smooth (non-delta) part of the BSDF f(wo, wi), without the cosine,
 * and in *pdf the solid-angle pdf with which bsdf_sample would pick wi. */
vec3 bsdf_eval(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, float *pdf);

/** The solid-angle pdf with which bsdf_sample, given wo, picks wi (its
 * smooth lobes; 0 for a direction only a delta lobe reaches).  The pdf of
 * the reverse step, wo given wi, is bsdf_pdf(m, sf, wi, wo): bidirectional
 * integrators ask for both. */
float bsdf_pdf(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi);

/** The factor that turns a sample weight or a value of bsdf_eval for the
 * step wo -> wi, which carry radiance (from wi toward wo), into the adjoint
 * BSDF's that carries importance the other way (light subpaths): 1 for a
 * reflection, (n_wi / n_wo)^2 for a transmission (indices of refraction on
 * wi's and wo's side), since radiance is compressed by refraction and
 * importance is not (Veach 1997, section 5.2).  Shading normals need a
 * correction of their own (the caller's: it involves the geometry). */
float bsdf_adjoint_scale(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi);

/** Sample wi given wo from three uniform numbers (lobe choice, direction).
 * Returns 0 when the path ends here (absorbed, or a void sample). */
int bsdf_sample(const fr_material *m, const fr_surface *sf, vec3 wo, float ulobe, float u1, float u2,
                fr_bsdf_sample *out);

/** 1 if bsdf_sample reads its lobe number ulobe: a microfacet model, or a
 * lobe material with two lobes or more.  A material with one lobe (or
 * none) takes any ulobe in [0, 1) alike, so a path need not draw it. */
int bsdf_needs_lobe(const fr_material *m);

/** 1 if the material has a smooth lobe, so light sampling can help. */
int bsdf_has_smooth(const fr_material *m);

/** Set m->p_lobe, the cumulative probabilities with which bsdf_sample picks
 * each lobe, from the lobe colours: in proportion to each lobe's brightest
 * channel; all zero for a material without a lobe (it only emits).  A
 * microfacet model is one smooth lobe: {0, 1, 1, 1}.  Called when textures
 * change a material's colours (bsdf_material_finish calls it too). */
void bsdf_lobe_probs(fr_material *m);

/** Derive what a material's fields imply: p_lobe (bsdf_lobe_probs) and a
 * conductor's average Fresnel factor.  Call once when a material's fields
 * are set. */
void bsdf_material_finish(fr_material *m);

/** Unpolarized Fresnel reflectance of a smooth dielectric boundary for light
 * arriving at cos_i (> 0) from the side of index 1 onto index `eta` (the
 * relative index), both polarizations exact.  *cos_t receives the cosine of
 * the refracted direction, 0 on total internal reflection (F = 1). */
float bsdf_fresnel(float cos_i, float eta, float *cos_t);

/** Local-frame samplers (z up), exposed for the chi-square tests. */
vec3 bsdf_sample_cosine(float u1, float u2);                 /**< pdf cos(theta)/pi */
vec3 bsdf_sample_phong(float exponent, float u1, float u2);  /**< pdf (n+1)/(2 pi) cos^n around +z */

#endif
