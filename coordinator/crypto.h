/** @file crypto.h
 * Cryptomatte (the open specification, version 1.1) for the
 * crypto_material render pass (common/passes.h), and the name table of
 * the material_id pass.
 *
 * A material's id is the MurmurHash3_x86_32 hash (seed 0) of its name,
 * stored as a float by uint32_to_float32 (the bits of the hash with the
 * exponent clamped to 1..254, so never a NaN, an infinity or a
 * denormal); nothing hit is 0.  The layer "ViewLayer.CryptoMaterial" (as
 * Blender names it) is written as ViewLayer.CryptoMaterial00, 01, 02 (R:
 * id, G: coverage, B: id, A: coverage of the next rank), with the metadata cryptomatte/KEY/name, hash
 * ("MurmurHash3_32"), conversion ("uint32_to_float32") and manifest (a
 * JSON object, name to the 8 hex digits of the id's float bits), KEY being
 * the first 7 hex digits of the hash of the layer's name.
 *
 * A material's name is the scene file's (the material_names section of
 * the binary scene); one without a name is called "material" and its
 * index ("material3").  The crypto_object pass (layer
 * "ViewLayer.CryptoObject") and object_id are the same with the objects'
 * names (the object_names section).
 */
#ifndef FRANJA_CRYPTO_H
#define FRANJA_CRYPTO_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "scene.h"

/** The materials' (or objects') names of a scene: n entries (0: none
 * known); one without a name is called prefix and its index (prefix NULL:
 * "material"). */
typedef struct {
    const fr_name *v;
    uint32_t n;
    const char *prefix;
} crypto_names;

/** MurmurHash3_x86_32 of len bytes at key with seed. */
uint32_t crypto_murmur3(const void *key, size_t len, uint32_t seed);

/** A hash as a Cryptomatte id (uint32_to_float32). */
float crypto_float(uint32_t hash);

/** The name of material `index` (see crypto.h) into out[64]. */
void crypto_name(const crypto_names *names, uint32_t index, char *out);

/** Turns the ids of npx pixels of the crypto_material pass (12 floats a
 * pixel: id as 1 + material index, coverage, ...) into Cryptomatte ids
 * in place (0 stays 0). */
void crypto_ids(float *pass, size_t npx, uint32_t stride, const crypto_names *names);

/** The metadata of the layer `type` ("CryptoMaterial") for materials
 * 0..n_materials-1: into attrs, 8 strings (name, value pairs for
 * iio_options.attrs) pointing into *buf, which is malloc'd (the caller
 * frees it).  -1 with err when memory runs out. */
int crypto_metadata(const char *type, const crypto_names *names, uint32_t n_materials, const char *attrs[8],
                    char **buf, fr_error *err);

/** The material_id pass's name table: a JSON array of the names, index
 * k - 1 for the pass value k, malloc'd into *out.  -1 with err when memory
 * runs out. */
int crypto_name_table(const crypto_names *names, uint32_t n_materials, char **out, fr_error *err);

#endif
