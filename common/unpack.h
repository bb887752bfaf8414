/** @file unpack.h
 * A binary scene sent compressed unpacked into a host's scene cache by
 * the worker there (`franja-worker --unpack IN --scene OUT`).  The
 * coordinator packs (coordinator/transport/pack.h) in one of two forms:
 * a packed scene (FORMAT.md, "Packed scenes": a header and one zstd
 * frame of parts, each with a transform, mip levels left to the host to
 * rebuild with mip.h) for workers that advertise UNPACK_FEATURE, or one
 * plain zstd frame of the file for those that advertise only
 * PROTO_FEATURE_UNPACK.  Workers built without libzstd (a static build
 * without libzstd.a) cannot unpack, say so in `--features`, and are sent
 * scenes as they are.
 */
#ifndef FRANJA_UNPACK_H
#define FRANJA_UNPACK_H

#include <stdint.h>

#include "error.h"
#include "scene.h"

/** The `--features` word of a worker that unpacks packed scenes of
 * UNPACK_VERSION. */
#define UNPACK_FEATURE "unpack-fpak1"
/** A packed scene's first 8 bytes: `\x89FRJPAK\n`. */
#define UNPACK_MAGIC "\x89" "FRJPAK\n"
/** Layout version of packed scenes (FORMAT.md, "Packed scenes"). */
#define UNPACK_VERSION 1u
/** Sizes: header, part table entry; the most parts a packed scene has;
 * the largest scene it may announce (2^44 bytes). */
enum { UNPACK_HEADER = 48, UNPACK_ENTRY = 24, UNPACK_MAX_PARTS = 1 << 20 };
#define UNPACK_MAX_SCENE ((uint64_t)1 << 44)
/** Transforms of a part (FORMAT.md). */
enum { UNPACK_COPY = 0, UNPACK_SHUFFLE = 1, UNPACK_PREDICT = 2, UNPACK_MIP = 3, UNPACK_TRANSFORMS = 4 };

/** 1 when this build can unpack (it links libzstd), else 0. */
int unpack_available(void);

/** Where image texture t's levels lie in a scene whose texels section
 * starts at byte `texels_at` and has `texels_size` bytes: level 0's words
 * at *l0 (*l0_len bytes), then levels 1 to t->levels - 1 one after the
 * other as the compiler lays them out, at *mip (*mip_len bytes, 0 for a
 * single level).  Fails (err: what is wrong with the record) unless t is
 * an image of known format, 1 or 3 channels, sides 1 to FR_TEX_MAX_SIDE,
 * 1 to the full chain of levels laid out so, inside the section. */
int unpack_texture_ranges(const fr_texture *t, uint64_t texels_at, uint64_t texels_size, uint64_t *l0,
                          uint64_t *l0_len, uint64_t *mip, uint64_t *mip_len, fr_error *err);

/** Unpacks the packed scene or zstd file `in` (told apart by its first
 * bytes) into a new file beside `out` (OUT.part-PID), checks it as a
 * binary scene (its content hash over the whole file, as `--check`, and
 * for a packed scene the hash its header announced), renames it to `out`
 * and puts its hash in *hash.  `in` is removed in every case, and the
 * temporary file on failure.  Fails, naming the file and the byte offset
 * where one applies, on a damaged or truncated stream (zstd's checksum; a
 * packed scene's header or part table out of its rules), a scene that
 * does not check out, or a write error (a full disk).  Memory: zstd's
 * window (at most 2^27 bytes), the part table (24 bytes a part) and
 * 2 MiB; the scene is written to the file (predicted texels through a
 * shared mapping of it, through which mip levels read their level
 * above), after its size is reserved on disk. */
int unpack_file(const char *in, const char *out, uint64_t *hash, fr_error *err);

#endif
