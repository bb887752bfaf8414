/** @file json_scene.h
 * Reading a scene description (JSON, see scenes/README.md) at compile time.
 *
 * The reader validates everything: a missing field, a wrong type, an
 * unknown field or material name, a negative radius, a zero-area shape, a
 * degenerate camera or a non-finite number is refused with the file, the
 * JSON path (e.g. `shapes[3].radius`) and what was expected.  Shapes,
 * materials, lights, the image and the camera are read here; textures,
 * media, the lens and tone mapping in json_appear.h; meshes and image
 * files through the caller's hooks (scene_hooks.h).
 */
#ifndef FRANJA_JSON_SCENE_H
#define FRANJA_JSON_SCENE_H

#include "compile/builder.h"
#include "compile/scene_hooks.h"

/** Parse the JSON text `text` (from file `file`, used in messages) into b,
 * with `hooks` (may be NULL).  The text must be strict JSON
 * (jsoncheck.h: no duplicate member names, so no two materials of one
 * name, nothing after the scene's closing brace).  Returns 0, or -1 with
 * *err naming the file and the JSON path, or the line and column of a
 * syntax error. */
int json_scene_parse(const char *text, const char *file, const scene_hooks *hooks, fr_builder *b, fr_error *err);

/** Read file `path`, parse it and freeze the scene into *out (freeze.h;
 * *out then owns its bytes: release with scn_free).  Returns 0, or -1 with
 * *err naming the file. */
int json_scene_load(const char *path, const scene_hooks *hooks, fr_scene *out, fr_error *err);

#endif
