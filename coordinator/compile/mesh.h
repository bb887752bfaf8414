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

/** What mesh_add would read for shape `node` (JSON path `where`, file
 * names relative to `dir`, material `material`), folded into *key (a
 * hash): the shape's JSON as posed, its files' names and their identity
 * on disk (device, inode, size, modification time), and for a shape with
 * levels of detail (chosen by its size on screen) or a material with an
 * interior medium (which may hold the camera) the camera and image size.  Two
 * compiles that fold the same keys read the same meshes (unless a file
 * the mesh file names, such as an MTL, changed by itself).  Fails like
 * mesh_add on a shape without files. */
int mesh_key(const fr_builder *b, const cJSON *node, const char *where, const char *dir, uint32_t material,
             uint64_t *key, fr_error *err);

/** What a skeleton compile (compile.h) adds in place of a mesh shape: a
 * unit sphere at the origin, of a default diffuse material of its own,
 * so that a scene of meshes alone still has a shape.  Fails on memory. */
int mesh_stand_in(fr_builder *b, fr_error *err);

/** What a skeleton compile given the meshes' bounds (compile.h:
 * mesh_bounds) adds in place of a mesh shape with `instances` and a
 * material (not FR_NONE): a mesh of one triangle of that material whose
 * vertices span `box` (lo x y z, hi x y z: the object-space vertex bounds
 * of the mesh a full compile made), placed by the shape's instances as
 * mesh_add places them; so the instances, their bounds and the scene's
 * tree are the full compile's.  Fails on a bad instance (as mesh_add) or
 * on memory. */
int mesh_stand_in_placed(fr_builder *b, const cJSON *node, const char *where, const float box[6],
                         uint32_t material, fr_error *err);

#endif
