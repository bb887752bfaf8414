/* fuzz_unpack.c -- libFuzzer target for what a worker unpacks
 * (common/unpack.h: unpack_file, `franja-worker --unpack`): a packed
 * scene (FORMAT.md, "Packed scenes") or a zstd frame, sent by a
 * coordinator over the network.
 *
 * A fuzzer cannot make a zstd frame whose checksum matches, so the first
 * byte picks the form: even, the rest is the file as it is sent; odd, the
 * rest is a packed scene's header and the content of its frame, which
 * this target compresses (with its checksum) before unpacking, so that the
 * part table and the transforms are fuzzed.  The file written is limited
 * to 16 MiB (RLIMIT_FSIZE; SIGXFSZ ignored: the write fails instead), as
 * a full disk would.  Seeds: packed scenes of the fbin seeds, in both
 * forms, made by tests/fuzz/run.sh (bin/bench/packbench -o and -O). */
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zstd.h>

#include "file.h"
#include "unpack.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], in[128], out[128];

static int setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-fuzz-unpack-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    snprintf(in, sizeof in, "%s/in", dir);
    snprintf(out, sizeof out, "%s/out.fbin", dir);
    struct rlimit rl = {16u << 20, 16u << 20};
    setrlimit(RLIMIT_FSIZE, &rl);
    signal(SIGXFSZ, SIG_IGN);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ready;
    if (!ready)
        ready = setup() == 0 ? 1 : -1;
    if (ready < 0 || size < 1)
        return 0;
    const uint8_t *body = data + 1;
    size_t n = size - 1;
    unsigned char *file = NULL;
    if (data[0] & 1) {
        /* Header as it is, then the content compressed into one frame. */
        size_t head = n < UNPACK_HEADER ? n : UNPACK_HEADER, cap = ZSTD_compressBound(n - head);
        file = malloc(head + cap);
        ZSTD_CCtx *cc = ZSTD_createCCtx();
        if (!file || !cc) {
            free(file);
            ZSTD_freeCCtx(cc);
            return 0;
        }
        memcpy(file, body, head);
        ZSTD_CCtx_setParameter(cc, ZSTD_c_compressionLevel, 1);
        ZSTD_CCtx_setParameter(cc, ZSTD_c_checksumFlag, 1);
        size_t z = ZSTD_compress2(cc, file + head, cap, body + head, n - head);
        ZSTD_freeCCtx(cc);
        if (ZSTD_isError(z)) {
            free(file);
            return 0;
        }
        body = file;
        n = head + z;
    }
    fr_error err;
    if (file_write_atomic(in, body, n, &err) == 0) {
        uint64_t hash;
        if (unpack_file(in, out, &hash, &err) == 0)
            unlink(out);
        if (access(in, F_OK) == 0 || access(out, F_OK) == 0) /* unpack_file removes what it was given */
            abort();
    }
    free(file);
    return 0;
}
