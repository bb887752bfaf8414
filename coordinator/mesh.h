/** @file mesh.h
 * Triangle meshes in a scene: the `mesh` shape of the JSON scene (fields in
 * scenes/README.md), read from files, placed, given a level of detail and
 * added to a builder.
 *
 * OBJ files go through our reader (obj.h, exact file:line errors); any
 * other extension (ply, stl, gltf, glb, dae, fbx, 3ds ...) through Assimp,
 * in a child process with limits (mesh_import.h).
 * MTL (or Assimp) materials become Franja materials as scenes/README.md
 * describes, unless the shape names a material that overrides them all.
 */
#ifndef FRANJA_MESH_H
#define FRANJA_MESH_H

#include <cjson/cJSON.h>

#include "builder.h"
#include "obj.h"

/** The scn_hooks mesh hook: reads shape `node` (JSON path `where`), with
 * file names relative to `dir`, and appends its triangles (and their
 * materials, unless `material` is not FR_NONE) to b.  Errors start with
 * `where` or the mesh file's name and line. */
int mesh_add(fr_builder *b, const cJSON *node, const char *where, const char *dir, uint32_t material,
             fr_error *err);

/** Reads a mesh file by its extension: OBJ by obj_read, others by
 * mesh_import into the same structure (free with obj_free).  The file's
 * size, and each MTL file an OBJ names, count against budget's read limit
 * first (NULL: no limit). */
int mesh_read(const char *path, fr_budget *budget, obj_mesh *m, fr_error *err);

#endif
