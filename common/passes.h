/** @file passes.h
 * Render passes: images of a render's parts beside the beauty, for
 * denoisers and compositors, computed by the path integrator with the
 * samples of the beauty (pathtrace.h) and carried in partial images
 * (image.h).
 *
 * The passes, in their fixed order (a set of them is a bit mask, bit i for
 * pass i; a pixel's pass values are the channels of the passes in the set,
 * in this order):
 * - albedo (RGB): the reflectance of the first surface that is not a
 *   perfect mirror or smooth glass, times the colour of the perfect
 *   mirrors and glass the path went through to reach it, as Cycles'
 *   denoising data has it; in [0, 1].  A material's reflectance is the sum
 *   of its lobe colours (capped at 1), a conductor's specular colour, a
 *   rough dielectric's tint or a principled material's base colour.
 *   0 where the path escapes, ends, or enters a medium first.
 * - normal (XYZ): that surface's shading normal, world space, unit, on
 *   the side the path arrived from (its dot product with the ray that
 *   found it is negative).  Averaged over the pixel's samples, so shorter
 *   than 1 where a pixel sees several surfaces; 0 where albedo is 0.
 * - depth (Z): the distance from the camera (the ray's origin on the
 *   lens) to the first thing the camera ray hits, scene units; 1e10 where
 *   it hits nothing (Blender's value).  Sample 0 of the pixel only, not
 *   averaged (as Cycles' Z pass).
 * - position (XYZ): the world position of that first hit, sample 0; 0
 *   where nothing is hit.
 * - emission (RGB): light seen directly: emitters and distant lights (the
 *   environment, sun disks) the camera ray meets before any scattering.
 * - diffuse_direct, diffuse_indirect, glossy_direct, glossy_indirect,
 *   transmission_direct, transmission_indirect (RGB): the rest of the
 *   light, split by the first scattering vertex.  Direct: light that
 *   reaches the camera after one scattering (light sampled there, or an
 *   emitter hit by the ray leaving it); indirect: after two or more.  The
 *   kind is that of the first vertex's scattering: for a sampled
 *   direction, the lobe sampled (Lambert: diffuse; Phong, mirror,
 *   conductor, the reflection of glass and rough dielectrics: glossy;
 *   refraction through the surface: transmission; principled materials
 *   reflect as glossy); for light sampling at a lobe material, the
 *   Lambert lobe's share of the BSDF toward the light is diffuse and the
 *   rest glossy (transmission when the light is behind the surface).  A
 *   first scattering in a medium counts as diffuse.  The emission pass
 *   and these six sum to the beauty (within float rounding).
 * - material_id (X): 1 + the index of the material first hit (sample 0),
 *   the order of the scene's materials; 0 where nothing is hit.
 * - crypto_material (12 channels): the Cryptomatte ranking of the
 *   materials first hit: PASS_CRYPTO_RANKS pairs (id, coverage), the
 *   materials by the share of the pixel's samples that hit them first
 *   (most first; equal shares by id), id 1 + the material's index (0:
 *   nothing hit, and unused ranks (0, 0)).  The coordinator turns ids into
 *   the hashes of the materials' names (Cryptomatte's uint32_to_float32).
 *   At most PASS_CRYPTO_SLOTS materials a pixel are counted; the
 *   coverages of a pixel then sum to 1 when it sees at most
 *   PASS_CRYPTO_RANKS of them.
 * - variance (RGB): the variance of the pixel's mean, per channel: the
 *   unbiased sample variance of its samples (as the image has them, a
 *   dropped sample as 0) over their number; 0 for a single sample.  What
 *   a denoiser or the adaptive sampler's user weighs the pixel by.
 *
 * - object_id (X): 1 + the index of the object first hit (sample 0), in
 *   the order of the scene's object_names (a JSON shape, a glTF node with
 *   a mesh; an instance is its placing shape's or node's object); 0 where
 *   nothing is hit or the scene has no objects.
 * - crypto_object (12 channels): the Cryptomatte ranking of the objects
 *   first hit, as crypto_material's (ids 1 + the object's index).
 * - light_groups (PASS_LIGHT_GROUPS x RGB): the beauty split by the light
 *   group of the light it came from (the scene's group_names, group 0
 *   "default": lights without a group, and every light of a scene that
 *   names none; groups past the scene's are 0).  An emitter hit by a ray
 *   (the camera's or a scattered one) gives its own group, next-event
 *   estimation the group of the light sampled, the environment and suns
 *   seen by an escaping ray theirs; light that media scatter toward a ray
 *   by equiangular sampling (vertex.h) goes to group 0.  The groups sum
 *   to the beauty (within float rounding).
 * - shadow (RGB): how much of the direct light at the first hit is not
 *   shadowed, per channel: the sum over the pixel's samples of the light
 *   that next-event estimation at the camera ray's first surface brings
 *   (shadow rays tested), over the sum of what it would bring with every
 *   shadow ray unblocked (and no medium's attenuation); 1 fully lit, 0
 *   fully in shadow, 1 where no light could reach (Cycles' Shadow pass,
 *   one light sample a vertex).
 *
 * Every value is finite.  Light passes and albedo are means over the
 * pixel's samples like the beauty, so any split of rows gives the same
 * bits.
 */
