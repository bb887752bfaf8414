/* freeze.c -- a builder frozen into a ready scene: camera, BVH, lights, bytes
 * (see freeze.h). */

#include "compile/freeze.h"

#include <malloc.h>
#include <stdlib.h>
#include <string.h>

#include "compile/builder_instance.h"
#include "compile/builder_object.h"
#include "compile/bvh_build.h"
#include "fbin.h"
#include "compile/freeze_light.h"

/* The meshes' prims taken out of b->prims into `mp` (mesh by mesh, each
 * mesh's in order) and each mesh's BVH built over them, in object space:
 * nodes and blocks appended to mnodes and mleaves, lanes naming the prims
 * where they will be once appended after the `top` prims of the scene's
 * tree.  b->meshes becomes the fr_mesh table. */
static int build_meshes(fr_builder *b, fr_array *mp, fr_array *mnodes, fr_array *mleaves, fr_array *table,
                        fr_error *err)
{
    uint32_t nm = b->meshes.count, n = b->prims.count;
    const bld_mesh *meshes = b->meshes.data;
    unsigned char *in_mesh = calloc(n ? n : 1, 1);
    fr_array world = {NULL, 0, 0, sizeof(fr_prim)};
    if (!in_mesh)
        return fr_fail(err, "out of memory for the meshes");
    uint32_t top = n;
    for (uint32_t k = 0; k < nm; k++) {
        memset(in_mesh + meshes[k].first, 1, meshes[k].count);
        top -= meshes[k].count;
    }
    int rc = 0;
    const fr_prim *prims = b->prims.data;
    for (uint32_t i = 0; i < n && rc == 0; i++)
        if (!in_mesh[i] && bld_push(&world, &prims[i]) == FR_NONE)
            rc = fr_fail(err, "out of memory for the meshes");
    free(in_mesh);
    uint32_t first = top;
    for (uint32_t k = 0; k < nm && rc == 0; k++) {
        fr_builder mb = *b;
        mb.prims = (fr_array){NULL, 0, 0, sizeof(fr_prim)};
        for (uint32_t i = 0; i < meshes[k].count && rc == 0; i++)
            if (bld_push(&mb.prims, &prims[meshes[k].first + i]) == FR_NONE)
                rc = fr_fail(err, "out of memory for the meshes");
        fr_array nodes = {NULL, 0, 0, sizeof(fr_bvh_node)}, leaves = {NULL, 0, 0, sizeof(fr_bvh_leaf)};
        if (rc == 0)
            rc = bvh_build(&mb, &nodes, &leaves, NULL, err);
        fr_mesh m = {mnodes->count, nodes.count, mleaves->count, leaves.count, first, mb.prims.count, {0, 0}};
        fr_bvh_leaf *L = leaves.data;
        for (uint32_t j = 0; j < leaves.count; j++)
            for (int lane = 0; lane < 4; lane++)
                if (L[j].prim[lane] != FR_NONE)
                    L[j].prim[lane] += first;
        for (uint32_t j = 0; j < nodes.count && rc == 0; j++)
            if (bld_push(mnodes, (fr_bvh_node *)nodes.data + j) == FR_NONE)
                rc = fr_fail(err, "out of memory for the meshes");
        for (uint32_t j = 0; j < leaves.count && rc == 0; j++)
            if (bld_push(mleaves, L + j) == FR_NONE)
                rc = fr_fail(err, "out of memory for the meshes");
        for (uint32_t i = 0; i < mb.prims.count && rc == 0; i++)
            if (bld_push(mp, (fr_prim *)mb.prims.data + i) == FR_NONE)
                rc = fr_fail(err, "out of memory for the meshes");
        if (rc == 0 && bld_push(table, &m) == FR_NONE)
            rc = fr_fail(err, "out of memory for the meshes");
        first += mb.prims.count;
        free(mb.prims.data);
        free(nodes.data);
        free(leaves.data);
    }
    if (rc < 0) {
        free(world.data);
        return -1;
    }
    free(b->prims.data);
    b->prims = world;
    return 0;
}

/* The arrays freezing makes beside the builder's. */
typedef struct {
    fr_array nodes, leaves, mnodes, mleaves, table;
    fr_array objects;          /* uint32_t: the objects section (builder_object.h) */
} frozen;

static void frozen_free(frozen *f)
{
    free(f->nodes.data);
    free(f->leaves.data);
    free(f->mnodes.data);
    free(f->mleaves.data);
    free(f->table.data);
    free(f->objects.data);
}

/* Everything but the bytes: camera, BVH, lights; *view points at the
 * builder's arrays and f's (f freed by the caller, also on failure). */
