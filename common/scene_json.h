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

typedef struct {
    /* Add the mesh described by JSON object `node` (at JSON path `where`)
     * to the builder with material `material`; `dir` is the scene file's
     * directory, for relative file names. */
    int (*mesh)(fr_builder *b, const cJSON *node, const char *where, const char *dir, uint32_t material,
                fr_error *err);
} scn_hooks;

/* Parse the JSON text `text` (from file `file`, used in messages) into b. */
int scn_parse_json(const char *text, const char *file, const scn_hooks *hooks, fr_builder *b, fr_error *err);

/* Read file `path`, parse it and freeze the scene into *out. */
int scn_load_json(const char *path, const scn_hooks *hooks, fr_scene *out, fr_error *err);

/* Helpers shared with the hooks: read a JSON member as a finite number or
 * a 3-vector, with the same error style.  `where` is the object's path. */
int scn_json_number(const cJSON *obj, const char *key, const char *where, int required, float def, float *out,
                    fr_error *err);
int scn_json_vec3(const cJSON *obj, const char *key, const char *where, int required, vec3 def, vec3 *out,
                  fr_error *err);

#endif
