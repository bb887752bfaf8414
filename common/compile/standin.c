/* standin.c -- a triangle spanning a mesh's bounds, standing for it (see standin.h). */
#include "compile/standin.h"

#include <math.h>

#include "compile/builder_instance.h"

int standin_mesh(fr_builder *b, const float box[6], uint32_t material, uint32_t *mesh, fr_error *err)
{
    for (int i = 0; i < 3; i++)
        if (!isfinite(box[i]) || !isfinite(box[i + 3]) || box[i] > box[i + 3])
            return fr_fail(err, "a stand-in's bounds hold no vertex");
    vec3 corner[3] = {v3(box[0], box[1], box[2]), v3(box[3], box[4], box[5]), v3(box[0], box[4], box[5])};
    uint32_t m = bld_mesh_begin(b), base = b->positions.count;
    if (m == FR_NONE)
        return fr_fail(err, "out of memory");
    for (int i = 0; i < 3; i++)
        if (bld_push(&b->positions, &corner[i]) == FR_NONE)
            return fr_fail(err, "out of memory");
    fr_triangle tri = {{base, base + 1, base + 2}, 0};
    uint32_t ti = bld_push(&b->triangles, &tri);
    fr_prim p = {FR_PRIM_TRIANGLE, ti, material, FR_NONE};
    if (ti == FR_NONE || bld_push(&b->prims, &p) == FR_NONE)
        return fr_fail(err, "out of memory");
    if (bld_mesh_end(b, m, err) < 0)
        return -1;
    *mesh = m;
    return 0;
}
