/** @file scene_hooks.h
 * What a caller plugs into the scene readers: the loaders of assets that
 * need heavy libraries (meshes, image textures).  The coordinator's
 * compiler passes them; the worker passes none, and scenes that need them
 * are then refused with a hint to compile them first.
 */
#ifndef FRANJA_SCENE_HOOKS_H
#define FRANJA_SCENE_HOOKS_H

#include <cjson/cJSON.h>

#include "compile/budget.h"
#include "compile/builder.h"
#include "compile/confine.h"

/** How a decoded image's values are held: the file's own precision. */
enum { SCENE_PIX_F32 = 0, SCENE_PIX_U8 = 1, SCENE_PIX_U16 = 2, SCENE_PIX_F16 = 3 };

/** Where a texture hook may decode an image instead of malloc'ing it
 * (texstore.h gives one that is the texels' own place). */
typedef struct scene_image_dest {
    /** Called by the hook once it knows the image's size, channels and
     * type (SCENE_PIX_*): where to decode it, keeping the first *keep
     * channels of each pixel (width*height*keep values), or NULL: malloc
     * it whole as usual. */
    void *(*at)(const struct scene_image_dest *d, uint32_t width, uint32_t height, uint32_t channels,
                uint32_t type, uint32_t *keep);
} scene_image_dest;

/** An image as a texture hook decodes it: width*height*channels values of
 * `type` (SCENE_PIX_*; 0, float, unless the hook says otherwise), top row
 * first, as stored: no colour conversion (8- and 16-bit integers mean
 * k / 255 and k / 65535, halves are IEEE 754 binary16 bits).  The pixels
 * are malloc'd, and the reader frees them, unless the hook decoded them
 * where `dest` said (`borrowed`). */
typedef struct {
    union {
        float *pixels;         /**< SCENE_PIX_F32 */
        void *data;            /**< the other types: uint8_t, uint16_t, binary16 bits in uint16_t */
    };
    uint32_t width, height, channels;
    uint32_t type;             /**< SCENE_PIX_* */
    const scene_image_dest *dest; /**< set by the reader: where the hook may decode (NULL: malloc) */
    int borrowed;              /**< set by the hook: 1 when data is dest's memory, not to be freed */
} scene_image;

/** The asset loaders (any may be NULL) and the compile's budget. */
typedef struct {
    /** Add the mesh described by JSON object `node` (at JSON path `where`)
     * to the builder with material `material` (FR_NONE: the mesh's own
     * materials); `dir` is the scene file's directory, for relative file
     * names, and every file the mesh reads is opened through `scope`
     * (confine.h).  Returns 0, or -1 with *err set. */
    int (*mesh)(fr_builder *b, const cJSON *node, const char *where, const char *dir, const confine *scope,
                uint32_t material, fr_error *err);
    /** Decode the image file `path` (already joined to the scene's
     * directory; its extension names the format), whose `len` bytes the
     * reader has read through its confine.h scope into `data`, into *img;
     * on failure return -1 and say why (unsupported, corrupt) without
     * quoting the bytes. */
    int (*texture)(const char *path, const void *data, size_t len, scene_image *img, fr_error *err);
    /** Decode an image held in memory (`len` bytes; `mime` such as
     * "image/png", or "" when unknown), as `texture` does a file.  May be
     * NULL: images embedded in glTF files are then not decoded (a warning
     * says so). */
    int (*image_mem)(const void *data, size_t len, const char *mime, scene_image *img, fr_error *err);
    /** Report a warning (a feature of an input file that is not supported
     * and was ignored, named once); `user` is passed back.  May be NULL. */
    void (*warn)(void *user, const char *msg);
    void *user;
    /** Folders besides the scene's own that its files may lie in
     * (`--allow-path`; n_allow of them, may be NULL when 0). */
    const char *const *allow;
    unsigned n_allow;
    /** The compile's limits (budget.h): the scene readers give it to their
     * builder, and count what they read and build against it.  May be
     * NULL: no limits. */
    fr_budget *budget;
    /** Where the readers write the binary scene (freeze.h's
     * frz_scene_file: the builder freed before the file is mapped back),
     * or NULL: it is made in memory (frz_scene). */
    const char *fbin;
    /** When timed: the frame at which animated scenes are posed, at fps
     * frames per second (glTF animations at ganim_hooks_time: gltf_anim.h;
     * keyframes of JSON scenes by frame: json_keys.h); otherwise they are
     * read at rest. */
    int timed;
    double frame, fps;
    /** When timed: how long the shutter is open, in frames, centred on
     * `frame` (0: no motion blur).  What moves across it is blurred
     * (scene.h's fr_motion). */
    double shutter;
    /** A skeleton (coordinator/reuse.h): glTF meshes are not read, each
     * node's mesh stands as one triangle of the default material; the
     * mesh shapes of JSON scenes are the mesh hook's to leave out. */
    int skeleton;
    /** When not NULL, every glTF file read folds its name and identity on
     * disk, and every mesh a node draws what places and shapes it (node,
     * mesh, world transform, morph weights, joints), into *mesh_key, in a
     * skeleton or not alike. */
    uint64_t *mesh_key;
    /** A skeleton only: NULL, or the object-space vertex bounds (lo x y z,
     * hi x y z) of the n_mesh_bounds meshes (builder_instance.h) of the
     * full compile the skeleton follows, by mesh index.  A glTF mesh placed
     * by instances (drawn by several nodes, or moving across the shutter)
     * then stands as standin.h's triangle spanning the bounds its mesh
     * index has, of its first primitive's material, placed as the mesh
     * would be; its key leaves out the node's placement.  Every other glTF
     * mesh is read whole (its triangles are the world's). */
    const float *mesh_bounds;
    uint32_t n_mesh_bounds;
    /** When not NULL: every glTF file and mesh folded into *placed_key as
     * a skeleton with mesh_bounds folds them into *mesh_key (that key,
     * without reading a mesh). */
    uint64_t *placed_key;
} scene_hooks;

#endif
