/** @file json_gltf.h
 * The `gltf` shape of the JSON scene format (scenes/README.md): a glTF 2.0
 * file placed in a JSON scene with its own transform, so that a glTF asset
 * is lit and framed by the JSON scene's settings.
 *
 * The shape's fields: `file` (required), `scale`, `rotate`, `translate` or
 * `matrix` (as a mesh's), `material` (a material of the JSON scene for
 * every triangle; default: the file's materials), `lights` (take the file's
 * punctual lights; default true) and `camera` (true, or a camera's name:
 * the scene's camera is the file's, placed by the transform; allowed only
 * when the JSON scene gives no camera of its own).  Compile time only.
 */
#ifndef FRANJA_JSON_GLTF_H
#define FRANJA_JSON_GLTF_H

#include <cjson/cJSON.h>

#include "compile/builder.h"
#include "compile/scene_hooks.h"

/** Adds gltf shape `o` (at JSON path `where`; file names relative to
 * `dir`, the file and what it names read through `scope`: confine.h) to b, with `material` (FR_NONE: the file's).  `take_camera`: set
 * b->camera from the file as the shape's `camera` field asks.  Errors start
 * with `where` or name the glTF file and JSON pointer. */
int json_gltf_shape(fr_builder *b, const cJSON *o, const char *where, const char *dir, const confine *scope,
                   const scene_hooks *hooks, uint32_t material, int take_camera, fr_error *err);

/** The scene's camera from the first gltf shape of array `shapes` with a
 * `camera` field (read through `scope`, posed at hooks' time when timed),
 * for a JSON scene without "camera".  Returns 0, or -1 when
 * there is none (saying so) or the file's camera cannot be taken. */
int json_gltf_camera(fr_builder *b, const cJSON *shapes, const char *dir, const confine *scope,
                     const scene_hooks *hooks, fr_error *err);

#endif
