/* json_light.c -- the JSON scene's "lights" array and "environment" object
 * (see json_light.h). */

#include "compile/json_light.h"

#include <stdio.h>
#include <string.h>

#include "compile/builder_group.h"
#include "compile/builder_light.h"
#include "fmath.h"
#include "compile/jsonval.h"

#define PATHLEN 160
#define DEG (FM_PI / 180.0f)

/* A message from builder_light.h, prefixed with the light's path. */
static int located(int rc, const char *where, const fr_error *e, fr_error *err)
{
    return rc < 0 ? fr_fail(err, "%s.%s", where, e->msg) : 0;
}

static int parse_light(json_appear *a, const cJSON *o, const char *where, fr_error *err)
{
    static const char *const point_f[] = {"type", "position", "intensity", NULL};
    static const char *const spot_f[] = {"type", "position", "direction", "target", "intensity", "inner_angle",
                                         "outer_angle", NULL};
    static const char *const sun_f[] = {"type", "direction", "irradiance", "angle", NULL};
    static const char *const types[] = {"point", "spot", "sun", NULL};
    if (!cJSON_IsObject(o))
        return fr_fail(err, "%s: expected an object", where);
    int type;
    if (!cJSON_GetObjectItemCaseSensitive(o, "type"))
        return fr_fail(err, "%s.type: missing (expected point, spot or sun; area lights are shapes with emission)",
                       where);
    if (jv_choice(o, "type", where, types, 0, &type, err) < 0)
        return -1;
    fr_error e;
    vec3 pos, dir, col;
    if (type == 0) {
        if (jv_only_fields(o, where, point_f, err) < 0 || jv_vec3(o, "position", where, 1, v3s(0), &pos, err) < 0 ||
            jv_vec3(o, "intensity", where, 1, v3s(0), &col, err) < 0)
            return -1;
        return located(bld_point_light(a->b, pos, col, &e), where, &e, err);
    }
    if (type == 1) {
        float inner, outer;
        int has_dir = cJSON_GetObjectItemCaseSensitive(o, "direction") != NULL;
        if (has_dir == (cJSON_GetObjectItemCaseSensitive(o, "target") != NULL))
            return fr_fail(err, "%s: expected either \"direction\" or \"target\"", where);
        if (jv_only_fields(o, where, spot_f, err) < 0 || jv_vec3(o, "position", where, 1, v3s(0), &pos, err) < 0 ||
            jv_vec3(o, has_dir ? "direction" : "target", where, 1, v3s(0), &dir, err) < 0 ||
            jv_vec3(o, "intensity", where, 1, v3s(0), &col, err) < 0 ||
            jv_number(o, "inner_angle", where, 0, 0.0f, &inner, err) < 0 ||
            jv_number(o, "outer_angle", where, 0, 45.0f, &outer, err) < 0)
            return -1;
        if (!has_dir)
            dir = v3_sub(dir, pos);
        if (!(outer > 0.0f && outer <= 180.0f))
            return fr_fail(err, "%s.outer_angle: expected degrees from the axis in (0, 180]", where);
        if (!(inner >= 0.0f && inner < outer))
            return fr_fail(err, "%s.inner_angle: expected degrees from the axis in [0, outer_angle)", where);
        if (!has_dir && !(v3_len2(dir) > 0.0f))
            return fr_fail(err, "%s.target: expected a point other than the position", where);
        return located(bld_spot_light(a->b, pos, dir, col, inner * DEG, outer * DEG, &e), where, &e, err);
    }
    float angle;
    if (jv_only_fields(o, where, sun_f, err) < 0 || jv_vec3(o, "direction", where, 1, v3s(0), &dir, err) < 0 ||
        jv_vec3(o, "irradiance", where, 1, v3s(0), &col, err) < 0 ||
        jv_number(o, "angle", where, 0, 0.0f, &angle, err) < 0)
        return -1;
    if (!(angle >= 0.0f && angle <= 180.0f))
        return fr_fail(err, "%s.angle: expected an angular diameter in [0, 180] degrees", where);
    return located(bld_sun_light(a->b, dir, col, angle * DEG, &e), where, &e, err);
}

/* parse(a, o, where, err) with o's optional "light_group" key set aside
 * while it reads o's other fields: the light it adds is in that group
 * (builder_group.h). */
static int grouped(json_appear *a, const cJSON *o, const char *where,
                   int (*parse)(json_appear *, const cJSON *, const char *, fr_error *), fr_error *err)
{
    cJSON *g = cJSON_IsObject(o) ? cJSON_DetachItemFromObjectCaseSensitive((cJSON *)o, "light_group") : NULL;
    uint32_t before = a->b->lights.count;
    int rc = 0;
    if (g && (!cJSON_IsString(g) || !g->valuestring[0]))
        rc = fr_fail(err, "%s.light_group: expected a non-empty string", where);
    if (rc == 0)
        rc = parse(a, o, where, err);
    if (rc == 0 && g && a->b->lights.count > before)
        rc = bld_light_group(a->b, before, g->valuestring, where, err);
    if (g)
        cJSON_AddItemToObject((cJSON *)o, "light_group", g);
    return rc;
}

int json_lights(json_appear *a, const cJSON *lights, fr_error *err)
{
    if (!lights)
        return 0;
    if (!cJSON_IsArray(lights))
        return fr_fail(err, "lights: expected an array");
    int i = 0;
    for (const cJSON *o = lights->child; o; o = o->next, i++) {
        char where[PATHLEN];
        snprintf(where, sizeof where, "lights[%d]", i);
        if (grouped(a, o, where, parse_light, err) < 0)
            return -1;
    }
    return 0;
}

static int environment(json_appear *a, const cJSON *env, const char *where, fr_error *err);

int json_environment(json_appear *a, const cJSON *env, fr_error *err)
{
    return env ? grouped(a, env, "environment", environment, err) : 0;
}

/* The environment object but its light_group. */
static int environment(json_appear *a, const cJSON *env, const char *where, fr_error *err)
{
    static const char *const fields[] = {"color", "strength", "rotation", NULL};
    (void)where;
    if (!cJSON_IsObject(env))
        return fr_fail(err, "environment: expected an object");
    vec3 color;
    uint32_t tex;
    float strength, rotation;
    if (jv_only_fields(env, "environment", fields, err) < 0 ||
        json_colour(a, env, "color", "environment", 1, v3s(0), &color, &tex, err) < 0 ||
        jv_number(env, "strength", "environment", 0, 1.0f, &strength, err) < 0 ||
        jv_number(env, "rotation", "environment", 0, 0.0f, &rotation, err) < 0)
        return -1;
    if (!(strength > 0.0f))
        return fr_fail(err, "environment.strength: expected a positive number");
    if (!(rotation >= -3600.0f && rotation <= 3600.0f))
        return fr_fail(err, "environment.rotation: expected degrees in [-3600, 3600]");
    fr_error e;
    return located(bld_environment(a->b, v3_scale(color, strength), tex, rotation * DEG, &e), "environment", &e,
                   err);
}
