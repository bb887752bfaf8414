/** @file json_light.h
 * The lights part of the JSON scene format: the "lights" array (point,
 * spot and sun lights) and the "environment" object (documented in
 * scenes/README.md).  json_scene.c calls these while it reads a scene;
 * they check every field and add the lights through builder_light.h.
 *
 * Errors follow the scene reader's style: the JSON path and what was
 * expected, e.g. `lights[2].outer_angle: expected (0, 180] degrees`.
 */
#ifndef FRANJA_JSON_LIGHT_H
#define FRANJA_JSON_LIGHT_H

#include <cjson/cJSON.h>

#include "compile/json_appear.h"

/** The top-level "lights" array (absent: no lights), into a->b. */
int json_lights(json_appear *a, const cJSON *lights, fr_error *err);

/** The top-level "environment" object (absent: none), into a->b; an
 * environment map is a texture of the "textures" object, decoded here. */
int json_environment(json_appear *a, const cJSON *env, fr_error *err);

#endif
