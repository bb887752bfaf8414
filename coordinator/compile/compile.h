/** @file compile.h
 * The scene compiler: a JSON scene with its meshes, or a glTF scene, becomes
 * a binary scene (`franja compile`, and `franja render` of such a scene).
 *
 * Every file a scene names is read from the scene file's folder, or one
 * the options allow (common/compile/confine.h).
 *
 * The compiler is the JSON reader (common/compile/json_scene.h) with the mesh hook
 * of mesh.h: meshes are read (OBJ/MTL by our own reader; PLY, STL, glTF and
 * other formats through Assimp), placed, given a level of detail and frozen
 * with the rest into the binary layout of common/FORMAT.md.
 */
#ifndef FRANJA_COMPILE_H
#define FRANJA_COMPILE_H

#include "compile/budget.h"
#include "error.h"
#include "scene.h"

/** How to compile: the glTF camera to take (NULL: the first), where
 * warnings go (NULL: nowhere; `user` is passed back), the folders
 * besides the scene's own that its files may lie in (`--allow-path`;
 * confine.h), the limits (budget.h; NULL: the defaults) and the file the
 * binary scene goes to. */
typedef struct {
    const char *camera;
    void (*warn)(void *user, const char *msg);
    void *user;
    const char *const *allow;
    unsigned n_allow;
    const fr_budget *limits;
    const char *fbin;          /**< where the binary scene is written as it is made (scene_hooks.h); NULL:
                                    in memory only */
    int timed;                 /**< pose animated scenes at `frame` (scene_hooks.h); 0: at rest */
    double frame, fps;         /**< when timed: the frame, and frames per second (0: GANIM_FPS) */
    double shutter;            /**< frames the shutter is open around `frame` (motion blur); 0: none */
    int skeleton;              /**< a JSON scene without its meshes (their files not read): the
                                    sections the rest makes, for frame_reuse.h */
    uint64_t *mesh_key;        /**< when not NULL, receives the meshes' key (mesh.h's mesh_key over
                                    every mesh shape of a JSON scene, in order; 0 without) */
    const char *files;         /**< compile_child only: when not NULL, the file it writes the list of
                                    files the compile read into (compile_child.h) */
    const float *mesh_bounds;  /**< skeleton: NULL, or the object-space vertex bounds (lo x y z, hi x y z)
                                    of the n_mesh_bounds meshes of the full compile the skeleton follows,
                                    by mesh index: a mesh shape with instances and a material (without
                                    an interior medium) whose mesh index has bounds becomes mesh.h's mesh_stand_in_placed, and its
                                    key leaves its instances out (what the mesh's own content reads); a
                                    glTF scene's meshes placed by instances stand so too (scene_hooks.h) */
    uint32_t n_mesh_bounds;
    uint64_t *placed_key;      /**< when not NULL, receives the key the same compile with mesh_bounds
                                    would give a glTF scene (scene_hooks.h's placed_key) */
} compile_opts;

/** Help text for --limit (franja compile and franja render). */
#define COMPILE_LIMIT_HELP                                                                 \
    "  --limit NAME=VALUE   one of the compile's limits (repeatable): read=BYTES\n"        \
    "                       (files read in all), vertices=N and triangles=N (across\n"    \
    "                       all meshes), fbin=BYTES (the binary scene), cpu=SECONDS,\n"   \
    "                       memory=BYTES (address space); K M G T are powers of 1024\n"   \
    "                       (default read=4G, vertices=128M, triangles=128M,\n"          \
    "                       fbin=16G, cpu=1h, memory=32G)\n"

/** 1 when `path` names a glTF scene (.gltf or .glb, any case). */
int compile_is_gltf(const char *path);

/** Compiles the scene `path`: a whole glTF scene (.gltf, .glb;
 * gltf_scene.h) or a JSON scene, within o's limits (read, vertices,
 * triangles, fbin: a scene whose binary form passes the fbin limit is
 * refused).  *out then owns its blob (scn_free).  Returns 0, or -1 with
 * err naming the file and where in it, or the limit passed. */
int compile_scene(const char *path, const compile_opts *o, fr_scene *out, fr_error *err);

#endif
