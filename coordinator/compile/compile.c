/* compile.c -- the scene compiler: the JSON reader with the mesh and
 * texture hooks of the coordinator, and the glTF reader (see compile.h). */
#include "compile/compile.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "compile/gltf_scene.h"
#include "imageio.h"
#include "compile/mesh.h"
#include "compile/json_scene.h"

/* The scene's pixel type of OpenImageIO's. */
static uint32_t pix_type(iio_type t)
{
    return t == IIO_U8 ? SCENE_PIX_U8 : t == IIO_U16 ? SCENE_PIX_U16 : t == IIO_F16 ? SCENE_PIX_F16 : SCENE_PIX_F32;
}

/* The reader's scene_image_dest as imageio.h's iio_dest. */
typedef struct {
    iio_dest d;
    const scene_image_dest *to;
    void *given;               /* what to->at returned */
} dest_bridge;

static void *bridge_at(const iio_dest *d, uint32_t width, uint32_t height, uint32_t channels, iio_type type,
                       uint32_t *keep)
{
    dest_bridge *b = (dest_bridge *)d;
    b->given = b->to->at(b->to, width, height, channels, pix_type(type), keep);
    return b->given;
}

/* After iio_read: the image's type, and whether it is in the reader's place. */
static int decoded(int rc, iio_type t, const dest_bridge *b, scene_image *img)
{
    img->type = pix_type(t);
    img->borrowed = rc == 0 && img->data && img->data == b->given;
    return rc;
}

/* The texture hook: images are decoded by OpenImageIO (imageio.h) at
 * their own precision, from the bytes the reader read through its scope,
 * into the place the reader gives (img->dest) when it gives one. */
static int texture_load(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    iio_type t = IIO_F32;
    dest_bridge b = {{bridge_at}, img->dest, NULL};
    int rc = iio_read(path, data, len, img->dest ? &b.d : NULL, &img->data, &t, &img->width, &img->height,
                      &img->channels, err);
    return decoded(rc, t, &b, img);
}

/* Images embedded in glTF files, likewise. */
static int image_load(const void *data, size_t len, const char *mime, scene_image *img, fr_error *err)
{
    iio_type t = IIO_F32;
    dest_bridge b = {{bridge_at}, img->dest, NULL};
    int rc = iio_read_mem(data, len, mime, img->dest ? &b.d : NULL, &img->data, &t, &img->width, &img->height,
                          &img->channels, err);
    return decoded(rc, t, &b, img);
}

int compile_is_gltf(const char *path)
{
    size_t n = strlen(path);
    return (n > 5 && !strcasecmp(path + n - 5, ".gltf")) || (n > 4 && !strcasecmp(path + n - 4, ".glb"));
}

/* The compile's meshes' key, and whether they are left out (compile_opts:
 * skeleton, mesh_key); a compile runs on one thread. */
static uint64_t keys, placed_keys;
static int skeleton;
static const float *bounds;
static uint32_t n_bounds;

/* The mesh hook: its key folded in, then the mesh read unless left out. */
static int mesh_hook(fr_builder *b, const cJSON *node, const char *where, const char *dir, const confine *scope,
                     uint32_t material, fr_error *err)
{
    /* A mesh of an interior medium may hold the camera (json_appear.c
     * looks at its triangles): not stood in.  (A builder without the
     * material places the shape's instances at shutter close only.) */
    if (skeleton && material != FR_NONE && b->meshes.count < n_bounds &&
        (material >= b->materials.count || !((const fr_material *)b->materials.data)[material].medium) &&
        cJSON_GetObjectItemCaseSensitive(node, "instances")) {
        cJSON *content = cJSON_Duplicate(node, 1);
        if (!content)
            return fr_fail(err, "%s: out of memory", where);
        cJSON_DeleteItemFromObjectCaseSensitive(content, "instances");
        int rc = mesh_key(b, content, where, dir, material, &keys, err);
        cJSON_Delete(content);
        return rc < 0 ? -1 : mesh_stand_in_placed(b, node, where, bounds + 6 * (size_t)b->meshes.count, material, err);
    }
    if (mesh_key(b, node, where, dir, material, &keys, err) < 0)
        return -1;
    return skeleton ? mesh_stand_in(b, err) : mesh_add(b, node, where, dir, scope, material, err);
}

int compile_scene(const char *path, const compile_opts *o, fr_scene *out, fr_error *err)
{
    keys = placed_keys = 0;
    skeleton = o && o->skeleton;
    bounds = skeleton ? o->mesh_bounds : NULL;
    n_bounds = bounds ? o->n_mesh_bounds : 0;
    fr_budget budget;
    if (o && o->limits)
        memcpy(budget.limit, o->limits->limit, sizeof budget.limit);
    else
        budget_init(&budget);
    memset(budget.used, 0, sizeof budget.used);
    scene_hooks hooks = {mesh_hook, texture_load, image_load, o ? o->warn : NULL, o ? o->user : NULL,
                         o ? o->allow : NULL, o ? o->n_allow : 0, &budget,
                         o ? o->fbin : NULL, o ? o->timed : 0, o ? o->frame : 0.0, o ? o->fps : 0.0,
                         o ? o->shutter : 0.0, skeleton, &keys, bounds, n_bounds,
                         o && o->placed_key ? &placed_keys : NULL};
    int rc;
    if (compile_is_gltf(path))
        rc = gltf_load_scene(path, &hooks, o ? o->camera : NULL, out, err);
    else if (o && o->camera)
        return fr_fail(err, "%s: --camera names a camera of a glTF scene; a JSON scene has its own", path);
    else
        rc = json_scene_load(path, &hooks, out, err);
    if (rc == 0 && o && o->mesh_key)
        *o->mesh_key = keys;
    if (rc == 0 && o && o->placed_key)
        *o->placed_key = placed_keys;
    char where[4200];
    snprintf(where, sizeof where, "%s: the binary scene", path);
    if (rc == 0 && budget_take(&budget, BUDGET_FBIN, out->blob_size, where, err) < 0) {
        scn_free(out);
        return -1;
    }
    return rc;
}
