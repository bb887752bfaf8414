/** @file gltf_scene.h
 * Importing a glTF 2.0 scene (.gltf or .glb) at compile time: the node
 * hierarchy with its transforms, the meshes' triangles with normals and
 * UVs (bent by their morph targets' weights and their skins' joints),
 * materials and textures (gltf_mat.h), the camera and the punctual
 * lights; posed by the file's animations at a time when asked
 * (gltf_anim.h).  The mapping, and what is ignored, is documented in
 * scenes/README.md.
 *
 * glTF is Y-up, right-handed, in metres; Franja has no fixed up axis, so
 * the scene keeps glTF's coordinates (a placement may move it).  glTF's
 * texture origin is the image's top-left corner: v is flipped on import
 * (Franja's v grows upward).
 *
 * Errors name the file and the JSON pointer (or byte offset) at fault and
 * never abort; features that are not supported are reported once each
 * through the hooks' warn callback (scene_hooks.h).  Compile time only.
 */
#ifndef FRANJA_GLTF_SCENE_H
#define FRANJA_GLTF_SCENE_H

#include "compile/builder.h"
#include "compile/scene_hooks.h"

/** Most triangles one import may add unless told otherwise (instancing a
 * mesh many times could otherwise turn a small file into a huge scene). */
#define GLTF_MAX_TRIANGLES (1u << 26)

/** What to take from the file and how to place it. */
typedef struct {
    const char *camera;        /**< name of the camera to use (node or camera name); NULL: the first */
    int take_camera;           /**< set b->camera (and the image size, from aspectRatio) from the file */
    int take_lights;           /**< add the file's punctual lights */
    double place[3][4];        /**< row-major affine transform applied to the whole scene */
    uint32_t material;         /**< FR_NONE: the file's materials; else this one for every triangle */
    uint32_t max_triangles;    /**< 0: GLTF_MAX_TRIANGLES */
    const confine *scope;      /**< the file is named by a scene with this scope (confine.h): it, its
                                    buffers and images are read through it; NULL: the file is the scene,
                                    read as named, with its own folder and the hooks' allow list */
    int animate;               /**< pose the nodes by the file's animations at `time` (gltf_anim.h); 0:
                                    the nodes' own transforms (a warning says animations are not played) */
    double time;               /**< seconds, when animate */
    int camera_only;           /**< take the camera alone: no meshes (nor, with take_lights 0, lights) */
} gltf_options;

/** Options for a file rendered alone: its first camera, its lights, no
 * placement, its own materials, at rest. */
void gltf_options_default(gltf_options *o);

/** What an import found. */
typedef struct {
    int camera_found;          /**< the file's camera was taken (take_camera) */
    float aspect;              /**< its aspectRatio (width / height), 0 when it gives none */
    uint32_t triangles;        /**< triangles added */
    uint32_t lights;           /**< punctual lights added */
} gltf_result;

/** Imports file `path` into b as `o` says.  A named camera that is not in
 * the file is an error (listing the names there are).  Returns 0, or -1
 * with err naming the file and JSON pointer. */
int gltf_import(const char *path, const scene_hooks *hooks, const gltf_options *o, fr_builder *b, gltf_result *r,
                fr_error *err);

/** The same, from a document already in memory (tests, fuzzing). */
int gltf_import_mem(const void *bytes, size_t len, const char *name, const scene_hooks *hooks, const gltf_options *o,
                    fr_builder *b, gltf_result *r, fr_error *err);

/** A glTF file as a whole scene, posed at hooks->time when hooks->timed
 * (scene_hooks.h), its camera moving across hooks->shutter (seconds,
 * centred on that time: the camera posed at shutter open and close,
 * scene.h's fr_motion, when the two poses differ): default image settings (640 pixels wide,
 * the height from the camera's aspect ratio, else 480; 64 samples, 8
 * bounces), the file's camera `camera` (or its first; with none, one
 * framing the scene's bounds from +Z, with a warning) and its lights (with
 * none and nothing emissive, a white environment of radiance 1, with a
 * warning),
 * frozen into *out (freeze.h).  Returns 0, or -1 with err set. */
int gltf_load_scene(const char *path, const scene_hooks *hooks, const char *camera, fr_scene *out, fr_error *err);

/** The builder part of gltf_load_scene, for callers that freeze it
 * themselves (`bytes` NULL: read `path`). */
int gltf_build_scene(const char *path, const void *bytes, size_t len, const scene_hooks *hooks, const char *camera,
                     uint32_t max_triangles, fr_builder *b, fr_error *err);

#endif
