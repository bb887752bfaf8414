/* compile.c -- the scene compiler: the JSON reader with the mesh and
 * texture hooks of the coordinator (see compile.h). */
#include "compile.h"

#include "imageio.h"
#include "mesh.h"
#include "scene_json.h"

/* The texture hook: images are decoded by OpenImageIO (imageio.h). */
static int texture_load(const char *path, scn_image *img, fr_error *err)
{
    return iio_read(path, &img->pixels, &img->width, &img->height, &img->channels, err);
}

int compile_json(const char *json_path, fr_scene *out, fr_error *err)
{
    const scn_hooks hooks = {mesh_add, texture_load};
    return scn_load_json(json_path, &hooks, out, err);
}
