/** @file builder_instance.h
 * Meshes placed many times (instancing) at compile time.
 *
 * A reader adds a mesh's triangles to the builder between bld_mesh_begin()
 * and bld_mesh_end(), in the mesh's own (object) space, then places it with
 * bld_instance() as often as it likes: each placement costs one
 * fr_instance and one FR_PRIM_INSTANCE prim, not a copy of the triangles.
 * frz_scene() (freeze.h) builds one BVH per mesh and the scene's BVH over
 * the other prims and the instances (the two levels of scene.h).  A mesh no
 * instance places is dropped; meshes with an emissive material are
 * flattened (bld_flatten), so that every area light is a prim of the world.
 */
#ifndef FRANJA_BUILDER_INSTANCE_H
#define FRANJA_BUILDER_INSTANCE_H

#include "compile/builder.h"

/** Start a mesh: the prims added until bld_mesh_end() are its triangles.
 * Returns its index in b->meshes, or FR_NONE when memory runs out. */
uint32_t bld_mesh_begin(fr_builder *b);
/** End mesh `mesh` (the last one begun): every prim added since
 * bld_mesh_begin must be a triangle. Returns 0, or -1 with *err set. */
int bld_mesh_end(fr_builder *b, uint32_t mesh, fr_error *err);
/** Place `mesh` by the affine transform xf (world = xf * (p, 1), row-major
 * 3x4); its inverse is computed here in double.  Returns 0, or -1 with
 * *err set for a singular or non-finite transform or on memory
 * exhaustion. */
int bld_instance(fr_builder *b, uint32_t mesh, const float xf[3][4], fr_error *err);
/** Replace instances by copies of their mesh's triangles, transformed as
 * the JSON `mesh` shape places a file (vertices by xf, normals by the
 * inverse transpose, two corners swapped where xf mirrors): every instance
 * with `all`, else those of meshes with an emissive material.  Meshes left
 * without instances are dropped with their prims.  Returns 0, or -1 with
 * *err set on memory exhaustion. */
int bld_flatten(fr_builder *b, int all, fr_error *err);
/** World-space bounds of instance i (its mesh's vertex bounds carried
 * through the transform, over the whole shutter when it moves
 * (bld_motion_bounds), widened by a few ulps so that they hold every
 * point the ray test can find). */
void bld_instance_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi);

/** Bounds of the triangles outside meshes and of every instance, in
 * world space (an empty box, lo > hi, when there are none). */
void bld_bounds(const fr_builder *b, vec3 *lo, vec3 *hi);

#endif
