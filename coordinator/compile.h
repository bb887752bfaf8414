/** @file compile.h
 * The scene compiler: a JSON scene with its meshes becomes a binary scene
 * (`franja compile`, and `franja render` of a JSON scene).
 *
 * The compiler is the JSON reader (common/scene_json.h) with the mesh hook
 * of mesh.h: meshes are read (OBJ/MTL by our own reader; PLY, STL, glTF and
 * other formats through Assimp), placed, given a level of detail and frozen
 * with the rest into the binary layout of common/FORMAT.md.
 */
#ifndef FRANJA_COMPILE_H
#define FRANJA_COMPILE_H

#include "error.h"
#include "scene.h"

/** Reads the scene `json_path` and every mesh it names, builds the BVH and
 * fills *out (which then owns its blob; release with scn_free).  Returns 0,
 * or -1 with err naming the file and JSON path or line at fault. */
int compile_json(const char *json_path, fr_scene *out, fr_error *err);

#endif
