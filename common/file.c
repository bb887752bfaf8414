/* file.c -- whole files into memory, and written atomically (see file.h). */
#include "file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind(mode_t m)
{
    return S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device" : S_ISBLK(m) ? "a block device"
         : S_ISDIR(m) ? "a directory" : S_ISSOCK(m) ? "a socket" : "not a plain file";
}

int file_open_regular(const char *path, size_t max, int *fd, size_t *size, fr_error *err)
{
    *fd = -1;
    *size = 0;
    int d = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (d < 0)
        return fr_fail(err, "%s: %s", path, strerror(errno));
    struct stat st;
    if (fstat(d, &st) < 0) {
        int e = errno;
        close(d);
        return fr_fail(err, "%s: %s", path, strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        close(d);
        return fr_fail(err, "%s: not a regular file (%s)", path, kind(st.st_mode));
    }
    if (st.st_size < 0 || (uintmax_t)st.st_size > max) {
        close(d);
        return fr_fail(err, "%s: %jd bytes, more than the %zu this reader takes", path, (intmax_t)st.st_size, max);
    }
    *fd = d;
    *size = (size_t)st.st_size;
    return 0;
}

int file_write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n > 0) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            if (k == 0)
                errno = 0;
            return -1;
        }
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

static int read_stream(FILE *f, const char *path, size_t max, char **text, size_t *len, fr_error *err);

int file_read(const char *path, char **text, size_t *len, fr_error *err)
{
    return file_read_max(path, FILE_READ_MAX, text, len, err);
}

int file_read_max(const char *path, size_t max, char **text, size_t *len, fr_error *err)
{
    int fd;
    size_t size;
    *text = NULL;
    *len = 0;
    if (file_open_regular(path, max, &fd, &size, err) < 0)
        return -1;
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        int e = errno;
        close(fd);
        return fr_fail(err, "%s: %s", path, strerror(e));
    }
    return read_stream(f, path, max, text, len, err);
}

/* file_read_stream with a limit of max bytes. */
static int read_stream(FILE *f, const char *path, size_t max, char **text, size_t *len, fr_error *err)
{
    *text = NULL;
    *len = 0;
    /* A regular file's size is known: room for it, its NUL, and one byte
     * more so that the read that finds the end needs no bigger buffer.  A
     * pipe or a /proc file (size 0) grows as it is read, up to one byte
     * past the limit (which shows that the limit was passed). */
    struct stat st;
    size_t cap = 4096, top = max + 2;
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && (uintmax_t)st.st_size + 2 > cap)
        cap = (uintmax_t)st.st_size + 2 < top ? (size_t)st.st_size + 2 : top;
    size_t n = 0;
    char *buf = malloc(cap);
    while (buf && n <= max) {
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0)
            break;
        if (n + 1 == cap && cap < top) {
            size_t bigger_cap = cap < top / 2 ? cap * 2 : top;
            char *bigger = realloc(buf, bigger_cap);
            if (!bigger)
                free(buf);
            buf = bigger;
            cap = bigger_cap;
        }
    }
    int bad = ferror(f), why = errno;
    fclose(f);
    if (!buf)
        return fr_fail(err, "%s: out of memory", path);
    if (n > max) {
        free(buf);
        return fr_fail(err, "%s: more than the %zu bytes this reader takes", path, max);
    }
    if (bad) {
        free(buf);
        return fr_fail(err, "%s: read error: %s", path, strerror(why));
    }
    buf[n] = 0;
    *text = buf;
    *len = n;
    return 0;
}

int file_read_stream(FILE *f, const char *path, char **text, size_t *len, fr_error *err)
{
    return read_stream(f, path, FILE_READ_MAX, text, len, err);
}

void file_dir(const char *path, char *dir, size_t cap)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, cap, ".");
    else
        snprintf(dir, cap, "%.*s", (int)(slash - path), path);
}

/* A target that is not a file to replace: a character device or a FIFO
 * (itself, or through a system link such as /dev/stdout) is opened as it
 * is, with *flags; 1 when so, 0 for a plain target, -1 (err set) when
 * refused. */
static int direct_kind(const char *path, int *flags, fr_error *err)
{
    struct stat ls, st;
    if (lstat(path, &ls))
        return 0;
    *flags = O_WRONLY | O_CLOEXEC;
    if (S_ISLNK(ls.st_mode)) {
        if (strncmp(path, "/dev/", 5) && strncmp(path, "/proc/", 6))
            return 0; /* a link elsewhere is replaced, never followed */
        /* /dev/stdout and its kind: what the link reaches is written,
         * a plain file from its start, as a shell's > would. */
        if (stat(path, &st))
            return fr_fail(err, "%s: %s", path, strerror(errno));
        if (S_ISREG(st.st_mode))
            *flags |= O_TRUNC;
        else if (!S_ISCHR(st.st_mode) && !S_ISFIFO(st.st_mode))
            return fr_fail(err, "%s: cannot write over %s", path, kind(st.st_mode));
    } else if (S_ISREG(ls.st_mode)) {
        return 0;
    } else if (!S_ISCHR(ls.st_mode) && !S_ISFIFO(ls.st_mode)) {
        return fr_fail(err, "%s: cannot write over %s", path, kind(ls.st_mode));
    }
    return 1;
}

