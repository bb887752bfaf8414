/** @file json_keys.h
 * Keyframed values of JSON scenes (scenes/README.md, "Animation"): any
 * field of the camera, of a shape or of one of a mesh's `instances` may be
 * given as keys by frame instead of a value,
 *
 *     "translate": { "keys": [[1, [0, 0, 0]], [24, [5, 0, 0]]], "interpolation": "linear" }
 *
 * each key [FRAME, VALUE], VALUE a number or an array of numbers (all keys
 * of one field alike), frames strictly increasing; `interpolation` is
 * "linear" (the default: each number blended linearly between the keys
 * around the frame) or "step" (the key at or before the frame).  Before
 * the first key the first value holds, after the last the last.
 *
 * json_keys_pose replaces each keyed field, in the parsed tree, by its
 * value at a frame, before the scene reader reads it.  Errors name the
 * JSON path (`shapes[2].translate.keys[1]: ...`).  Compile time only.
 */
#ifndef FRANJA_JSON_KEYS_H
#define FRANJA_JSON_KEYS_H

#include <cjson/cJSON.h>

#include "error.h"

/** 1 when object `o` (the camera, a shape) has a keyed field, or one of
 * its `instances` does. */
int json_keys_in(const cJSON *o);

/** Replaces every keyed field of object `o` (at JSON path `where`) and of
 * its `instances` by its value at `frame`.  Returns 0, or -1 with err
 * naming the path at fault (the tree is then partly posed). */
int json_keys_pose(cJSON *o, const char *where, double frame, fr_error *err);

#endif
