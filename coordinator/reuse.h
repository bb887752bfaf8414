/** @file reuse.h
 * The frames of an animation compiled and sent as what changed since the
 * frame before.
 *
 * Compile once: a frame is first compiled as a skeleton (compile.h: a
 * JSON scene's meshes left out and their files not read, only a key of
 * what they would read, mesh.h's mesh_key; a glTF scene's meshes each a
 * stand-in triangle, keyed by what places and shapes them and by the
 * file's identity on disk: scene_hooks.h; for one animated file, also
 * the keys of skeletons posed half a frame before and after, the most a
 * shutter is open).  When the key is the one of
 * the frame before, the frame's scene is the last full compile with the
 * sections that differ between the two skeletons replaced by this
 * skeleton's, provided each of those sections was, in the frame before,
 * the same in the skeleton as in the full scene (the meshes added nothing
 * to it: the camera, the settings, the camera's motion).  When instead
 * only the instances of meshes moved (a rigid object placed by keyed
 * instances), the frame is made of the frame before's mesh sections and
 * the rest of a skeleton given those meshes' bounds (reuse_placed.h),
 * keyed by the meshes' content alone; a glTF mesh placed by instances
 * (drawn by several nodes, or moving across the shutter) is such a mesh,
 * keyed by the file's identity, its node and whether it moves
 * (scene_hooks.h's mesh_bounds; without the skeletons half a frame
 * around, as that skeleton reads every other mesh whole).  Anything else (a mesh that moves
 * itself, a mesh of its file's materials, a glTF mesh flattened into the
 * world's triangles that moves, skinned or morphed, a section the
 * meshes add to: the lights of an emissive mesh) compiles the frame whole, and so does a file that the last full compile
 * read and that changed since (a mesh's MTL file, a texture it names).
 * The result is byte for byte the scene a full
 * compile of the frame makes (tests/it_anim_reuse.sh).  Compiled .fbin
 * frames are taken as they are (reuse_loaded).
 *
 * Send a delta: for every frame after the first, a scene patch (fpatch.h)
 * from the frame before's scene is written into the frame's job directory
 * when it is under a quarter of the scene's size; stage_scene sends it to hosts that
 * hold the frame before's scene (transport/stage.h).
 *
 * One per animation run; the frames are opened one after the other.
 */
#ifndef FRANJA_REUSE_H
#define FRANJA_REUSE_H

#include <signal.h>
#include <stdint.h>

#include "compile/compile.h"
#include "error.h"
#include "scene.h"

/** What the run keeps of the frame before. */
typedef struct {
    fr_scene full;             /**< its scene, mapped (the mapping outlives its job directory) */
    fr_scene skel;             /**< its skeleton (JSON scenes; else empty) */
    uint64_t key;              /**< its meshes' key */
    fr_scene placed;           /**< its skeleton with its meshes' bounds (a scene with instanced meshes;
                                    else empty): reuse_placed.h */
    uint64_t placed_key;       /**< that skeleton's key (the meshes' content, without their instances) */
    float *bounds;             /**< its meshes' object-space vertex bounds, 6 floats each, or NULL */
    uint32_t n_bounds;
    char *files;               /**< the files its last full compile read (compile_child.h's list), or NULL */
    int have;                  /**< 1 once a frame was compiled */
    int reused;                /**< frames made from the frame before's sections (for the log) */
} reuse_state;

/** What reuse_compile did for one frame. */
typedef struct {
    int reused;                /**< 1: made from the frame before's sections (no full compile) */
    double seconds;            /**< the compile's time, skeleton included */
    uint64_t base;             /**< the patch's base scene hash (the frame before's); 0: no patch */
    uint64_t patch_bytes;      /**< the patch's size */
} reuse_result;

/** Compiles the frame `scene` (a JSON or glTF scene) with options co into
 * the .fbin file `out` as described above; writes `patch` (a path) when a
 * patch from the frame before is worth sending (r->base not 0), else
 * removes it.  stop as compile_child's.  Returns 0, or -1 with err (the
 * compiler's, or a write error). */
int reuse_compile(reuse_state *st, const char *scene, const compile_opts *co, const char *out, const char *patch,
                  volatile sig_atomic_t *stop, reuse_result *r, fr_error *err);

/** A frame given as a compiled scene (`path`, an .fbin): a patch to it
 * from the frame before's scene written to `patch` as reuse_compile does
 * (r->base, r->patch_bytes; r->seconds 0), and the scene kept for the next
 * frame.  Returns 0, or -1 with err (a scene that does not load, a write
 * error). */
int reuse_loaded(reuse_state *st, const char *path, const char *patch, reuse_result *r, fr_error *err);

/** Lets go of what st keeps. */
void reuse_free(reuse_state *st);

#endif
