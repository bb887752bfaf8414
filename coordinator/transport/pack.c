/* pack.c -- binary scenes compressed for the trip to a host (see pack.h). */
#include "transport/pack.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zstd.h>

#include "fbin.h"
#include "file.h"

int pack_file(const char *in, const char *out, int level, uint64_t *size, fr_error *err)
{
    *size = 0;
    int fi;
    size_t len;
    if (file_open_regular(in, SIZE_MAX, &fi, &len, err) < 0)
        return -1;
    int fo = open(out, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fo < 0) {
        int e = errno;
        close(fi);
        return fr_fail(err, "%s: %s", out, strerror(e));
    }
    ZSTD_CCtx *cc = ZSTD_createCCtx();
    size_t in_cap = ZSTD_CStreamInSize(), out_cap = ZSTD_CStreamOutSize();
    char *ibuf = malloc(in_cap), *obuf = malloc(out_cap);
    int rc = 0;
    if (!cc || !ibuf || !obuf)
        rc = fr_fail(err, "%s: out of memory", in);
    if (rc == 0 && (ZSTD_isError(ZSTD_CCtx_setParameter(cc, ZSTD_c_compressionLevel, level)) ||
                    ZSTD_isError(ZSTD_CCtx_setParameter(cc, ZSTD_c_checksumFlag, 1)) ||
                    ZSTD_isError(ZSTD_CCtx_setPledgedSrcSize(cc, len))))
        rc = fr_fail(err, "%s: zstd refused level %d", in, level);
    uint64_t done = 0;
    for (int last = 0; rc == 0 && !last;) {
        ssize_t got = read(fi, ibuf, in_cap);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            rc = fr_fail(err, "%s: read error: %s", in, strerror(errno));
            break;
        }
        done += (uint64_t)got;
        last = got == 0 || done >= len;
        ZSTD_inBuffer ib = {ibuf, (size_t)got, 0};
        for (int finished = 0; rc == 0 && !finished;) {
            ZSTD_outBuffer ob = {obuf, out_cap, 0};
            size_t left = ZSTD_compressStream2(cc, &ob, &ib, last ? ZSTD_e_end : ZSTD_e_continue);
            if (ZSTD_isError(left))
                rc = fr_fail(err, "%s: zstd: %s (the file changed while it was read?)", in, ZSTD_getErrorName(left));
            else if (file_write_all(fo, obuf, ob.pos) < 0)
                rc = fr_fail(err, "%s: write error: %s", out, strerror(errno));
            else
                *size += ob.pos;
            finished = last ? left == 0 : ib.pos == ib.size;
        }
    }
    free(ibuf);
    free(obuf);
    ZSTD_freeCCtx(cc);
    close(fi);
    if (close(fo) < 0 && rc == 0)
        rc = fr_fail(err, "%s: write error: %s", out, strerror(errno));
    if (rc < 0)
        unlink(out);
    return rc;
}

/* The copies in use: few at once (one per scene being staged). */
enum { SLOTS = 16 };
static struct {
    uint64_t hash;
    int users;                 /* 0: free */
    int ready;                 /* made (users wait on `made` until then) */
    char path[4200];
    uint64_t size;
} slot[SLOTS];
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t made = PTHREAD_COND_INITIALIZER;

int pack_acquire(const char *scene, uint64_t hash, char *path, size_t cap, uint64_t *size, fr_error *err)
{
    pthread_mutex_lock(&lock);
    int i, free_i = -1;
    for (;;) {
        for (i = 0; i < SLOTS; i++)
            if (slot[i].users && slot[i].hash == hash)
                break;
        if (i == SLOTS || slot[i].ready)
            break;
        pthread_cond_wait(&made, &lock);
    }
    if (i < SLOTS) {
        slot[i].users++;
        snprintf(path, cap, "%s", slot[i].path);
        *size = slot[i].size;
        pthread_mutex_unlock(&lock);
        return 0;
    }
    for (i = 0; i < SLOTS && free_i < 0; i++)
        if (!slot[i].users)
            free_i = i;
    if (free_i < 0) {
        pthread_mutex_unlock(&lock);
        return fr_fail(err, "more than %d scenes being compressed at once", SLOTS);
    }
    i = free_i;
    const char *tmp = getenv("TMPDIR");
    char hex[17];
    fbin_hash_hex(hash, hex);
    snprintf(slot[i].path, sizeof slot[i].path, "%s/franja-%s-%ld-%d.fbin.zst", tmp && tmp[0] ? tmp : "/tmp", hex,
             (long)getpid(), i);
    slot[i].hash = hash;
    slot[i].users = 1;
    slot[i].ready = 0;
    pthread_mutex_unlock(&lock);

    /* Compressed outside the lock: hosts of other scenes go on. */
    uint64_t n;
    unlink(slot[i].path);
    int rc = pack_file(scene, slot[i].path, PACK_LEVEL, &n, err);

    pthread_mutex_lock(&lock);
    if (rc == 0) {
        slot[i].size = n;
        slot[i].ready = 1;
        snprintf(path, cap, "%s", slot[i].path);
        *size = n;
    } else {
        slot[i].users = 0;     /* waiting threads try again themselves */
    }
    pthread_cond_broadcast(&made);
    pthread_mutex_unlock(&lock);
    return rc;
}

void pack_release(uint64_t hash)
{
    pthread_mutex_lock(&lock);
    for (int i = 0; i < SLOTS; i++)
        if (slot[i].users && slot[i].ready && slot[i].hash == hash) {
            if (--slot[i].users == 0)
                unlink(slot[i].path);
            break;
        }
    pthread_mutex_unlock(&lock);
}
