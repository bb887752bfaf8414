/** @file json_microfacet.h
 * The microfacet materials of the JSON scene format (documented in
 * scenes/README.md): the types "conductor" and "principled", and a "glass"
 * with a roughness.  json_scene.c reads the members every material shares
 * (type, emission, bump ...) and the lobe types; this module checks and
 * reads the rest.
 *
 * Errors follow the scene reader's style: the JSON path and what was
 * expected, e.g. `materials.gold.roughness: expected a number in [0, 1]`.
 */
#ifndef FRANJA_JSON_MICROFACET_H
#define FRANJA_JSON_MICROFACET_H

#include <cjson/cJSON.h>

#include "compile/json_appear.h"

/** How many names json_microfacet_fields holds. */
#define SCN_MICROFACET_NFIELDS 11

/** Names of every member a microfacet material may have beyond those all
 * materials share (NULL-terminated), for the reader's list of known
 * members. */
extern const char *const json_microfacet_fields[SCN_MICROFACET_NFIELDS + 1];

/** Read the microfacet part of material object o (at path `where`) of type
 * `type` into *m (already initialized by bld_material_init and, for glass,
 * holding its tint and ior): sets m->model and its fields for "conductor",
 * "principled" and a "glass" whose roughness is not 0 (or is a texture).
 * For every other type, and for a smooth glass, refuses the members only
 * microfacet materials have.  Returns 0, or -1 with *err set. */
int json_microfacet(json_appear *a, const cJSON *o, const char *where, const char *type, fr_material *m,
                   fr_error *err);

#endif
