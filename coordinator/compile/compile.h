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

#include "error.h"
#include "scene.h"

/** How to compile: the glTF camera to take (NULL: the first), where
 * warnings go (NULL: nowhere; `user` is passed back), and the folders
 * besides the scene's own that its files may lie in (`--allow-path`;
 * confine.h). */
typedef struct {
    const char *camera;
    void (*warn)(void *user, const char *msg);
    void *user;
    const char *const *allow;
    unsigned n_allow;
} compile_opts;

/** 1 when `path` names a glTF scene (.gltf or .glb, any case). */
int compile_is_gltf(const char *path);

/** Compiles the scene `path`: a whole glTF scene (.gltf, .glb;
 * gltf_scene.h) or a JSON scene.  *out then owns its blob (scn_free).
 * Returns 0, or -1 with err naming the file and where in it. */
int compile_scene(const char *path, const compile_opts *o, fr_scene *out, fr_error *err);

#endif
