/** @file fpatch.h
 * Scene patches: a binary scene (fbin.h) told as the sections it changes
 * in another one, for the frames of an animation whose geometry stays
 * (FORMAT.md, "Scene patches").
 *
 * A binary scene is a table of sections (fbin.h FBIN_SECTIONS) laid out one after the other
 * in id order, each at the next multiple of 64 bytes.  fpatch_sections
 * reads that table; fpatch_assemble lays sections taken from anywhere
 * out again, byte for byte as fbin_serialize would; fpatch_make says
 * which sections of one scene differ from another's and writes those
 * only, with the hashes of both; fpatch_apply and fpatch_file rebuild
 * the scene from the base it names and the patch, and check its hash.
 *
 * A patch comes over the network: fpatch_apply checks every field,
 * count and size before use, and its errors name the byte offset in the
 * patch.  Memory: the scene rebuilt (at most the base's size plus the
 * patch's) and the base mapped.
 */
#ifndef FRANJA_FPATCH_H
#define FRANJA_FPATCH_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "fbin.h"

/** The `--features` word of a worker that applies scene patches. */
#define FPATCH_FEATURE "patch-1"
/** A patch's first 8 bytes: `\x89FRJPAT\n`. */
#define FPATCH_MAGIC "\x89" "FRJPAT\n"
/** Layout version of patches (FORMAT.md, "Scene patches"). */
#define FPATCH_VERSION 1u
/** Sizes: the header; the entry before each section carried; the
 * sections of a binary scene (ids 1 to FPATCH_SECTIONS, fbin.h's; the
 * mask of carried sections holds up to 64). */
enum { FPATCH_HEADER = 64, FPATCH_ENTRY = 16, FPATCH_SECTIONS = FBIN_SECTIONS };

/** One section of a binary scene: `count` elements of `elem` bytes at
 * `data` (not owned). */
typedef struct {
    const void *data;
    uint32_t elem;
    uint64_t count;
} fpatch_sect;

/** The sections of the binary scene blob[0..size) into s[1..FPATCH_SECTIONS] (s[0]
 * unused), pointing into the blob.  The blob should have been opened
 * (fbin_open_mem); its table is checked again here all the same.  Fails,
 * naming the byte offset, on a table out of bounds. */
int fpatch_sections(const void *blob, size_t size, fpatch_sect s[FPATCH_SECTIONS + 1], fr_error *err);

/** 1 when sections a and b hold the same elements (size and bytes). */
int fpatch_same(const fpatch_sect *a, const fpatch_sect *b);

/** A new malloc'd binary scene (owned by the caller) of the sections
 * s[1..FPATCH_SECTIONS], laid out as fbin_serialize lays them out, with its content
 * hash; *size and *hash say its size and hash.  Fails on a size past
 * what size_t holds, or memory. */
int fpatch_assemble(const fpatch_sect s[FPATCH_SECTIONS + 1], void **blob, size_t *size, uint64_t *hash,
                    fr_error *err);

/** The patch that makes the scene res[0..rsize) of the scene
 * base[0..bsize) (both opened binary scenes of one format version): a new
 * malloc'd buffer *patch of *psize bytes, carrying each section of res
 * that differs from base's (in size or in a byte).  *changed gets a mask
 * of them (bit id - 1). */
int fpatch_make(const void *base, size_t bsize, const void *res, size_t rsize, void **patch, size_t *psize,
                uint64_t *changed, fr_error *err);

/** The base scene hash a patch names, read from its header (no other
 * check).  Fails when the bytes are not a patch's header. */
int fpatch_base(const void *patch, size_t psize, uint64_t *base, fr_error *err);

/** Rebuilds the scene of `patch` from `base` (an opened binary scene
 * whose hash the patch names): *out a new malloc'd blob of *osize bytes
 * (owned by the caller) whose hash the patch announced.  Fails, naming
 * the byte offset in the patch, on any header field, entry or size out
 * of its rules, a base of another hash or size, or a result of another
 * hash. */
int fpatch_apply(const void *patch, size_t psize, const void *base, size_t bsize, void **out, size_t *osize,
                 fr_error *err);

/** 1 when the file at `path` starts with FPATCH_MAGIC, else 0. */
int fpatch_is(const char *path);

/** `franja-worker --unpack` of a patch: reads the patch file `in`, maps
 * its base from the folder of `out` (HASH.fbin, as the scene caches name
 * scenes), rebuilds the scene into a new file beside `out`
 * (OUT.part-PID), opens it as a binary scene (fbin_load: every check),
 * renames it to `out` and puts its hash in *hash.  `in` is removed in
 * every case, the temporary file on failure.  Fails, naming the file and
 * the byte offset, on a patch out of its rules, a missing or damaged
 * base, a result of another hash, or a write error. */
int fpatch_file(const char *in, const char *out, uint64_t *hash, fr_error *err);

#endif