int file_out_in_place(const char *path)
{
    int flags;
    fr_error e;
    return direct_kind(path, &flags, &e) == 1;
}

static int out_direct(const char *path, file_out *o, fr_error *err)
{
    int flags, d = direct_kind(path, &flags, err);
    if (d <= 0)
        return d;
    if (snprintf(o->tmp, sizeof o->tmp, "%s", path) >= (int)sizeof o->tmp)
        return fr_fail(err, "%s: path too long", path);
    o->fd = open(path, flags);
    if (o->fd < 0) {
        int e = errno;
        o->tmp[0] = 0;
        return fr_fail(err, "%s: %s", path, strerror(e));
    }
    o->direct = 1;
    return 1;
}

int file_out_open(const char *path, file_out *o, fr_error *err)
{
    static unsigned counter;
    o->fd = -1;
    o->direct = 0;
    o->tmp[0] = 0;
    int d = out_direct(path, o, err);
    if (d)
        return d < 0 ? -1 : 0;
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path + 1) : 0;
    const char *base = path + dirlen;
    const char *dot = strrchr(base, '.');
    const char *ext = dot && dot != base ? dot : "";
    for (int tries = 0; tries < 100; tries++) {
        unsigned n = __atomic_fetch_add(&counter, 1, __ATOMIC_RELAXED);
        if (snprintf(o->tmp, sizeof o->tmp, "%.*s.%s.tmp-%ld-%u%s", dirlen, path, base, (long)getpid(), n, ext) >=
            (int)sizeof o->tmp)
            return fr_fail(err, "%s: path too long", path);
        o->fd = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (o->fd >= 0)
            return 0;
        if (errno != EEXIST)
            break;
    }
    int e = errno;
    fr_fail(err, "%s: cannot create a temporary file beside it: %s", path, strerror(e));
    o->tmp[0] = 0;
    return -1;
}

int file_out_write(file_out *o, const void *data, size_t n, fr_error *err)
{
    const char *p = data;
    while (n) {
        ssize_t k = write(o->fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return fr_fail(err, "%s: write failed: %s", o->tmp, k < 0 ? strerror(errno) : "no progress");
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

int file_out_copy(file_out *o, const char *src, fr_error *err)
{
    int in = open(src, O_RDONLY | O_CLOEXEC);
    if (in < 0)
        return fr_fail(err, "%s: %s", src, strerror(errno));
    char buf[1 << 16];
    ssize_t n;
    int rc = 0;
    while (!rc && (n = read(in, buf, sizeof buf)) != 0)
        if (n < 0)
            rc = errno == EINTR ? 0 : fr_fail(err, "%s: %s", src, strerror(errno));
        else
            rc = file_out_write(o, buf, (size_t)n, err);
    close(in);
    return rc;
}

int file_out_commit(file_out *o, const char *path, fr_error *err)
{
    int rc = 0;
    if (o->direct) {
        if (close(o->fd))
            rc = fr_fail(err, "%s: close failed: %s", path, strerror(errno));
        o->fd = -1;
        o->tmp[0] = 0;
        return rc;
    }
    if (fsync(o->fd))
        rc = fr_fail(err, "%s: fsync failed: %s", o->tmp, strerror(errno));
    if (close(o->fd) && rc == 0)
        rc = fr_fail(err, "%s: close failed: %s", o->tmp, strerror(errno));
    o->fd = -1;
    if (rc == 0 && rename(o->tmp, path))
        rc = fr_fail(err, "%s: %s", path, strerror(errno));
    if (rc)
        unlink(o->tmp);
    o->tmp[0] = 0;
    return rc;
}

void file_out_abort(file_out *o)
{
    if (o->fd >= 0)
        close(o->fd);
    if (o->tmp[0] && !o->direct)
        unlink(o->tmp);
    o->fd = -1;
    o->tmp[0] = 0;
}

int file_write_atomic(const char *path, const void *data, size_t len, fr_error *err)
{
    file_out o;
    if (file_out_open(path, &o, err))
        return -1;
    if (file_out_write(&o, data, len, err)) {
        file_out_abort(&o);
        return -1;
    }
    return file_out_commit(&o, path, err);
}