#ifndef FRANJA_PASSES_H
#define FRANJA_PASSES_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "scene.h"
#include "trace.h"

/** The passes, in channel order. */
enum {
    PASS_ALBEDO = 0,
    PASS_NORMAL,
    PASS_DEPTH,
    PASS_POSITION,
    PASS_EMISSION,
    PASS_DIFFUSE_DIRECT,
    PASS_DIFFUSE_INDIRECT,
    PASS_GLOSSY_DIRECT,
    PASS_GLOSSY_INDIRECT,
    PASS_TRANSMISSION_DIRECT,
    PASS_TRANSMISSION_INDIRECT,
    PASS_MATERIAL_ID,
    PASS_CRYPTO_MATERIAL,
    PASS_VARIANCE,
    PASS_OBJECT_ID,
    PASS_CRYPTO_OBJECT,
    PASS_LIGHTGROUP,
    PASS_SHADOW,
    PASS_COUNT
};

/** Every pass's bit. */
#define PASS_ALL ((1u << PASS_COUNT) - 1u)

/** Most channels a pixel's passes have (all of them). */
#define PASS_MAX_CHANNELS 87

/** Light groups a scene may have (the default one included). */
#define PASS_LIGHT_GROUPS 8

/** Ranks of the Cryptomatte pass (each an id and its coverage). */
#define PASS_CRYPTO_RANKS 6

/** Materials a pixel's Cryptomatte pass tells apart; a sample on a
 * further one is not counted. */
#define PASS_CRYPTO_SLOTS 16

/** Most doubles pass_accumulate keeps for a pixel (all the passes). */
#define PASS_MAX_ACC (PASS_MAX_CHANNELS - 4 * PASS_CRYPTO_RANKS + 4 * PASS_CRYPTO_SLOTS + 3 + 3)

/** Depth where the camera ray hits nothing. */
#define PASS_DEPTH_NONE 1e10f

/** A pass: its name in --passes, its layer name in a multilayer OpenEXR
 * (Blender's: ViewLayer.LAYER.CHANNEL) and its channel names, one
 * letter each ("RGB", "XYZ", "Z", "X"). */
typedef struct {
    const char *name, *layer, *channels;
} pass_info;

/** Pass i (0 <= i < PASS_COUNT). */
const pass_info *pass_get(int i);

/** Channels of the passes in mask. */
uint32_t pass_channels(uint32_t mask);

/** Parses a comma-separated list of pass names, or "all", "light" (emission
 * and the six light passes), "denoise" (albedo and normal) or "none", into
 * *mask.  Fails naming the unknown word and the known ones. */
