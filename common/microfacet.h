/** @file microfacet.h
 * Rough surfaces: the GGX (Trowbridge-Reitz) microfacet model and the
 * conductor, dielectric and glTF metallic-roughness lobes built on it, with
 * the Fresnel factors and the cosine-weighted hemisphere they use (bsdf.c
 * builds its materials from these).
 *
 * Everything works in a local shading frame: z is the shading normal, x and
 * y the tangent directions that anisotropic roughness refers to.  Directions
 * point away from the surface and are unit length: @c wo toward the viewer
 * (the previous path vertex), @c wi toward the light (the next vertex).  The
 * lobes need @c wo.z > 0 (the caller turns the frame to @c wo's side) and
 * return zero otherwise.  Every BSDF value is f(wo, wi) without the cosine;
 * every pdf is per unit solid angle of @c wi.
 *
 * Roughness follows glTF and Blender: alpha = roughness^2 (mf_alpha_iso).
 *
 * Masking-shadowing is Smith's for GGX, in one of two forms (MF_SMITH_*):
 * height-correlated, G2 = 1 / (1 + Lambda(wo) + Lambda(wi)), the default
 * (Heitz 2014; glTF's reference BRDF uses it), or separable,
 * G2 = G1(wo) G1(wi), which is what Cycles 3.4's GGX closures compute.
 *
 * Sampling draws the visible normals of @c wo (Heitz 2018), so a sampled
 * direction's weight is bounded by the masking ratio G2 / G1(wo) <= 1 times
 * the Fresnel factor.
 *
 * Energy compensation (optional, @c compensate): single scattering loses the
 * light that bounces between microfacets: at roughness 1 a white conductor
 * keeps only ~40 % of it.  Following Kulla and Conty (2017), the lost share
 * is 1 - E(mu), where E is the single-scattering directional albedo, and it
 * comes back as further bounces tinted by the average Fresnel factor F_avg;
 * as in Turquin (2019) that energy is given back by scaling the single
 * scattering lobe, f_ss (1 + F_avg (1 - E(mu_o)) / E(mu_o)) for conductors
 * and f_ss / E(mu_o) for dielectrics (E there counts reflection plus
 * transmission), which keeps the lobe's shape and its sampling and brings a
 * white surface's albedo to 1 at every angle.  The price: a compensated
 * lobe depends on mu_o, so it is not exactly reciprocal.  The albedo tables
 * were integrated once by tests/gen/genmftab.c and are compiled in
 * (microfacet_table.c), so they are the same numbers on every host.
 *
 * Everything here uses + - * / and sqrt and the functions of fmath.h only:
 * the same bits on every machine. */
#ifndef FRANJA_MICROFACET_H
#define FRANJA_MICROFACET_H

#include <stdint.h>

#include "vec.h"

/** Smallest alpha used (roughness 0.01): below it the distribution is too
 *  narrow for single precision. */
#define MF_ALPHA_MIN 1e-4f

/** Form of Smith's masking-shadowing term. */
enum {
    MF_SMITH_CORRELATED = 0, /**< height-correlated (default) */
    MF_SMITH_SEPARABLE = 1,  /**< G1(wo) G1(wi), as Cycles 3.4 */
};

/** How a conductor's reflectance depends on the angle. */
enum {
    MF_FRESNEL_SCHLICK = 0,   /**< colour is F0: F = F0 + (1 - F0)(1 - cos)^5 */
    MF_FRESNEL_CONDUCTOR = 1, /**< exact Fresnel of complex index eta + i k, times colour */
    MF_FRESNEL_NONE = 2,      /**< colour at every angle (Cycles' Glossy BSDF, Mitsuba's "none") */
};

/** Where a rough dielectric evaluates its Fresnel factor. */
enum {
    MF_DIELECTRIC_MICRO = 0, /**< per microfacet, F(wo.h) (Walter et al. 2007; default; reciprocal) */
    MF_DIELECTRIC_MACRO = 1, /**< once with the shading normal, F(wo.z), as Cycles 3.4's Glass BSDF */
};

