/** @file freeze.h
 * Freezing a builder into a scene, at compile time: the step between the
 * scene readers and the binary scene.
 *
 * It finishes the camera, builds the BVH (bvh_build.h, which reorders the
 * primitives), derives the light table (every primitive with an emissive
 * material becomes an area light of its surface area; each light is picked
 * with probability proportional to its power), serializes the arrays into
 * the binary-scene layout (fbin.h) and opens those bytes, so the result is
 * exactly what loading the written .fbin gives.
 */
#ifndef FRANJA_FREEZE_H
#define FRANJA_FREEZE_H

#include "compile/builder.h"

/** Freeze the builder into *out, which then owns its bytes (release with
 * scn_free).  The builder's arrays stay allocated (free them with
 * bld_free); its prims are left in BVH order, its lights include the
 * area lights and the vertices no triangle uses are gone
 * (bld_drop_unused_vertices).  Returns 0, or -1 with *err set (degenerate camera, memory,
 * non-finite geometry, a scene the binary format refuses). */
int frz_scene(fr_builder *b, fr_scene *out, fr_error *err);

/** As frz_scene, but the bytes go to the file `path` (fbin_write_view:
 * the same bytes, the same hash) instead of memory, and the builder is
 * freed (bld_free) once they are written, before *out maps the file
 * (fbin_load): the compile's peak memory is then the builder's arrays,
 * never those and the scene's bytes at once.  On failure the builder is
 * freed too, and `path` may be left behind (complete, but refused). */
int frz_scene_file(fr_builder *b, const char *path, fr_scene *out, fr_error *err);

#endif