static int prepare(fr_builder *b, frozen *f, fr_scene *view, fr_error *err)
{
    f->nodes = (fr_array){NULL, 0, 0, sizeof(fr_bvh_node)};
    f->leaves = (fr_array){NULL, 0, 0, sizeof(fr_bvh_leaf)};
    f->mnodes = (fr_array){NULL, 0, 0, sizeof(fr_bvh_node)};
    f->mleaves = (fr_array){NULL, 0, 0, sizeof(fr_bvh_leaf)};
    f->table = (fr_array){NULL, 0, 0, sizeof(fr_mesh)};
    f->objects = (fr_array){NULL, 0, 0, sizeof(uint32_t)};
    if (bld_camera_finish(&b->camera, err) < 0 || bld_drop_unused_vertices(b, err) < 0 || bld_flatten(b, 0, err) < 0)
        return -1;
    if ((b->motion.flags & FR_MOTION_CAMERA) && bld_camera_finish(&b->motion.camera_close, err) < 0)
        return -1;
    fr_array mprims = {NULL, 0, 0, sizeof(fr_prim)};
    /* With instances, two levels: a tree per mesh, then the scene's over
     * the other prims and the instances (bld_flatten has dropped meshes
     * without instances, so a scene without any takes the one-level path
     * unchanged). */
    int rc = b->meshes.count ? build_meshes(b, &mprims, &f->mnodes, &f->mleaves, &f->table, err) : 0;
    /* The BVH reorders prims, so lights (which point at prims) come after. */
    uint32_t *placed = NULL;
    if (rc == 0)
        rc = bvh_build(b, &f->nodes, &f->leaves, &placed, err);
    if (rc == 0)
        rc = frz_lights(b, placed, err);
    free(placed);
    for (uint32_t i = 0; i < mprims.count && rc == 0; i++)
        if (bld_push(&b->prims, (fr_prim *)mprims.data + i) == FR_NONE)
            rc = fr_fail(err, "out of memory for the meshes");
    free(mprims.data);

    /* Every material has a name ("" when none was given), or none has. */
    fr_name unnamed;
    memset(&unnamed, 0, sizeof unnamed);
    while (rc == 0 && b->material_names.count && b->material_names.count < b->materials.count)
        if (bld_push(&b->material_names, &unnamed) == FR_NONE)
            rc = fr_fail(err, "out of memory for the materials' names");
    if (rc == 0)
        rc = bld_object_table(b, &f->objects, err);
    memset(view, 0, sizeof *view);
    view->settings = b->settings;
    view->camera = b->camera;
#define VIEW(field, arr) view->field = arr.data, view->n_##field = arr.count
    VIEW(materials, b->materials); VIEW(prims, b->prims); VIEW(spheres, b->spheres);
    VIEW(rects, b->rects); VIEW(triangles, b->triangles); VIEW(positions, b->positions);
    VIEW(normals, b->normals); VIEW(uvs, b->uvs); VIEW(planes, b->planes);
    VIEW(lights, b->lights); VIEW(nodes, f->nodes); VIEW(leaves, f->leaves);
    VIEW(textures, b->textures); VIEW(texels, b->texels); VIEW(media, b->media);
    view->volume = b->volume;
    view->tonemap = b->tonemap;
    view->world = b->world;
    view->motion = b->motion;
    VIEW(distrib, b->distrib);
    VIEW(meshes, f->table); VIEW(instances, b->instances); VIEW(inst_motions, b->inst_motions);
    VIEW(mesh_nodes, f->mnodes); VIEW(mesh_leaves, f->mleaves);
    VIEW(light_nodes, b->light_nodes);
    VIEW(material_names, b->material_names);
    VIEW(objects, f->objects);
    VIEW(light_groups, b->light_groups);
    if (b->light_groups.count)
        VIEW(group_names, b->group_names);
    if (f->objects.count)
        VIEW(object_names, b->object_names);
#undef VIEW
    return rc;
}

int frz_scene(fr_builder *b, fr_scene *out, fr_error *err)
{
    memset(out, 0, sizeof *out);
    frozen f;
    fr_scene view;
    int rc = prepare(b, &f, &view, err);
    void *blob = NULL;
    size_t size = 0;
    if (rc == 0)
        rc = fbin_serialize(&view, &blob, &size, err);
    frozen_free(&f);
    if (rc == 0)
        rc = fbin_open_mem(blob, size, 0, out, err);
    if (rc < 0)
        free(blob);
    return rc;
}

int frz_scene_file(fr_builder *b, const char *path, fr_scene *out, fr_error *err)
{
    memset(out, 0, sizeof *out);
    /* What the readers freed (mesh files, their parsed arrays) goes back
     * to the system before the BVH's working memory is taken, and the
     * builder's before the file is mapped: else it stays the process's. */
    malloc_trim(0);
    frozen f;
    fr_scene view;
    int rc = prepare(b, &f, &view, err);
    uint64_t hash;
    size_t size;
    if (rc == 0)
        rc = fbin_write_view(&view, path, &hash, &size, err);
    frozen_free(&f);
    bld_free(b);
    malloc_trim(0);
    /* Checked as a worker will check it, from the file. */
    if (rc == 0)
        rc = fbin_load(path, out, err);
    return rc;
}
