/** @file fbin.h
 * The binary scene: one file a worker maps and renders from.
 *
 * Layout (little-endian, specified in common/FORMAT.md): a 64-byte header
 * with magic, version and content hash, a table of sections, then each
 * section's array of fixed-size elements, 64-byte aligned.  The content
 * hash (XXH3-64 of everything after the header) names the scene in partial
 * images and host caches.
 *
 * Every open checks the header, every section's bounds and size, the hash
 * and every index inside (vertex, material, light, BVH child, leaf block
 * and lane, tree shape and depth) before the scene is used, so a truncated
 * or corrupt file is refused with the section and byte offset at fault,
 * never a crash.
 */
#ifndef FRANJA_FBIN_H
#define FRANJA_FBIN_H

#include "error.h"
#include "scene.h"

#define FBIN_VERSION 16

/** The number of sections of the format (FORMAT.md, "Sections"). */
#define FBIN_SECTIONS 33

/** Serialize the arrays `view` points at into a new malloc'd blob (owned by
 * the caller) and compute its hash. */
int fbin_serialize(const fr_scene *view, void **blob, size_t *size, fr_error *err);

/** Write the bytes fbin_serialize would make of `view` (the same file,
 * the same hash) to `path`, section by section from the arrays `view`
 * points at, never holding them twice: atomically (file.h's file_out: a
 * temporary name, then rename).  *hash and *size: the file's. */
int fbin_write_view(const fr_scene *view, const char *path, uint64_t *hash, size_t *size, fr_error *err);

/** Validate `blob` (16-byte aligned, as malloc and mmap give) and point *out
 * into it.  On success *out owns the blob (freed or unmapped by scn_free
 * according to `mapped`); on failure the caller still owns it. */
int fbin_open_mem(void *blob, size_t size, int mapped, fr_scene *out, fr_error *err);

/** Map and validate a binary scene file.  Errors name the file. */
int fbin_load(const char *path, fr_scene *out, fr_error *err);

/** Write a scene's blob to `path` atomically (temporary name, then rename). */
int fbin_write(const fr_scene *s, const char *path, fr_error *err);

/** The header's first 32 bytes of a scene of `size` bytes into head:
 * magic, version, byte-order mark, header size, section count, size (the
 * hash and the reserved bytes are the caller's). */
void fbin_put_header(unsigned char *head, uint64_t size);

/** The 16 lowercase hex digits of a hash, NUL-terminated, into buf[17]. */
void fbin_hash_hex(uint64_t hash, char buf[17]);

#endif
