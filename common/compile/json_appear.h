/** @file json_appear.h
 * The appearance part of the JSON scene format:
 * textures, textured colours, bump and normal maps, participating media,
 * the camera's f-number form and tone-mapping defaults (documented in
 * scenes/README.md).  json_scene.c calls these while it reads a scene.
 *
 * Errors follow the scene reader's style: the JSON path and what was
 * expected, e.g. `materials.floor.albedo: no texture named 'wood'`.
 */
#ifndef FRANJA_JSON_APPEAR_H
#define FRANJA_JSON_APPEAR_H

#include <cjson/cJSON.h>

#include "compile/builder.h"
#include "compile/scene_hooks.h"

/** A decoded texture already in the builder: definition name, whether its
 * texels were converted from sRGB, and its index. */
typedef struct {
    const char *name;
    int from_srgb;
    uint32_t index;
} json_tex_entry;

typedef struct {
    const char *dir;           /**< the scene file's directory */
    const confine *scope;      /**< where image files may be read (confine.h) */
    const scene_hooks *hooks;    /**< may be NULL: image textures then refused */
    fr_builder *b;
    const cJSON *textures;     /**< the "textures" object, or NULL */
    const cJSON *media;        /**< the "media" object, or NULL */
    json_tex_entry *loaded;     /**< textures decoded so far (malloc'd) */
    uint32_t n_loaded, cap_loaded;
} json_appear;

/** Check the top-level "textures" and "media" objects of `root` (every
 * field; image files must have a supported extension and be regular
 * files in `scope`, checked before anything is read) and add
 * the media to b.  Textures are decoded when a material first uses them.
 * Release with json_appear_free. */
int json_appear_begin(json_appear *a, const cJSON *root, const char *dir, const confine *scope, const scene_hooks *hooks,
                     fr_builder *b, fr_error *err);
void json_appear_free(json_appear *a);

/** Read colour member `key` of obj (at path `where`): [r, g, b], a texture
 * name, or {"texture": name, "factor": [r, g, b]}.  *tint receives the
 * colour or the factor (white by default), *tex the texture index or
 * FR_NONE.  Absent and not required: *tint = def, *tex = FR_NONE. */
int json_colour(json_appear *a, const cJSON *obj, const char *key, const char *where, int required, vec3 def,
               vec3 *tint, uint32_t *tex, fr_error *err);

/** Read number member `key` of obj (at path `where`): a number, a texture
 * name, or {"texture": name, "factor": f} (a data texture: no sRGB
 * decoding).  *value receives the number or the factor (1 by default),
 * which must lie in [lo, hi]; *tex the texture index or FR_NONE.  Absent:
 * *value = def, *tex = FR_NONE. */
int json_scalar(json_appear *a, const cJSON *obj, const char *key, const char *where, float def, float lo, float hi,
               float *value, uint32_t *tex, fr_error *err);

/** The material members this module owns: "bump", "normal_map" and
 * "medium"; and the type "interface" (when is_interface). */
int json_material_appearance(json_appear *a, const cJSON *obj, const char *where, int is_interface, fr_material *m,
                            fr_error *err);

/** The camera's optional "fstop" and "focal_length" (both or neither; not
 * with "aperture"): sets cam->aperture = focal_length / (2 fstop). */
int json_camera_lens(const cJSON *cam_obj, fr_camera *cam, fr_error *err);

/** After the shapes: the top-level "medium" (fog) and the medium the camera
 * sits in (found by casting a ray from it across the shapes with interior
 * media), and the top-level "tonemap" object. */
int json_appear_finish(json_appear *a, const cJSON *root, fr_error *err);

#endif
