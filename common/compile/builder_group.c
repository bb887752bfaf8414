/* builder_group.c -- light groups at compile time: their names and which
 * lights and emissive materials are in them (see builder_group.h). */

#include "compile/builder_group.h"

#include <string.h>

#include "passes.h"

/* The index of group `name`, added (after "default") when new. */
static int group_index(fr_builder *b, const char *name, const char *where, uint32_t *out, fr_error *err)
{
    fr_name n;
    if (!b->group_names.count) {
        bld_name_set(&n, "default");
        if (bld_push(&b->group_names, &n) == FR_NONE)
            return fr_fail(err, "%s: out of memory", where);
    }
    bld_name_set(&n, name);
    const fr_name *v = b->group_names.data;
    for (uint32_t i = 0; i < b->group_names.count; i++)
        if (!strcmp(v[i].name, n.name)) {
            *out = i;
            return 0;
        }
    if (b->group_names.count >= PASS_LIGHT_GROUPS)
        return fr_fail(err, "%s.light_group: '%s' would be light group %u; a scene has at most %d, \"default\" "
                       "included", where, n.name, b->group_names.count + 1, PASS_LIGHT_GROUPS);
    if ((*out = bld_push(&b->group_names, &n)) == FR_NONE)
        return fr_fail(err, "%s: out of memory", where);
    return 0;
}

/* a[index] = value, a grown with zeros (the default group) to hold it. */
static int set_at(fr_array *a, uint32_t index, uint32_t value, const char *where, fr_error *err)
{
    uint32_t zero = 0;
    while (a->count <= index)
        if (bld_push(a, &zero) == FR_NONE)
            return fr_fail(err, "%s: out of memory", where);
    ((uint32_t *)a->data)[index] = value;
    return 0;
}

int bld_light_group(fr_builder *b, uint32_t light, const char *name, const char *where, fr_error *err)
{
    uint32_t g;
    return group_index(b, name, where, &g, err) < 0 ? -1 : set_at(&b->given_groups, light, g, where, err);
}

int bld_material_group(fr_builder *b, uint32_t material, const char *name, const char *where, fr_error *err)
{
    uint32_t g;
    return group_index(b, name, where, &g, err) < 0 ? -1 : set_at(&b->material_groups, material, g, where, err);
}

uint32_t bld_group_of(const fr_builder *b, uint32_t given, uint32_t material)
{
    const fr_array *a = given != FR_NONE ? &b->given_groups : &b->material_groups;
    uint32_t i = given != FR_NONE ? given : material;
    return i < a->count ? ((const uint32_t *)a->data)[i] : 0;
}
