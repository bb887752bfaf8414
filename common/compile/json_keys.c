/* json_keys.c -- keyframed values of JSON scenes (json_keys.h). */
#include "compile/json_keys.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Most numbers in one keyed value (a 4x4 matrix). */
#define KEY_MAX 16

/* Whether value v is a keyed one: an object with a "keys" member. */
static int keyed(const cJSON *v)
{
    return cJSON_IsObject(v) && cJSON_GetObjectItemCaseSensitive(v, "keys") != NULL;
}

int json_keys_in(const cJSON *o)
{
    for (const cJSON *m = cJSON_IsObject(o) ? o->child : NULL; m; m = m->next) {
        if (keyed(m))
            return 1;
        if (m->string && !strcmp(m->string, "instances") && cJSON_IsArray(m))
            for (const cJSON *i = m->child; i; i = i->next)
                if (json_keys_in(i))
                    return 1;
    }
    return 0;
}

/* Key k's value (a number, or an array of at most KEY_MAX numbers) into
 * v[*n]; *array says which.  Errors name `where`. */
static int key_value(const cJSON *val, const char *where, double *v, int *n, int *array, fr_error *err)
{
    if (cJSON_IsNumber(val)) {
        if (!isfinite(val->valuedouble))
            return fr_fail(err, "%s: expected a finite number", where);
        v[0] = val->valuedouble;
        *n = 1;
        *array = 0;
        return 0;
    }
    if (!cJSON_IsArray(val))
        return fr_fail(err, "%s: expected a number or an array of numbers", where);
    *n = 0;
    *array = 1;
    for (const cJSON *e = val->child; e; e = e->next) {
        if (*n == KEY_MAX)
            return fr_fail(err, "%s: more than %d numbers", where, KEY_MAX);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return fr_fail(err, "%s[%d]: expected a finite number", where, *n);
        v[(*n)++] = e->valuedouble;
    }
    if (*n == 0)
        return fr_fail(err, "%s: an empty array", where);
    return 0;
}

/* The value of keyed field `kv` (at `where`) at `frame`, as a new cJSON
 * value; NULL with err set. */
static cJSON *pose_one(const cJSON *kv, const char *where, double frame, fr_error *err)
{
    for (const cJSON *m = kv->child; m; m = m->next)
        if (strcmp(m->string, "keys") != 0 && strcmp(m->string, "interpolation") != 0) {
            fr_fail(err, "%s.%s: a keyed value has only keys and interpolation", where, m->string);
            return NULL;
        }
    int step = 0;
    const cJSON *ip = cJSON_GetObjectItemCaseSensitive(kv, "interpolation");
    if (ip && cJSON_IsString(ip))
        step = !strcmp(ip->valuestring, "step");
    if (ip && !(cJSON_IsString(ip) && (step || !strcmp(ip->valuestring, "linear")))) {
        fr_fail(err, "%s.interpolation: expected \"linear\" or \"step\"", where);
        return NULL;
    }
    const cJSON *keys = cJSON_GetObjectItemCaseSensitive(kv, "keys");
    if (!cJSON_IsArray(keys) || !keys->child) {
        fr_fail(err, "%s.keys: expected an array of [frame, value] keys", where);
        return NULL;
    }
    /* Every key checked; the two around the frame kept. */
    double a[KEY_MAX], b[KEY_MAX], v[KEY_MAX], fa = 0.0, fb = 0.0, prev = 0.0;
    int na = 0, array = 0, have_a = 0, have_b = 0, k = 0;
    for (const cJSON *key = keys->child; key; key = key->next, k++) {
        char at[200];
        snprintf(at, sizeof at, "%s.keys[%d]", where, k);
        if (!cJSON_IsArray(key) || cJSON_GetArraySize(key) != 2 || !cJSON_IsNumber(key->child) ||
            !isfinite(key->child->valuedouble)) {
            fr_fail(err, "%s: expected [frame, value]", at);
            return NULL;
        }
        double f = key->child->valuedouble;
        if (k > 0 && !(f > prev)) {
            fr_fail(err, "%s: frame %g is not after the key before (%g): frames must increase", at, f, prev);
            return NULL;
        }
        prev = f;
        int n = 0, arr = 0;
        char vat[210];
        snprintf(vat, sizeof vat, "%s[1]", at);
        if (key_value(key->child->next, vat, v, &n, &arr, err) < 0)
            return NULL;
        if (k > 0 && (n != na || arr != array)) {
            fr_fail(err, "%s: a value unlike the first key's", vat);
            return NULL;
        }
        na = n, array = arr;
        if (f <= frame || !have_a) {
            memcpy(a, v, sizeof a);
            fa = f;
            have_a = 1;
            have_b = 0;
        } else if (!have_b) {
            memcpy(b, v, sizeof b);
            fb = f;
            have_b = 1;
        }
    }
    /* a: the last key at or before the frame (else the first); b: the one
     * after it, when the frame lies between them. */
    if (have_b && !step && frame > fa) {
        double u = (frame - fa) / (fb - fa);
        for (int i = 0; i < na; i++)
            a[i] = (1.0 - u) * a[i] + u * b[i];
    }
    cJSON *out = array ? cJSON_CreateDoubleArray(a, na) : cJSON_CreateNumber(a[0]);
    if (!out)
        fr_fail(err, "%s: out of memory", where);
    return out;
}

int json_keys_pose(cJSON *o, const char *where, double frame, fr_error *err)
{
    if (!cJSON_IsObject(o))
        return 0;
    for (cJSON *m = o->child; m; m = m->next) {
        char at[200];
        snprintf(at, sizeof at, "%s.%s", where, m->string);
        if (keyed(m)) {
            cJSON *v = pose_one(m, at, frame, err);
            /* (the new value takes the member's name; names are unique) */
            if (!v || !cJSON_ReplaceItemInObjectCaseSensitive(o, m->string, v)) {
                cJSON_Delete(v);
                return v ? fr_fail(err, "%s: out of memory", at) : -1;
            }
            m = v;
        } else if (!strcmp(m->string, "instances") && cJSON_IsArray(m)) {
            int i = 0;
            for (cJSON *e = m->child; e; e = e->next, i++) {
                char ie[220];
                snprintf(ie, sizeof ie, "%s[%d]", at, i);
                if (json_keys_pose(e, ie, frame, err) < 0)
                    return -1;
            }
        }
    }
    return 0;
}
