/* confine.c -- the folders a scene may read (see confine.h). */
#include "compile/confine.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "file.h"

int confine_init(confine *c, const char *scene, const char *const *allow, unsigned n, fr_error *err)
{
    memset(c, 0, sizeof *c);
    char dir[4096], real[PATH_MAX];
    file_dir(scene, dir, sizeof dir);
    if (!dir[0])
        snprintf(dir, sizeof dir, "/");
    errno = 0;
    if (!realpath(dir, real) || strlen(real) >= sizeof c->root)
        snprintf(c->root_err, sizeof c->root_err, "the scene's folder %.200s: %s", dir,
                 errno ? strerror(errno) : "path too long");
    else
        snprintf(c->root, sizeof c->root, "%s", real);
    if (n > CONFINE_MAX_ALLOW)
        return fr_fail(err, "--allow-path: %u folders, more than the %d allowed", n, CONFINE_MAX_ALLOW);
    for (unsigned i = 0; i < n; i++) {
        struct stat st;
        if (!realpath(allow[i], real))
            return fr_fail(err, "%s: --allow-path: %s", allow[i], strerror(errno));
        if (stat(real, &st) < 0 || !S_ISDIR(st.st_mode))
            return fr_fail(err, "%s: --allow-path: not a directory", allow[i]);
        if (strlen(real) >= sizeof c->allow[0])
            return fr_fail(err, "%s: --allow-path: path too long", allow[i]);
        snprintf(c->allow[c->n_allow++], sizeof c->allow[0], "%s", real);
    }
    return 0;
}

int confine_below(const char *real, const char *dir)
{
    size_t n = strlen(dir);
    if (n == 1 && dir[0] == '/')
        return real[0] == '/';
    return strncmp(real, dir, n) == 0 && (real[n] == 0 || real[n] == '/');
}

static int inside(const confine *c, const char *real)
{
    if (c->root[0] && confine_below(real, c->root))
        return 1;
    for (unsigned i = 0; i < c->n_allow; i++)
        if (confine_below(real, c->allow[i]))
            return 1;
    return 0;
}

static const char *kind(mode_t m)
{
    return S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device" : S_ISBLK(m) ? "a block device"
         : S_ISDIR(m) ? "a directory" : S_ISSOCK(m) ? "a socket" : "not a plain file";
}

static int outside(const confine *c, const char *path, fr_error *err)
{
    if (!c->root[0])
        return fr_fail(err, "%s: cannot check it against %s", path, c->root_err);
    return fr_fail(err, "%s: outside the scene's folder %s: a scene reads only files in its own folder "
                   "(franja --allow-path DIR allows another)", path, c->root);
}

/* confine_watch's observer (one compile a process). */
static void (*watch_fn)(void *user, const char *real, const struct stat *st);
static void *watch_user;

void confine_watch(void (*fn)(void *user, const char *real, const struct stat *st), void *user)
{
    watch_fn = fn;
    watch_user = user;
}

int confine_open(const confine *c, const char *path, size_t max, int *fd, size_t *size, fr_error *err)
{
    *fd = -1;
    *size = 0;
    if (!c)
        return fr_fail(err, "%s: no folder is open to this reader (a scene held in memory)", path);
    char real[PATH_MAX];
    if (!realpath(path, real))
        return fr_fail(err, "%s: %s", path, strerror(errno));
    if (!inside(c, real))
        return outside(c, path, err);
    /* The real path's last component is no link: a FIFO or a device is
     * known by lstat before any open, and O_NOFOLLOW | O_NONBLOCK keep a
     * file swapped in since from being followed or blocking the open. */
    struct stat st;
    if (lstat(real, &st) < 0)
        return fr_fail(err, "%s: %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return fr_fail(err, "%s: not a regular file (%s)", path, kind(st.st_mode));
    int d = open(real, O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_NOCTTY | O_CLOEXEC);
    if (d < 0)
        return fr_fail(err, "%s: %s", path, strerror(errno));
    int rc = 0;
    if (fstat(d, &st) < 0)
        rc = fr_fail(err, "%s: %s", path, strerror(errno));
    else if (!S_ISREG(st.st_mode))
        rc = fr_fail(err, "%s: not a regular file (%s)", path, kind(st.st_mode));
    else if (st.st_size < 0 || (uintmax_t)st.st_size > max)
        rc = fr_fail(err, "%s: %jd bytes, more than the %zu this reader takes", path, (intmax_t)st.st_size, max);
    if (rc == 0) {
        /* Where the descriptor really is: a folder on the way replaced by
         * a link after realpath would show here.  Without /proc the
         * checks above stand alone. */
        char link[64], there[PATH_MAX];
        snprintf(link, sizeof link, "/proc/self/fd/%d", d);
        ssize_t k = readlink(link, there, sizeof there - 1);
        if (k > 0) {
            there[k] = 0;
            if (!inside(c, there))
                rc = outside(c, path, err);
        }
    }
    int fl = rc == 0 ? fcntl(d, F_GETFL) : -1;
    if (rc == 0 && (fl < 0 || fcntl(d, F_SETFL, fl & ~O_NONBLOCK) < 0))
        rc = fr_fail(err, "%s: %s", path, strerror(errno));
    if (rc < 0) {
        close(d);
        return -1;
    }
    *fd = d;
    *size = (size_t)st.st_size;
    if (watch_fn)
        watch_fn(watch_user, real, &st);
    return 0;
}

int confine_read(const confine *c, const char *path, size_t max, char **data, size_t *len, fr_error *err)
{
    int fd;
    size_t size;
    *data = NULL;
    *len = 0;
    if (confine_open(c, path, max, &fd, &size, err) < 0)
        return -1;
    char *buf = malloc(size + 1);
    if (!buf) {
        close(fd);
        return fr_fail(err, "%s: out of memory", path);
    }
    size_t got = 0;
    while (got < size) {
        ssize_t k = read(fd, buf + got, size - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k < 0) {
            int e = errno;
            free(buf);
            close(fd);
            return fr_fail(err, "%s: read error: %s", path, strerror(e));
        }
        if (k == 0)
            break;             /* shrank meanwhile: what is there */
        got += (size_t)k;
    }
    close(fd);
    buf[got] = 0;
    *data = buf;
    *len = got;
    return 0;
}