/** Roughness of the distribution along the frame's x and y axes. */
typedef struct { float ax, ay; } mf_alpha;

/** Isotropic alpha = roughness^2, roughness clamped to [0, 1] and alpha to
 *  at least MF_ALPHA_MIN. */
mf_alpha mf_alpha_iso(float roughness);

/** Anisotropic alphas from roughness and anisotropy in [-1, 1] (0:
 *  isotropic; > 0 makes the surface rougher along x, so highlights stretch
 *  along x): ax = alpha / a, ay = alpha * a with a = sqrt(1 - 0.9 |anisotropy|)
 *  (the aspect of Blender's Principled BSDF), both clamped to
 *  [MF_ALPHA_MIN, 1]; negative anisotropy swaps the two. */
mf_alpha mf_alpha_aniso(float roughness, float anisotropy);

/** GGX normal distribution D(m) (per unit solid angle of m, so the integral
 *  of D(m) m.z over the hemisphere is 1); 0 for m.z <= 0. */
float mf_D(mf_alpha a, vec3 m);

/** Smith's Lambda(w) for GGX (uses |w.z|, so it serves both sides); +inf at
 *  w.z = 0. */
float mf_lambda(mf_alpha a, vec3 w);

/** Masking of one direction, G1(w) = 1 / (1 + Lambda(w)). */
float mf_G1(mf_alpha a, vec3 w);

/** Masking-shadowing of the pair, in the form @p masking (MF_SMITH_*).  The
 *  caller checks that each direction is on the right side of the
 *  microfacet normal. */
float mf_G2(mf_alpha a, uint32_t masking, vec3 wo, vec3 wi);

/** A visible normal of @p wo (wo.z > 0), drawn with density mf_pdf_visible
 *  from two uniform numbers in [0, 1) (Heitz 2018). */
vec3 mf_sample_visible(mf_alpha a, vec3 wo, float u1, float u2);

/** Density of visible normals D_wo(m) = G1(wo) max(0, wo.m) D(m) / wo.z. */
float mf_pdf_visible(mf_alpha a, vec3 wo, vec3 m);

/** Schlick's approximation F0 + (1 - F0)(1 - cos)^5 per channel; @p cos_i
 *  clamped to [0, 1]. */
vec3 mf_fresnel_schlick(vec3 f0, float cos_i);

/** Unpolarized Fresnel reflectance of a smooth dielectric boundary for
 *  light arriving at cos_i (> 0) from the side of index 1 onto relative
 *  index @p eta, both polarizations exact.  *cos_t receives the cosine of
 *  the refracted direction, 0 on total internal reflection (F = 1). */
float mf_fresnel_dielectric(float cos_i, float eta, float *cos_t);

/** A direction of the hemisphere around +z with density cos(theta) / pi,
 *  from two uniform numbers (Malley's method). */
vec3 mf_sample_cosine(float u1, float u2);

/** F0 of a dielectric boundary of relative index @p eta:
 *  ((eta - 1) / (eta + 1))^2. */
float mf_f0_from_ior(float eta);

/** Exact unpolarized Fresnel reflectance of a conductor of complex
 *  relative index eta + i k (per channel), lit from a dielectric at
 *  @p cos_i in (0, 1]. */
vec3 mf_fresnel_conductor(float cos_i, vec3 eta, vec3 k);

/** Cosine-weighted hemispherical average of a conductor's Fresnel factor,
 *  F_avg = 2 int_0^1 F(mu) mu dmu (what energy compensation tints with):
 *  closed form for Schlick and none, 64-point midpoint rule for the exact
 *  conductor. */
vec3 mf_fresnel_average(uint32_t fresnel, vec3 color, vec3 eta, vec3 k);

/** Single-scattering directional albedo E(mu) of a GGX reflector with
 *  F = 1, from the compiled tables (bilinear; alpha_eff = sqrt(ax ay)). */
