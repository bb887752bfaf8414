/** @file reuse_placed.h
 * A frame whose instanced meshes are the frame before's, only placed
 * elsewhere, made of the frame before's mesh sections and the placements
 * of a skeleton that has the meshes' real bounds (reuse.h).
 *
 * The skeleton (compile.h: mesh_bounds) stands each instanced mesh in as
 * one triangle spanning the mesh's object-space vertex bounds, placed by
 * the shape's instances; the instances' bounds, and so the scene's tree,
 * the lights and all but the mesh sections, are then the full compile's.
 * That is not assumed: it is checked on the frame before, whose skeleton
 * and full scene must agree on every section but the meshes' own.
 */
#ifndef FRANJA_REUSE_PLACED_H
#define FRANJA_REUSE_PLACED_H

#include <stdint.h>

#include "error.h"
#include "scene.h"

/** The object-space vertex bounds of s's meshes (section meshes), 6
 * floats each (lo x y z, hi x y z), as the compile's builder computes them
 * (bld_mesh_end) into *bounds (malloc'd, NULL when s has no meshes), their
 * number into *n.  Returns 0, or -1 with err on memory or an index out of
 * range. */
int reuse_placed_bounds(const fr_scene *s, float **bounds, uint32_t *n, fr_error *err);

/** The frame's scene into `out`, made of `full` (the frame before's full
 * scene) and `now` (this frame's skeleton with full's bounds), `was`
 * being the frame before's skeleton with the same bounds: the mesh
 * sections (triangles, positions, normals, uvs, meshes, mesh_nodes,
 * mesh_leaves, and the meshes' prims and object entries) are full's,
 * every other section now's.  Only when was and now have the same mesh
 * sections, and was and full the same other sections (the skeleton made
 * the full compile's scene but for the meshes' content).  The caller
 * makes sure the meshes' content is the same (their keys).  Returns 1
 * when made, 0 when not (the frame needs a full compile), -1 with err on
 * a write error. */
int reuse_placed_splice(const fr_scene *full, const fr_scene *was, const fr_scene *now, const char *out,
                        fr_error *err);

#endif
