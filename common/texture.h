/** @file texture.h
 * Looking up textures, and applying them to a material at a
 * surface point (colours, bump maps, normal maps).
 *
 * Textures live in the scene (scene.h: fr_texture, texels): images are
 * stored at their own precision (8-bit sRGB or linear, 16-bit, half or
 * float; one or three values per texel, top row first) with their mip
 * levels; a checkerboard is computed.  A lookup maps the surface's UV
 * through the texture's scale and offset, wraps (repeat) or clamps, and
 * filters bilinearly or takes the nearest texel.  Stored values are
 * decoded exactly: bytes through a table, integers by one division, halves
 * by moving bits.  Everything is + - * / sqrt, floor and fmath.h, so
 * lookups give the same bits everywhere (invariant 2).
 *
 * Mip levels: a surface whose footprint (fr_surface.footprint, the width
 * of the ray's cone there) spans f > 1 level-0 texels reads level
 * log2(f), trilinearly (bilinear in the two nearest levels, blended); a
 * footprint under a texel, or none (0), reads level 0 bilinearly as
 * before mip-maps.  Nearest-filtered textures, bump and normal maps, the
 * emission texture and the environment map always read level 0.
 */
#ifndef FRANJA_TEXTURE_H
#define FRANJA_TEXTURE_H

#include "trace.h"

/** RGB value of texture `t` (a valid index) at surface coordinates uv, at
 * level 0; a one-channel texture gives its value in all three. */
vec3 tex_eval(const fr_scene *s, uint32_t t, vec2 uv);

/** RGB value of texture `t` at uv read bilinearly from mip level `level`
 * (the last level past it), whatever t's filter; a checker's colour.  For
 * means over a region at compile time (freeze_light.c): a level whose
 * texels are a fraction of the region's size smooths it no more than that. */
vec3 tex_eval_level(const fr_scene *s, uint32_t t, vec2 uv, uint32_t level);

/** The level of detail at which texture t is looked up at surface *sf:
 * log2 of the number of level-0 texels that its footprint spans, measured
 * isotropically (footprint times the square root of texels per unit of
 * surface area, from |dpdu x dpdv| and the texture's size and scale);
 * 0 when that is under one texel, for a checker, or without a footprint. */
float tex_lod(const fr_scene *s, uint32_t t, const fr_surface *sf);

/** Decoded linear value of texel (x, y) (in range) of mip level `level`
 * of image texture t, whose words are `texels`: out[0..t->channels). */
void tex_texel(const uint32_t *texels, const fr_texture *t, uint32_t level, uint32_t x, uint32_t y, float out[3]);

/** tex_texel of four texels at once: texel i[k] (row-major index, in
 * range) of level `level` into out[k][0..t->channels), k = 0..3. */
void tex_texels4(const uint32_t *texels, const fr_texture *t, uint32_t level, const size_t i[4], float out[4][3]);

/** Width and height of mip level `level` of t: max(1, size >> level). */
void tex_level_size(const fr_texture *t, uint32_t level, uint32_t *w, uint32_t *h);

/** Bytes of one value of a texel format (FR_TEXEL_*). */
uint32_t tex_format_bytes(uint32_t format);

/** An IEEE 754 binary16 (bits h) as a float, exactly, by moving bits. */
float tex_half_to_float(uint16_t h);

/** 1 if material m has any texture, bump or normal map. */
int tex_material_textured(const fr_material *m);

/** The material as it is at surface point *sf (its colour and scalar
 * textures at the level of detail of sf->footprint, tex_lod): when m has no texture,
 * returns m unchanged; otherwise copies it into *tmp, replaces each
 * textured colour by tint * texture (reflectances clamped to [0, 1],
 * emission to >= 0), a textured roughness (metallic) by the factor times
 * the texture's G (B) channel, clamped to [0, 1], recomputes the lobe
 * probabilities and returns tmp.
 * Bump and normal maps tilt sf->ns (the shading normal only: sf->ng, which
 * decides on which side of the surface a path is, is left alone, and ns is
 * kept in ng's hemisphere). */
const fr_material *tex_material(const fr_scene *s, const fr_material *m, fr_surface *sf, fr_material *tmp);

/** Emitted radiance of material m at uv, before the side test: m->emission,
 * times its emission texture if it has one. */
vec3 tex_emission(const fr_scene *s, const fr_material *m, vec2 uv);

/** The sRGB transfer curve inverted: an encoded value in [0, 1] to linear. */
float tex_srgb_to_linear(float v);

#endif
