/** @file builder_light.h
 * Adding lights to a scene under construction (compile time): point, spot
 * and sun lights and the environment, as the JSON reader and the glTF
 * importer give them.  Area lights are not added here: a shape with an
 * emissive material becomes one when the scene is frozen (freeze.h).
 *
 * Units are the renderer's (scene.h): radiance in the scene's linear RGB,
 * intensities in radiance x area (W/sr for a scene in metres and W/m^2/sr
 * radiance), irradiance in radiance x steradians (W/m^2).  glTF's
 * KHR_lights_punctual gives candela and lux; divide them by 683 lm/W to
 * get the watts Blender's exporter started from (scenes/README.md).
 *
 * Every function checks its arguments and returns 0, or -1 with *err set
 * (one line, without a location: the caller prefixes the JSON path or the
 * glTF light).  Directions need not be unit length; they must not be zero.
 */
#ifndef FRANJA_BUILDER_LIGHT_H
#define FRANJA_BUILDER_LIGHT_H

#include "compile/builder.h"

/** A point light at `position` sending `intensity` (>= 0 per channel, not
 * all 0) into every direction. */
int bld_point_light(fr_builder *b, vec3 position, vec3 intensity, fr_error *err);

/** A spot light at `position` shining along `direction` with `intensity`
 * on its axis, fading with glTF's smooth falloff between the cone angles
 * `inner` and `outer` (radians from the axis, as glTF's innerConeAngle and
 * outerConeAngle: 0 <= inner < outer <= pi). */
int bld_spot_light(fr_builder *b, vec3 position, vec3 direction, vec3 intensity, float inner, float outer,
                   fr_error *err);

/** A sun: parallel light travelling along `direction` (glTF's and
 * Blender's: the way the light goes, so (0, -1, 0) is a noon sun in a +y-up
 * scene), giving `irradiance` to a surface facing it.  `diameter` is the
 * sun's angular diameter in radians, 0 to pi (Blender's "Angle"); 0 gives
 * sharp shadows, more gives soft ones. */
int bld_sun_light(fr_builder *b, vec3 direction, vec3 irradiance, float diameter, fr_error *err);

/** The environment: constant radiance `color` when texture is FR_NONE,
 * otherwise an equirectangular map (an image texture already in b, without
 * scale or offset) times `color`.  `rotation` (radians) turns the lookup
 * direction about +y, as a Blender Mapping node's Z rotation does (scene.h,
 * fr_world).  At most one per scene. */
int bld_environment(fr_builder *b, vec3 color, uint32_t texture, float rotation, fr_error *err);

#endif