float mf_albedo(mf_alpha a, uint32_t masking, float mu);

/** Directional albedo of a GGX reflector with Schlick's Fresnel of @p f0
 *  (a scalar), and in *avg its cosine-weighted average 2 int E mu dmu:
 *  Schlick's factor is linear in F0, so this is f0 E + (1 - f0) E5 with E5
 *  the albedo under the factor (1 - cos)^5, both tabulated. */
float mf_albedo_schlick(mf_alpha a, uint32_t masking, float f0, float mu, float *avg);

/** Single-scattering albedo (reflection plus transmission, in flux, i.e.
 *  without the 1/eta^2 of radiance) of a rough dielectric boundary with
 *  micro-facet Fresnel, light arriving at mu from the side of index 1 onto
 *  relative index @p eta (> 1 entering, < 1 leaving), from the compiled
 *  tables (trilinear; eta clamped to [1/3, 3]). */
float mf_dielectric_albedo(mf_alpha a, uint32_t masking, float eta, float mu);

/** One sampled direction. */
typedef struct {
    vec3 wi;
    vec3 weight;   /**< f(wo, wi) |wi.z| / pdf */
    float pdf;     /**< solid-angle pdf of wi (the whole lobe mixture) */
} mf_sample;

/** A rough conductor.  Fill every field; mf_conductor_init sets favg. */
typedef struct {
    mf_alpha alpha;
    uint32_t masking;   /**< MF_SMITH_* */
    uint32_t fresnel;   /**< MF_FRESNEL_* */
    vec3 color;         /**< F0 (Schlick), reflectance (none) or tint (exact) */
    vec3 eta, k;        /**< complex index, MF_FRESNEL_CONDUCTOR only */
    int compensate;     /**< 1: multiple-scattering energy compensation */
    vec3 favg;          /**< derived: mf_fresnel_average of the above */
} mf_conductor;

/** Derive c->favg from the Fresnel fields. */
void mf_conductor_init(mf_conductor *c);

/** f(wo, wi) and in *pdf the density with which mf_conductor_sample draws
 *  wi; zero unless both directions are above the surface. */
vec3 mf_conductor_eval(const mf_conductor *c, vec3 wo, vec3 wi, float *pdf);

/** Draw wi by reflecting wo about a visible normal drawn from u1, u2 (@p uc
 *  is unused; it keeps the lobes' signatures alike).  Returns 0 for a void
 *  sample (the reflected direction goes below the surface). */
int mf_conductor_sample(const mf_conductor *c, vec3 wo, float uc, float u1, float u2, mf_sample *s);

/** A rough dielectric boundary.  Its relative index is an argument of each
 *  call: eta = index on the far side (where transmitted light goes) over
 *  the index on wo's side.  Transmitted radiance carries the factor
 *  1/eta^2 (radiance is compressed entering a denser medium), so f obeys
 *  generalized reciprocity: f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2. */
typedef struct {
    mf_alpha alpha;
    uint32_t masking;   /**< MF_SMITH_* */
    uint32_t fresnel_at;/**< MF_DIELECTRIC_* */
    vec3 reflect_tint;  /**< multiplies reflection */
    vec3 transmit_tint; /**< multiplies transmission */
    int compensate;     /**< 1: scale by 1 / E(mu_o) (MF_DIELECTRIC_MICRO only) */
} mf_dielectric;

/** f(wo, wi) (reflection for wi.z > 0, transmission for wi.z < 0) and the
 *  sampling pdf.  Total internal reflection: no transmission. */
vec3 mf_dielectric_eval(const mf_dielectric *d, float eta, vec3 wo, vec3 wi, float *pdf);

/** Draw wi: a visible normal from u1, u2, then reflection or refraction
 *  through it chosen by @p uc with probability F (and 1 - F).  Returns 0
 *  for a void sample. */
int mf_dielectric_sample(const mf_dielectric *d, float eta, vec3 wo, float uc, float u1, float u2,
                         mf_sample *s);

