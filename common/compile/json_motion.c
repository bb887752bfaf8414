/* json_motion.c -- keyed JSON shapes moving across the shutter: mesh shapes
 * become moving instances, others are posed at the frame with a warning
 * (see json_motion.h). */

#include "compile/json_motion.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "compile/builder_motion.h"
#include "compile/json_keys.h"

/* The fields that place a mesh shape or one of its instances. */
static const char *const placing[] = {"scale", "rotate", "translate", "matrix", NULL};

int json_motion_pose(cJSON *s, const char *where, const scene_hooks *h, cJSON **close, fr_error *err)
{
    *close = NULL;
    double f0 = h->frame - 0.5 * h->shutter, f1 = h->frame + 0.5 * h->shutter;
    cJSON *a = cJSON_Duplicate(s, 1), *z = cJSON_Duplicate(s, 1);
    if (!a || !z) {
        cJSON_Delete(a);
        cJSON_Delete(z);
        return fr_fail(err, "%s: out of memory", where);
    }
    int rc = json_keys_pose(a, where, f0, err) < 0 || json_keys_pose(z, where, f1, err) < 0 ? -1 : 0;
    int moves = rc == 0 && !cJSON_Compare(a, z, 1);
    cJSON_Delete(a);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(s, "type");
    int mesh = cJSON_IsString(type) && !strcmp(type->valuestring, "mesh");
    if (rc == 0 && moves && mesh) {
        *close = z;
        return json_keys_pose(s, where, f0, err);
    }
    cJSON_Delete(z);
    if (rc < 0)
        return -1;
    if (moves && h->warn) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s: moves across the shutter, but only mesh shapes and their instances are "
                 "motion blurred: it is posed at the frame's time, sharp", where);
        h->warn(h->user, msg);
    }
    return json_keys_pose(s, where, h->frame, err);
}

/* A copy of mesh shape o placed by instances: as it is when it has some,
 * else with its own placing fields moved into one instance. */
static cJSON *as_instances(const cJSON *o)
{
    cJSON *c = cJSON_Duplicate(o, 1);
    if (!c || cJSON_GetObjectItemCaseSensitive(c, "instances"))
        return c;
    cJSON *list = cJSON_CreateArray(), *one = cJSON_CreateObject();
    if (!list || !one || !cJSON_AddItemToArray(list, one) || !cJSON_AddItemToObject(c, "instances", list)) {
        cJSON_Delete(list);
        if (!list)
            cJSON_Delete(one);
        cJSON_Delete(c);
        return NULL;
    }
    for (int i = 0; placing[i]; i++) {
        cJSON *f = cJSON_DetachItemFromObjectCaseSensitive(c, placing[i]);
        if (f)
            cJSON_AddItemToObject(one, placing[i], f);
    }
    return c;
}

/* Warns (through h->warn) of each placement of a and z (shapes as
 * as_instances makes them) whose `rotate` turns by more than half a turn
 * about an axis between them: the renderer blends the shorter way. */
static void half_turns(const cJSON *a, const cJSON *z, const char *where, const scene_hooks *h)
{
    const cJSON *la = cJSON_GetObjectItemCaseSensitive(a, "instances"), *lz = cJSON_GetObjectItemCaseSensitive(z, "instances");
    int k = 0;
    for (const cJSON *x = la ? la->child : NULL, *y = lz ? lz->child : NULL; x && y && h->warn;
         x = x->next, y = y->next, k++) {
        const cJSON *ra = cJSON_GetObjectItemCaseSensitive(x, "rotate"), *rz = cJSON_GetObjectItemCaseSensitive(y, "rotate");
        if (cJSON_GetArraySize(ra) != 3 || cJSON_GetArraySize(rz) != 3)
            continue;
        double most = 0.0;
        for (int i = 0; i < 3; i++)
            most = fmax(most, fabs(cJSON_GetArrayItem(ra, i)->valuedouble - cJSON_GetArrayItem(rz, i)->valuedouble));
        if (most > 180.0) {
            char msg[512];
            snprintf(msg, sizeof msg, "%s.instances[%d].rotate: turns %g degrees across the shutter; the blur takes "
                     "the shorter way between its two ends (at most half a turn)", where, k, most);
            h->warn(h->user, msg);
        }
    }
}

int json_motion_mesh(fr_builder *b, cJSON *open, const cJSON *close, const char *where, const char *dir,
                     const confine *scope, const scene_hooks *h, uint32_t material, fr_error *err)
{
    if (cJSON_GetObjectItemCaseSensitive(open, "instances"))
        for (int i = 0; placing[i]; i++) {
            const cJSON *x = cJSON_GetObjectItemCaseSensitive(open, placing[i]),
                        *y = cJSON_GetObjectItemCaseSensitive(close, placing[i]);
            if (!x != !y || (x && !cJSON_Compare(x, y, 1)))
                return fr_fail(err, "%s.%s: a mesh shape with instances moves by its instances' transforms, not "
                               "its own (key the instances' %s instead)", where, placing[i], placing[i]);
        }
    cJSON *a = as_instances(open), *z = as_instances(close);
    /* The shape's name was read from the open pose (parse_shape sets it
     * aside while the shape's fields are read): the closing one's too. */
    if (z)
        cJSON_DeleteItemFromObjectCaseSensitive(z, "name");
    if (a && z)
        half_turns(a, z, where, h);
    fr_builder tmp;
    bld_init(&tmp);
    uint32_t first = b->instances.count;
    int rc = a && z ? 0 : fr_fail(err, "%s: out of memory", where);
    fr_error e;
    if (rc == 0 && h->mesh(b, a, where, dir, scope, material, &e) < 0)
        rc = fr_fail(err, "%s", e.msg);
    /* The placements at shutter close, from the same shape posed then. */
    tmp.camera = b->camera;
    tmp.settings = b->settings;
    if (rc == 0 && h->mesh(&tmp, z, where, dir, scope, material, &e) < 0)
        rc = fr_fail(err, "%s (at shutter close): %s", where, e.msg);
    if (rc == 0 && tmp.instances.count != b->instances.count - first)
        rc = fr_fail(err, "%s: %u placements at shutter open, %u at close", where, b->instances.count - first,
                     tmp.instances.count);
    for (uint32_t k = 0; rc == 0 && k < tmp.instances.count; k++) {
        const fr_instance *in = (const fr_instance *)tmp.instances.data + k;
        if (bld_instance_motion(b, first + k, (const float(*)[4])in->xf, &e) < 0)
            rc = fr_fail(err, "%s.instances[%u]: %s", where, k, e.msg);
    }
    bld_free(&tmp);
    cJSON_Delete(a);
    cJSON_Delete(z);
    return rc;
}
