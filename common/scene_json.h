/* scene_json.h -- reading a scene description (JSON, see scenes/README.md).
 *
 * The reader validates everything: a missing field, a wrong type, an
 * unknown field or material name, a negative radius, a zero-area shape, a
 * degenerate camera or a non-finite number is refused with the file, the
 * JSON path (e.g. `shapes[3].radius`) and what was expected.
 *
 * Assets that need heavy libraries (meshes, image textures) are loaded by
 * hooks the caller provides: the coordinator's compiler passes them, the
 * worker passes none and such scenes are refused with a hint to compile
 * them first. */
#ifndef FRANJA_SCENE_JSON_H
#define FRANJA_SCENE_JSON_H

#include <cjson/cJSON.h>

#include "builder.h"

/* An image as a texture hook decodes it: width*height*channels floats,
 * top row first, the values as stored (8- and 16-bit images scaled to
 * [0, 1]; no colour conversion).  pixels is malloc'd; the parser frees it. */
typedef struct {
    float *pixels;
    uint32_t width, height, channels;
} scn_image;

typedef struct {
    /* Add the mesh described by JSON object `node` (at JSON path `where`)
     * to the builder with material `material`; `dir` is the scene file's
     * directory, for relative file names. */
    int (*mesh)(fr_builder *b, const cJSON *node, const char *where, const char *dir, uint32_t material,
                fr_error *err);
    /* Decode image file `path` (already joined to the scene's directory)
     * into *img; on failure say why (unreadable, unsupported, corrupt). */
    int (*texture)(const char *path, scn_image *img, fr_error *err);
} scn_hooks;

/* Parse the JSON text `text` (from file `file`, used in messages) into b. */
int scn_parse_json(const char *text, const char *file, const scn_hooks *hooks, fr_builder *b, fr_error *err);

/* Read file `path`, parse it and freeze the scene into *out. */
int scn_load_json(const char *path, const scn_hooks *hooks, fr_scene *out, fr_error *err);

/* Helpers shared with the hooks: read a JSON member as a finite number or
 * a 3-vector, with the same error style.  `where` is the object's path. */
int scn_json_number(const cJSON *obj, const char *key, const char *where, int required, float def, float *out,
                    fr_error *err);
/* Refuse members of obj not in `allowed` (NULL-terminated): a typo must
 * not be silently ignored. */
int scn_json_only_fields(const cJSON *obj, const char *where, const char *const *allowed, fr_error *err);
int scn_json_vec3(const cJSON *obj, const char *key, const char *where, int required, vec3 def, vec3 *out,
                  fr_error *err);

#endif
