/** @file standin.h
 * A mesh standing for another in a skeleton (coordinator/reuse_placed.h):
 * one triangle whose bounds are the real mesh's, so that the instances
 * placing it, the scene's top-level BVH and the instances' motions come
 * out as those of the real mesh.
 */
#ifndef FRANJA_STANDIN_H
#define FRANJA_STANDIN_H

#include "compile/builder.h"
#include "error.h"

/** Adds to b a mesh (builder_instance.h) of one triangle of `material`
 * with corners (lo), (hi) and (lo x, hi y, hi z) of box (object-space
 * vertex bounds: lo x y z, hi x y z), whose vertex bounds are the box's;
 * its index into *mesh.  Returns 0, or -1 with err (a box that is not
 * finite or is inside out: the bounds of no vertex; out of memory). */
int standin_mesh(fr_builder *b, const float box[6], uint32_t material, uint32_t *mesh, fr_error *err);

#endif
