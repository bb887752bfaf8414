/** @file gltf_mat.h
 * glTF 2.0 materials, textures, samplers and images as Franja materials
 * and textures (the mapping is documented in scenes/README.md).
 *
 * A glTF material is read whole into gmat_values (every factor, texture
 * and extension this reader knows), then mapped onto an fr_material by
 * gmat_to_franja.  Images are decoded through the caller's hooks
 * (scene_hooks.h) once per colour space and shared by the textures that
 * use them; base colour and emission textures are sRGB-decoded, normal
 * and metallic-roughness textures are data and stay linear.  glTF's UV
 * origin is the image's top-left corner; Franja's v grows upward (scene.h),
 * so the importer flips v on the vertices and the texture transform here
 * is written for the flipped coordinates.
 *
 * Errors name the file and JSON pointer (gltf_doc.h); features that are
 * ignored become warnings, once each.  Compile time only.
 */
#ifndef FRANJA_GLTF_MAT_H
#define FRANJA_GLTF_MAT_H

#include "compile/builder.h"
#include "compile/gltf_doc.h"
#include "compile/scene_hooks.h"

/** A glTF texture reference resolved into a Franja texture: index into the
 * builder's textures, or FR_NONE. */
typedef struct {
    uint32_t tex;
} gmat_texref;

/** Everything read from one glTF material (its defaults when absent). */
typedef struct {
    vec3 base;                 /**< baseColorFactor's RGB, in [0, 1] */
    float alpha;               /**< baseColorFactor's alpha (not rendered) */
    float metallic, roughness; /**< factors, in [0, 1] */
    vec3 emissive;             /**< emissiveFactor times KHR_materials_emissive_strength */
    float normal_scale;        /**< normalTexture.scale */
    float transmission;        /**< KHR_materials_transmission factor, in [0, 1] */
    float ior;                 /**< KHR_materials_ior (1.5 by default) */
    int double_sided;
    gmat_texref t_base, t_metal_rough, t_normal, t_emissive, t_transmission;
} gmat_values;

/** The material state of one import. */
typedef struct {
    gltf_doc *doc;
    const scene_hooks *hooks;
    fr_builder *b;
    uint32_t *mat_of;          /**< builder material per glTF material (last: the default), FR_NONE until made */
    fr_texture *img[2];        /**< decoded images' fields, [linear, sRGB] per image */
    uint8_t *img_done[2];
    double (*uvxf)[6];         /**< per material slot: the UV transform its vertices take (see gmat_material) */
    uint8_t *has_uvxf;
    int xf_seen, xf_mixed, xf_rot; /**< while a material is read, its textures' KHR_texture_transform: one
                                        seen; two different ones; one with a rotation */
    double xf[5];              /**< the first seen: offset u, v, scale u, v, rotation (glTF's UV space) */
} gmat_ctx;

/** Prepares the conversion of d's materials into b.  Returns 0, or -1 when
 * memory runs out. */
int gmat_begin(gmat_ctx *c, gltf_doc *d, const scene_hooks *hooks, fr_builder *b, fr_error *err);
void gmat_end(gmat_ctx *c);

/** The builder material for glTF material `index` (UINT32_MAX: glTF's
 * default material), converting it on first use.  When the material's
 * textures share one KHR_texture_transform with a rotation (which Franja's
 * textures cannot express), the textures are left untransformed and *uvxf
 * receives the row-major 2x3 matrix to apply to the vertices' glTF UVs
 * instead (before v is flipped); otherwise *uvxf is NULL. */
int gmat_material(gmat_ctx *c, uint32_t index, uint32_t *out, const double **uvxf, fr_error *err);

#endif
