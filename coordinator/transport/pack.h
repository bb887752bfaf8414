/** @file pack.h
 * Scenes compressed for the trip to a host: one compressed copy of a
 * binary scene per render process and form, made when the first host
 * needs it and shared by every host staged while it is in use (stage.c
 * sends it and has the host's worker unpack it, unpack.h).  Two forms:
 * a packed scene (FORMAT.md, "Packed scenes": parts with transforms, mip
 * levels left out) for workers that advertise UNPACK_FEATURE, a plain
 * zstd frame for older ones.  The scene's hash stays that of the
 * uncompressed file.
 */
#ifndef FRANJA_PACK_H
#define FRANJA_PACK_H

#include <stdint.h>

#include "error.h"

/** The zstd level scenes travel at (tests/bench/README.md, "Compressed
 * transfer" and "Packed scenes": the ratio of level 3 at several times
 * the speed of the higher levels; long-distance matching gains 0.3 %). */
#define PACK_LEVEL 3

/** Compresses the file `in` into the new file `out` (one zstd frame with
 * its content size and checksum) at `level`; *size gets the compressed
 * size.  Fails, naming the file, on a read or write error. */
int pack_file(const char *in, const char *out, int level, uint64_t *size, fr_error *err);

/** Packs the binary scene `in` into the new file `out` (FORMAT.md,
 * "Packed scenes", at zstd level `level`): prims, triangles and normals
 * byte-shuffled, 8- and 16-bit texels through the predictor of xform.h,
 * mip levels left out where mip.h rebuilds them exactly (checked here,
 * level by level), the rest as it is.  *size gets the packed size.
 * Fails, naming the file, on a scene that does not load (fbin_load) or a
 * write error.  Memory: the scene mapped, 1 MiB and zstd's context. */
int pack_scene_file(const char *in, const char *out, int level, uint64_t *size, fr_error *err);

/** The forms of pack_acquire: a plain zstd frame (pack_file), a packed
 * scene (pack_scene_file). */
enum { PACK_ZSTD = 1, PACK_PARTS = 2 };

/** A compressed copy of the scene at `scene` (content hash `hash`): made
 * in form `form` (PACK_*) in the temporary folder ($TMPDIR, else /tmp) if
 * no caller holds one of that form,
 * else shared.  path[cap] gets its name and *size its size.  Each
 * successful call must be matched by pack_release; the copy is removed
 * when its last holder releases it.  Thread-safe. */
int pack_acquire(const char *scene, uint64_t hash, int form, char *path, size_t cap, uint64_t *size,
                 fr_error *err);

/** Lets go of a copy pack_acquire gave (of the same hash and form). */
void pack_release(uint64_t hash, int form);

#endif
