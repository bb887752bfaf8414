/* builder_object.c -- objects at compile time: named groups of geometry
 * for the object passes (see builder_object.h). */

#include "compile/builder_object.h"

#include <string.h>

/* A run with the builder's counts now, for object. */
static int push_run(fr_builder *b, uint32_t object, fr_error *err)
{
    bld_object_run r = {object, {0}};
    r.start[FR_PRIM_TRIANGLE] = b->triangles.count;
    r.start[FR_PRIM_SPHERE] = b->spheres.count;
    r.start[FR_PRIM_RECT] = b->rects.count;
    r.start[FR_PRIM_INSTANCE] = b->instances.count;
    r.start[FR_PRIM_KINDS] = b->planes.count;
    if (bld_push(&b->object_runs, &r) == FR_NONE)
        return fr_fail(err, "out of memory for the objects");
    return 0;
}

int bld_object(fr_builder *b, const char *name, fr_error *err)
{
    fr_name n;
    bld_name_set(&n, name);
    /* The same name as the object before: the same object (a JSON scene's
     * triangles of one mesh, each a shape of that name). */
    uint32_t last = b->object_names.count;
    if (last && !strcmp(((const fr_name *)b->object_names.data)[last - 1].name, n.name))
        return push_run(b, last - 1, err);
    uint32_t k = bld_push(&b->object_names, &n);
    if (k == FR_NONE)
        return fr_fail(err, "out of memory for the objects' names");
    return push_run(b, k, err);
}

int bld_object_continue(fr_builder *b, uint32_t object, fr_error *err)
{
    return b->object_runs.count ? push_run(b, object, err) : 0;
}

/* The object of element `index` of kind `kind` (FR_PRIM_TRIANGLE,
 * _SPHERE, _RECT, _INSTANCE, or FR_PRIM_KINDS for a plane); 0 when no
 * object was begun. */
static uint32_t object_of(const fr_builder *b, uint32_t kind, uint32_t index)
{
    if (kind == FR_PRIM_INSTANCE && b->inst_objects.count == b->instances.count && b->inst_objects.count)
        return ((const uint32_t *)b->inst_objects.data)[index];
    const bld_object_run *r = b->object_runs.data;
    uint32_t found = 0;
    /* Starts never decrease from one run to the next: the last run that
     * starts at or before index (a binary search over runs). */
    uint32_t lo = 0, hi = b->object_runs.count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (r[mid].start[kind] <= index)
            found = r[mid].object, lo = mid + 1;
        else
            hi = mid;
    }
    return found;
}

int bld_object_instances(fr_builder *b, fr_error *err)
{
    if (!b->object_runs.count)
        return 0;
    b->inst_objects.count = 0;
    uint32_t n = b->instances.count;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t o = object_of(b, FR_PRIM_INSTANCE, i);
        if (bld_push(&b->inst_objects, &o) == FR_NONE)
            return fr_fail(err, "out of memory for the objects");
    }
    return 0;
}

int bld_object_table(const fr_builder *b, fr_array *out, fr_error *err)
{
    if (!b->object_runs.count)
        return 0;
    const fr_prim *p = b->prims.data;
    for (uint32_t i = 0; i < b->prims.count; i++) {
        uint32_t o = object_of(b, p[i].kind, p[i].index);
        if (bld_push(out, &o) == FR_NONE)
            return fr_fail(err, "out of memory for the objects");
    }
    for (uint32_t i = 0; i < b->planes.count; i++) {
        uint32_t o = object_of(b, FR_PRIM_KINDS, i);
        if (bld_push(out, &o) == FR_NONE)
            return fr_fail(err, "out of memory for the objects");
    }
    for (uint32_t i = 0; i < b->instances.count; i++) {
        uint32_t o = object_of(b, FR_PRIM_INSTANCE, i);
        if (bld_push(out, &o) == FR_NONE)
            return fr_fail(err, "out of memory for the objects");
    }
    return 0;
}
