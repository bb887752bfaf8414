/** @file mesh.h
 * Triangle meshes in a scene: the `mesh` shape of the JSON scene (fields in
 * scenes/README.md), read from files, placed, given a level of detail and
 * added to a builder.
 *
 * OBJ files go through our reader (obj.h, exact file:line errors); any
 * other extension (ply, stl, gltf, glb, dae, fbx, 3ds ...) through Assimp,
 * in a child process with limits (mesh_import.h).
 * MTL (or Assimp) materials become Franja materials as scenes/README.md
 * describes, unless the shape names a material that overrides them all; a
 * usemtl name that no MTL file defines gets the default material, with a
 * warning through the builder's warn hook.
 */
#ifndef FRANJA_MESH_H
#define FRANJA_MESH_H

#include <cjson/cJSON.h>

#include "compile/builder.h"
#include "compile/confine.h"
#include "compile/mesh_data.h"

/** The scene_hooks mesh hook: reads shape `node` (JSON path `where`), with
 * file names relative to `dir` read through `scope` (confine.h), and
 * appends its triangles (and their materials, unless `material` is not
 * FR_NONE) to b.  Errors start with
 * `where` or the mesh file's name and line. */
int mesh_add(fr_builder *b, const cJSON *node, const char *where, const char *dir, const confine *scope,
             uint32_t material, fr_error *err);

#endif
