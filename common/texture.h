/** @file texture.h
 * Looking up textures, and applying them to a material at a
 * surface point (colours, bump maps, normal maps).
 *
 * Textures live in the scene (scene.h: fr_texture, texels): images hold
 * decoded linear floats, one or three per texel, top row first; a
 * checkerboard is computed.  A lookup maps the surface's UV through the
 * texture's scale and offset, wraps (repeat) or clamps, and filters
 * bilinearly or takes the nearest texel.  Everything is + - * / sqrt and
 * floor, so lookups give the same bits everywhere (invariant 2).
 */
#ifndef FRANJA_TEXTURE_H
#define FRANJA_TEXTURE_H

#include "trace.h"

/** RGB value of texture `t` (a valid index) at surface coordinates uv; a
 * one-channel texture gives its value in all three. */
vec3 tex_eval(const fr_scene *s, uint32_t t, vec2 uv);

/** 1 if material m has any texture, bump or normal map. */
int tex_material_textured(const fr_material *m);

/** The material as it is at surface point *sf: when m has no texture,
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