int pass_parse(const char *list, uint32_t *mask, fr_error *err);

/** The names of the passes in mask, comma-separated, into out[cap]
 * ("none" for 0); what pass_parse reads back. */
void pass_format(uint32_t mask, char *out, size_t cap);

/** What one sample brings to the passes (pathtrace.c fills it). */
typedef struct {
    vec3 albedo, normal;       /**< at the first surface that is not a delta-only one */
    vec3 albedo_beta;          /**< the colour of the delta bounces before it */
    int albedo_done;           /**< albedo and normal are found (or never will be) */
    float depth;
    vec3 position;
    uint32_t material;         /**< 1 + index, 0: none */
    uint32_t object;           /**< 1 + index into object_names, 0: none */
    int kind;                  /**< the first scattering's kind: 0 diffuse, 1 glossy, 2 transmission; -1 none yet */
    vec3 light[7];             /**< emission, then diffuse, glossy, transmission each direct and indirect */
    vec3 beauty;               /**< the sample's radiance, as the image adds it (variance) */
    vec3 group[PASS_LIGHT_GROUPS]; /**< the radiance by light group */
    vec3 lit, unshadowed;      /**< direct light at the first surface, and the same with no shadow (shadow) */
} pass_sample;

/** A sample's passes before its camera ray is traced. */
void pass_start(pass_sample *p);

/** The camera ray's first hit: point `at`, material index (FR_NONE: a
 * point in a medium), object (1 + index, 0: none; pass_object), the
 * ray's origin `from`. */
void pass_first_hit(pass_sample *p, vec3 at, uint32_t material, uint32_t object, vec3 from);

/** The object of surface sf (1 + its index into s->object_names), 0 when
 * the scene has no objects. */
uint32_t pass_object(const fr_scene *s, const fr_surface *sf);

/** Light L that reaches the camera after `bounces` scatterings (0: seen
 * directly): to emission, or to the direct or indirect pass of the first
 * scattering's kind (diffuse when none was set). */
void pass_light(pass_sample *p, uint32_t bounces, vec3 L);

/** Light L from light `light` (an index into s->lights; FR_NONE: group
 * 0) to its light group. */
void pass_group(pass_sample *p, const fr_scene *s, uint32_t light, vec3 L);

/** Light L from light sampling at the first scattering vertex (surface sf
 * of material m, seen along wo, the light along wi): split between the
 * direct passes as passes.h says. */
void pass_light_first(pass_sample *p, const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, vec3 L);

/** The first scattering's kind, from its sampled direction wi at surface
 * sf (seen along wo) of material m, with lobe number ulobe; a medium
 * vertex has sf NULL. */
void pass_first_kind(pass_sample *p, const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, float ulobe);

/** At a surface vertex reached along ray direction d, before albedo is
 * found: records albedo and normal there unless m has delta lobes only
 * (then pass_albedo_through follows its sampled bounce). */
void pass_albedo_at(pass_sample *p, const fr_material *m, const fr_surface *sf, vec3 d);

/** Next-event estimation at the first surface: L what it brought (0 when
 * shadowed), free what it would bring unshadowed (the shadow pass). */
void pass_shadow(pass_sample *p, vec3 L, vec3 free);

/** Albedo search goes on through a delta bounce of weight w. */
void pass_albedo_through(pass_sample *p, vec3 w);

/** Whether a sample whose light came out non-finite drops its light too:
 * zeroes the light passes (the beauty drops such samples). */
void pass_drop_light(pass_sample *p);

/** Adds sample `index` of a pixel to acc (pass_channels(mask) doubles,
 * zeroed by the caller before sample 0): means for the averaged passes,
 * sample 0's value for depth, position and material_id. */
void pass_accumulate(double *acc, uint32_t mask, const pass_sample *p, uint32_t index);

/** The pixel's pass values from acc after n samples into out
 * (pass_channels(mask) floats). */
void pass_finish(const double *acc, uint32_t mask, uint32_t n, float *out);

#endif
