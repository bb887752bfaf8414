/** @file unpack.h
 * A binary scene sent compressed (zstd) unpacked into a host's scene
 * cache by the worker there (`franja-worker --unpack IN --scene OUT`).
 * The coordinator packs (coordinator/transport/pack.h); workers built
 * without libzstd (a static build without libzstd.a) cannot unpack, say
 * so in `--features`, and are sent scenes as they are.
 */
#ifndef FRANJA_UNPACK_H
#define FRANJA_UNPACK_H

#include <stdint.h>

#include "error.h"

/** 1 when this build can unpack (it links libzstd), else 0. */
int unpack_available(void);

/** Decompresses the zstd file `in` (one frame with its checksum) into a
 * new file beside `out` (OUT.part-PID), checks it as a binary scene (its
 * content hash over the whole file, as `--check`), renames it to `out`
 * and puts its hash in *hash.  `in` is removed in every case, and the
 * temporary file on failure.  Fails, naming the file, on a damaged or
 * truncated stream (zstd's checksum), a scene that does not check out, or
 * a write error (a full disk). */
int unpack_file(const char *in, const char *out, uint64_t *hash, fr_error *err);

#endif
