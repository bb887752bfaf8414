/* unpack.c -- a compressed binary scene into the host's scene cache (see
 * unpack.h). */
#include "unpack.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fbin.h"
#include "file.h"

#ifdef FRANJA_NO_ZSTD

int unpack_available(void) { return 0; }

int unpack_file(const char *in, const char *out, uint64_t *hash, fr_error *err)
{
    (void)out;
    *hash = 0;
    unlink(in);
    return fr_fail(err, "%s: this worker was built without libzstd and cannot unpack scenes", in);
}

#else

#include <zstd.h>

int unpack_available(void) { return 1; }

/* Streams the frame of fd_in into fd_out; err names `in`. */
static int decompress(const char *in, int fd_in, int fd_out, fr_error *err)
{
    ZSTD_DCtx *dc = ZSTD_createDCtx();
    size_t in_cap = ZSTD_DStreamInSize(), out_cap = ZSTD_DStreamOutSize();
    char *ibuf = malloc(in_cap), *obuf = malloc(out_cap);
    int rc = 0;
    size_t left = 1;           /* ZSTD_decompressStream's hint: 0 once a frame is complete */
    if (!dc || !ibuf || !obuf)
        rc = fr_fail(err, "%s: out of memory", in);
    while (rc == 0) {
        ssize_t got = read(fd_in, ibuf, in_cap);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            rc = fr_fail(err, "%s: read error: %s", in, strerror(errno));
            break;
        }
        if (got == 0)
            break;
        if (left == 0) {
            rc = fr_fail(err, "%s: bytes after the end of the compressed scene", in);
            break;
        }
        ZSTD_inBuffer ib = {ibuf, (size_t)got, 0};
        while (rc == 0 && ib.pos < ib.size) {
            ZSTD_outBuffer ob = {obuf, out_cap, 0};
            left = ZSTD_decompressStream(dc, &ob, &ib);
            if (ZSTD_isError(left))
                rc = fr_fail(err, "%s: damaged compressed scene (%s)", in, ZSTD_getErrorName(left));
            else if (file_write_all(fd_out, obuf, ob.pos) < 0)
                rc = fr_fail(err, "%s: write error: %s", in, strerror(errno));
            else if (left == 0 && ib.pos < ib.size)
                rc = fr_fail(err, "%s: bytes after the end of the compressed scene", in);
        }
    }
    /* The rest of a frame can sit in the context's buffers: flush it. */
    while (rc == 0 && left != 0) {
        ZSTD_inBuffer ib = {ibuf, 0, 0};
        ZSTD_outBuffer ob = {obuf, out_cap, 0};
        left = ZSTD_decompressStream(dc, &ob, &ib);
        if (ZSTD_isError(left))
            rc = fr_fail(err, "%s: damaged compressed scene (%s)", in, ZSTD_getErrorName(left));
        else if (file_write_all(fd_out, obuf, ob.pos) < 0)
            rc = fr_fail(err, "%s: write error: %s", in, strerror(errno));
        else if (ob.pos == 0 && left != 0)
            rc = fr_fail(err, "%s: the compressed scene is cut short", in);
    }
    free(ibuf);
    free(obuf);
    ZSTD_freeDCtx(dc);
    return rc;
}

int unpack_file(const char *in, const char *out, uint64_t *hash, fr_error *err)
{
    *hash = 0;
    int fd_in;
    size_t size;
    if (file_open_regular(in, SIZE_MAX, &fd_in, &size, err) < 0) {
        unlink(in);
        return -1;
    }
    char tmp[4200];
    if (snprintf(tmp, sizeof tmp, "%s.part-%ld", out, (long)getpid()) >= (int)sizeof tmp) {
        close(fd_in);
        unlink(in);
        return fr_fail(err, "%s: path too long", out);
    }
    int fd_out = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_out < 0) {
        int e = errno;
        close(fd_in);
        unlink(in);
        return fr_fail(err, "%s: %s", tmp, strerror(e));
    }
    int rc = decompress(in, fd_in, fd_out, err);
    close(fd_in);
    unlink(in);
    if (close(fd_out) < 0 && rc == 0)
        rc = fr_fail(err, "%s: write error: %s", tmp, strerror(errno));
    fr_scene s;
    if (rc == 0 && fbin_load(tmp, &s, err) == 0) {
        *hash = s.hash;
        scn_free(&s);
    } else {
        rc = -1;
    }
    if (rc == 0 && rename(tmp, out) < 0)
        rc = fr_fail(err, "%s: %s", out, strerror(errno));
    if (rc < 0)
        unlink(tmp);
    return rc;
}

#endif
