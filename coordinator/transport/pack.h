/** @file pack.h
 * Scenes compressed for the trip to a host: one zstd copy of a binary
 * scene per render process, made when the first host needs it and shared
 * by every host staged while it is in use (stage.c sends it and has the
 * host's worker unpack it, unpack.h).  The scene's hash stays that of the
 * uncompressed file.
 */
#ifndef FRANJA_PACK_H
#define FRANJA_PACK_H

#include <stdint.h>

#include "error.h"

/** The zstd level scenes travel at (tests/bench/README.md, "Compressed
 * transfer": the ratio of level 3 at several times the speed of the
 * higher levels). */
#define PACK_LEVEL 3

/** Compresses the file `in` into the new file `out` (one zstd frame with
 * its content size and checksum) at `level`; *size gets the compressed
 * size.  Fails, naming the file, on a read or write error. */
int pack_file(const char *in, const char *out, int level, uint64_t *size, fr_error *err);

/** A compressed copy of the scene at `scene` (content hash `hash`): made
 * in the temporary folder ($TMPDIR, else /tmp) if no caller holds one,
 * else shared.  path[cap] gets its name and *size its size.  Each
 * successful call must be matched by pack_release; the copy is removed
 * when its last holder releases it.  Thread-safe. */
int pack_acquire(const char *scene, uint64_t hash, char *path, size_t cap, uint64_t *size, fr_error *err);

/** Lets go of a copy pack_acquire gave. */
void pack_release(uint64_t hash);

#endif
