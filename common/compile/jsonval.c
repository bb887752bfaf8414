/* jsonval.c -- typed values read out of cJSON, with the JSON path in errors
 * (see jsonval.h). */

#include "compile/jsonval.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PATHLEN 160

/* A JSON number the renderer can use: finite, and small enough that its
 * square, and sums of a few squares, stay finite in single precision. */
static int usable(const cJSON *v)
{
    return cJSON_IsNumber(v) && isfinite(v->valuedouble) && fabs(v->valuedouble) <= JV_MAX;
}

int jv_number(const cJSON *obj, const char *key, const char *where, int required, float def, float *out,
              fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        if (required)
            return fr_fail(err, "%s.%s: missing (expected a number)", where, key);
        *out = def;
        return 0;
    }
    if (!usable(v))
        return fr_fail(err, "%s.%s: expected a finite number (of magnitude at most %g)", where, key, JV_MAX);
    *out = (float)v->valuedouble;
    return 0;
}

int jv_uint(const cJSON *obj, const char *key, const char *where, int required, uint32_t def, uint32_t lo,
            uint32_t hi, uint32_t *out, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        if (required)
            return fr_fail(err, "%s.%s: missing (expected an integer in [%u, %u])", where, key, lo, hi);
        *out = def;
        return 0;
    }
    double d = v->valuedouble;
    if (!cJSON_IsNumber(v) || !(d >= lo && d <= hi) || d != floor(d))
        return fr_fail(err, "%s.%s: expected an integer in [%u, %u]", where, key, lo, hi);
    *out = (uint32_t)d;
    return 0;
}

int jv_vec3_value(const cJSON *v, const char *path, vec3 *out, fr_error *err)
{
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        return fr_fail(err, "%s: expected an array of 3 numbers", path);
    float c[3];
    for (int i = 0; i < 3; i++) {
        const cJSON *e = cJSON_GetArrayItem(v, i);
        if (!usable(e))
            return fr_fail(err, "%s[%d]: expected a finite number (of magnitude at most %g)", path, i, JV_MAX);
        c[i] = (float)e->valuedouble;
    }
    *out = v3(c[0], c[1], c[2]);
    return 0;
}

int jv_vec3(const cJSON *obj, const char *key, const char *where, int required, vec3 def, vec3 *out,
            fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        if (required)
            return fr_fail(err, "%s.%s: missing (expected [x, y, z])", where, key);
        *out = def;
        return 0;
    }
    char path[PATHLEN];
    snprintf(path, sizeof path, "%s.%s", where, key);
    return jv_vec3_value(v, path, out, err);
}

int jv_vec2(const cJSON *obj, const char *key, const char *where, vec2 def, vec2 *out, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = def;
    if (!v)
        return 0;
    if (cJSON_IsNumber(v)) {
        float x;
        if (jv_number(obj, key, where, 1, 0, &x, err) < 0)
            return -1;
        *out = (vec2){x, x};
        return 0;
    }
    const cJSON *e0 = cJSON_GetArrayItem(v, 0), *e1 = cJSON_GetArrayItem(v, 1);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2 || !usable(e0) || !usable(e1))
        return fr_fail(err, "%s.%s: expected a finite number or [u, v] (of magnitude at most %g)", where, key,
                       JV_MAX);
    *out = (vec2){(float)e0->valuedouble, (float)e1->valuedouble};
    return 0;
}

int jv_choice(const cJSON *obj, const char *key, const char *where, const char *const *choices, int def, int *out,
              fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        *out = def;
        return 0;
    }
    char list[200] = "";
    for (int i = 0; choices[i]; i++) {
        if (cJSON_IsString(v) && !strcmp(v->valuestring, choices[i])) {
            *out = i;
            return 0;
        }
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? " or " : "", choices[i]);
    }
    return fr_fail(err, "%s.%s: expected %s", where, key, list);
}

int jv_only_fields(const cJSON *obj, const char *where, const char *const *allowed, fr_error *err)
{
    for (const cJSON *m = obj->child; m; m = m->next) {
        int ok = 0;
        for (int i = 0; allowed[i] && !ok; i++)
            ok = !strcmp(m->string, allowed[i]);
        if (!ok)
            return fr_fail(err, "%s.%s: unknown field", where, m->string);
    }
    return 0;
}

int jv_member_index(const cJSON *o, const char *name)
{
    int i = 0;
    for (const cJSON *m = o ? o->child : NULL; m; m = m->next, i++)
        if (!strcmp(m->string, name))
            return i;
    return -1;
}
