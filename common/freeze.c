#include "freeze.h"

#include <stdlib.h>
#include <string.h>

#include "bvh_build.h"
#include "fbin.h"
#include "fmath.h"

static float prim_area(const fr_builder *b, const fr_prim *p)
{
    if (p->kind == FR_PRIM_SPHERE) {
        float r = ((const fr_sphere *)b->spheres.data)[p->index].radius;
        return 4.0f * FM_PI * r * r;
    }
    if (p->kind == FR_PRIM_RECT) {
        const fr_rect *q = &((const fr_rect *)b->rects.data)[p->index];
        return v3_len(v3_cross(q->edge_u, q->edge_v));
    }
    const fr_triangle *t = &((const fr_triangle *)b->triangles.data)[p->index];
    const vec3 *pos = b->positions.data;
    return 0.5f * v3_len(v3_cross(v3_sub(pos[t->v[1]], pos[t->v[0]]), v3_sub(pos[t->v[2]], pos[t->v[0]])));
}

/* Turn every prim with an emissive material into an area light and set the
 * probability of picking each light proportional to its power. */
static int make_lights(fr_builder *b, fr_error *err)
{
    const fr_material *mats = b->materials.data;
    fr_prim *prims = b->prims.data;
    for (uint32_t i = 0; i < b->prims.count; i++) {
        const fr_material *m = &mats[prims[i].material];
        prims[i].light = FR_NONE;
        if (v3_is_zero(m->emission))
            continue;
        fr_light l;
        memset(&l, 0, sizeof l);
        l.kind = FR_LIGHT_PRIM;
        l.prim = i;
        l.area = prim_area(b, &prims[i]);
        uint32_t li = bld_push(&b->lights, &l);
        if (li == FR_NONE)
            return fr_fail(err, "out of memory for lights");
        prims[i].light = li;
    }
    fr_light *lights = b->lights.data;
    double total = 0.0;
    for (uint32_t i = 0; i < b->lights.count; i++) {
        double power;
        if (lights[i].kind == FR_LIGHT_POINT) {
            power = 4.0 * FM_PI * v3_luma(lights[i].intensity);
        } else {
            const fr_material *m = &mats[prims[lights[i].prim].material];
            power = FM_PI * v3_luma(m->emission) * lights[i].area * (m->two_sided ? 2.0 : 1.0);
        }
        lights[i].pick = (float)power;
        total += power;
    }
    double acc = 0.0;
    for (uint32_t i = 0; i < b->lights.count; i++) {
        double p = total > 0.0 ? lights[i].pick / total : 1.0 / b->lights.count;
        acc += p;
        lights[i].pick = (float)p;
        lights[i].cdf = i + 1 == b->lights.count ? 1.0f : (float)acc;
    }
    return 0;
}

int frz_scene(fr_builder *b, fr_scene *out, fr_error *err)
{
    memset(out, 0, sizeof *out);
    if (bld_camera_finish(&b->camera, err) < 0)
        return -1;
    fr_array nodes = {NULL, 0, 0, sizeof(fr_bvh_node)}, leaves = {NULL, 0, 0, sizeof(fr_bvh_leaf)};
    /* The BVH reorders prims, so lights (which point at prims) come after. */
    if (bvh_build(b, &nodes, &leaves, err) < 0) {
        free(nodes.data);
        free(leaves.data);
        return -1;
    }
    /* Point lights were pushed by the parser; area lights are derived here. */
    fr_array points = b->lights;
    b->lights = (fr_array){NULL, 0, 0, sizeof(fr_light)};
    int rc = 0;
    for (uint32_t i = 0; i < points.count && rc == 0; i++)
        if (bld_push(&b->lights, (fr_light *)points.data + i) == FR_NONE)
            rc = fr_fail(err, "out of memory for lights");
    free(points.data);
    if (rc == 0)
        rc = make_lights(b, err);

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