/** How the principled material's specular layer sits over its diffuse
 *  base. */
enum {
    MF_COUPLE_ALBEDO = 0, /**< base times (1 - E_s(mu_o)) (1 - E_s(mu_i)) / (1 - E_s,avg): reciprocal, never gains energy (default) */
    MF_COUPLE_GLTF = 1,   /**< base times 1 - F(wo.h): glTF's fresnel_mix as written; gains energy at grazing angles */
    MF_COUPLE_CYCLES = 2, /**< Cycles 3.4's Principled BSDF (GGX): see mf_principled */
};

/** glTF 2.0's metallic-roughness material: a mix of a conductor (Schlick,
 *  F0 = base colour) with weight metallic and a dielectric with weight
 *  1 - metallic, whose specular layer (GGX, Schlick with F0 from ior) lies
 *  over a Lambert base of the base colour.  glTF writes that layering as
 *  fresnel_mix, which weights the base by 1 - F(wo.h); that formula (kept as
 *  MF_COUPLE_GLTF) reflects more than it receives at grazing angles, so the
 *  default weights the base by what the layer lets through on the way in and
 *  out, with E_s the layer's directional albedo (MF_COUPLE_ALBEDO).
 *  On a base of 0.8 the two albedos agree near normal incidence and part
 *  toward grazing, where glTF's exceeds 1
 *  (tests/bench/README.md, "glTF's fresnel_mix against albedo coupling").
 *  KHR_materials_transmission replaces the share @p transmission of the
 *  dielectric by refraction through a rough dielectric boundary of the
 *  given ior (exact Fresnel, its own reflection untinted and transmission
 *  tinted by the base colour: a closed solid, not glTF's thin-walled
 *  default).  Compensation scales the metal and the refraction.
 *
 *  MF_COUPLE_CYCLES computes what Cycles 3.4's Principled BSDF (GGX, the
 *  Specular input 0.08 F0 of ior, other inputs at their defaults) does:
 *  one specular lobe of weight 1 - transmission (1 - metallic) whose
 *  colour is C (1 - w) + w, C = F0 (1 - metallic) + base metallic, w =
 *  (F(wo.h) - F0) / (1 - F0) with F the exact dielectric Fresnel of ior;
 *  added to it, not weighted by it, a Disney diffuse base of weight
 *  (1 - metallic)(1 - transmission) with retro-reflection, base / pi
 *  ((1 - FV/2)(1 - FL/2) + R (FL + FV + FL FV (R - 1))), F = (1 - mu)^5,
 *  R = roughness (1 + wo.wi); and the refraction with Fresnel once with
 *  the shading normal (MF_DIELECTRIC_MACRO).  Reciprocal, but it may
 *  reflect more than it receives.  @p compensate is ignored. */
typedef struct {
    mf_alpha alpha;
    uint32_t masking;   /**< MF_SMITH_* */
    uint32_t coupling;  /**< MF_COUPLE_* */
    vec3 base;          /**< base colour, linear */
    float metallic;     /**< [0, 1] */
    float transmission; /**< [0, 1], KHR_materials_transmission */
    float ior;          /**< KHR_materials_ior, 1.5 by default */
    int compensate;
    float roughness;    /**< MF_COUPLE_CYCLES: the diffuse's retro-reflection (not alpha) */
} mf_principled;

/** f(wo, wi) and the sampling pdf.  @p eta is the relative index for
 *  refraction (ior entering, 1/ior leaving); the specular layer's F0 uses
 *  ior on either side. */
vec3 mf_principled_eval(const mf_principled *p, float eta, vec3 wo, vec3 wi, float *pdf);

/** Draw wi: @p uc picks the lobe (specular/metal, diffuse, refraction) and
 *  is reused, rescaled, inside it.  Returns 0 for a void sample. */
int mf_principled_sample(const mf_principled *p, float eta, vec3 wo, float uc, float u1, float u2,
                         mf_sample *s);

#endif
