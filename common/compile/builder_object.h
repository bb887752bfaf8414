/** @file builder_object.h
 * Objects at compile time: named groups of a scene's geometry, for the
 * object_id and crypto_object render passes (common/passes.h).
 *
 * A reader calls bld_object() before adding an object's shapes (a JSON
 * shape, a glTF node with a mesh): the spheres, rects, triangles, planes
 * and instances added from then until the next bld_object() are that
 * object's.  frz_scene() (freeze.h) writes the objects section (each
 * prim's, plane's and instance's object) and the object_names section;
 * a scene whose readers began no object has neither.
 */
#ifndef FRANJA_BUILDER_OBJECT_H
#define FRANJA_BUILDER_OBJECT_H

#include "compile/builder.h"

/** Begin object `name` (cut to 63 bytes as bld_name_set does); the same
 * name as the last object's goes on with that object.  0, or -1 with
 * *err set when memory runs out. */
int bld_object(fr_builder *b, const char *name, fr_error *err);

/** bld_flatten's part: the triangles added from now on are object's
 * (copies of an instance's mesh).  0, or -1 with *err set. */
int bld_object_continue(fr_builder *b, uint32_t object, fr_error *err);

/** bld_flatten's part: records each instance's object in b->inst_objects
 * (before instances are renumbered).  0, or -1 with *err set. */
int bld_object_instances(fr_builder *b, fr_error *err);

/** The objects section of the frozen prims, planes and instances (after
 * the BVH has ordered the prims) into *out (uint32_t, empty when no
 * object was begun).  0, or -1 with *err set. */
int bld_object_table(const fr_builder *b, fr_array *out, fr_error *err);

#endif
