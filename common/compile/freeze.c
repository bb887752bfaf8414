#include "compile/freeze.h"

#include <stdlib.h>
#include <string.h>

#include "compile/bvh_build.h"
#include "fbin.h"
#include "compile/freeze_light.h"

int frz_scene(fr_builder *b, fr_scene *out, fr_error *err)
{
    memset(out, 0, sizeof *out);
    if (bld_camera_finish(&b->camera, err) < 0)
        return -1;
    fr_array nodes = {NULL, 0, 0, sizeof(fr_bvh_node)}, leaves = {NULL, 0, 0, sizeof(fr_bvh_leaf)};
    /* The BVH reorders prims, so lights (which point at prims) come after. */
    uint32_t *placed = NULL;
    if (bvh_build(b, &nodes, &leaves, &placed, err) < 0) {
        free(nodes.data);
        free(leaves.data);
        return -1;
    }
    int rc = frz_lights(b, placed, err);
    free(placed);

    fr_scene view;
    memset(&view, 0, sizeof view);
    view.settings = b->settings;
    view.camera = b->camera;
#define VIEW(field, arr) view.field = arr.data, view.n_##field = arr.count
    VIEW(materials, b->materials); VIEW(prims, b->prims); VIEW(spheres, b->spheres);
    VIEW(rects, b->rects); VIEW(triangles, b->triangles); VIEW(positions, b->positions);
    VIEW(normals, b->normals); VIEW(uvs, b->uvs); VIEW(planes, b->planes);
    VIEW(lights, b->lights); VIEW(nodes, nodes); VIEW(leaves, leaves);
    VIEW(textures, b->textures); VIEW(texels, b->texels); VIEW(media, b->media);
    view.volume = b->volume;
    view.tonemap = b->tonemap;
    view.world = b->world;
    VIEW(distrib, b->distrib);
    VIEW(light_nodes, b->light_nodes);
#undef VIEW
    void *blob = NULL;
    size_t size = 0;
    if (rc == 0)
        rc = fbin_serialize(&view, &blob, &size, err);
    free(nodes.data);
    free(leaves.data);
    if (rc == 0)
        rc = fbin_open_mem(blob, size, 0, out, err);
    if (rc < 0)
        free(blob);
    return rc;
}
