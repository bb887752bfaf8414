/** @file jsonval.h
 * Reading typed values out of parsed JSON (cJSON) for the scene readers,
 * with one error style: the JSON path of the value and what was expected,
 * e.g. `shapes[3].radius: expected a finite number`.
 *
 * `obj` is a JSON object, `key` one of its members and `where` the object's
 * path (used in messages).  A member that is absent takes `def` unless it is
 * `required`.  Numbers must be finite and at most JV_MAX in magnitude, so
 * that squares (a radius, a length) and sums of a few of them stay finite
 * in single precision (a sphere of radius 3e38 would vanish, an emission
 * of 3e38 overflow the light's power).  Every function
 * returns 0, or -1 with *err set.  Compile time only (the scene readers and
 * the coordinator's mesh hook); nothing here allocates.
 */
#ifndef FRANJA_JSONVAL_H
#define FRANJA_JSONVAL_H

#include <stdint.h>

#include <cjson/cJSON.h>

#include "error.h"
#include "vec.h"

/** The largest magnitude a number of a scene may have. */
#define JV_MAX 1e18

/** Member `key` as a finite float. */
int jv_number(const cJSON *obj, const char *key, const char *where, int required, float def, float *out,
              fr_error *err);

/** Member `key` as an integer in [lo, hi]. */
int jv_uint(const cJSON *obj, const char *key, const char *where, int required, uint32_t def, uint32_t lo,
            uint32_t hi, uint32_t *out, fr_error *err);

/** Member `key` as [x, y, z]. */
int jv_vec3(const cJSON *obj, const char *key, const char *where, int required, vec3 def, vec3 *out,
            fr_error *err);

/** Value `v` itself (at path `path`) as [x, y, z]. */
int jv_vec3_value(const cJSON *v, const char *path, vec3 *out, fr_error *err);

/** Member `key` as a number (both components) or [u, v]; optional. */
int jv_vec2(const cJSON *obj, const char *key, const char *where, vec2 def, vec2 *out, fr_error *err);

/** Member `key` as one of the strings `choices` (NULL-terminated): *out is
 * its index; `def` when absent. */
int jv_choice(const cJSON *obj, const char *key, const char *where, const char *const *choices, int def, int *out,
              fr_error *err);

/** Refuse members of obj not in `allowed` (NULL-terminated): a typo must
 * not be silently ignored. */
int jv_only_fields(const cJSON *obj, const char *where, const char *const *allowed, fr_error *err);

/** Index of member `name` among the members of object o (NULL: none), or
 * -1 when it has none of that name. */
int jv_member_index(const cJSON *o, const char *name);

#endif
