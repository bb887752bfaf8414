/* imageio_load.c -- imageio.h through the plug-in franja-imageio.so
 * (imageio.cpp and OpenImageIO), loaded on first use.
 *
 * OpenImageIO brings some 250 shared libraries whose loading and symbol
 * binding take about 0.4 CPU-seconds; linked into franja, every run paid
 * them before main(), in series with the render.  Loaded here, only a run
 * that reads or writes an image format other than PFM pays, and then only
 * when it first needs one.
 *
 * The plug-in is looked for next to the running program (bin/ of a build
 * tree), in ../lib/franja/ from it (an installed tree: make install), and
 * one directory up (the test programs in bin/tests/). */
#include "imageio.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define PLUGIN "franja-imageio.so"

typedef int (*encode_fn)(const char *, const void *, iio_type, uint32_t, uint32_t, const iio_options *,
                         unsigned char **, size_t *, fr_error *);
typedef int (*read_fn)(const char *, const void *, size_t, const iio_dest *, void **, iio_type *, uint32_t *,
                       uint32_t *, uint32_t *, fr_error *);
typedef int (*read_mem_fn)(const void *, size_t, const char *, const iio_dest *, void **, iio_type *, uint32_t *,
                           uint32_t *, uint32_t *, fr_error *);
typedef int (*can_write_fn)(const char *);

static struct {
    encode_fn encode_with;
    read_fn read;
    read_mem_fn read_mem;
    can_write_fn can_write;
    char why[PATH_MAX + 300]; /* why the plug-in could not be used; "" once it is loaded */
} plug;

static pthread_once_t plug_once = PTHREAD_ONCE_INIT;

static void plug_load(void)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) {
        snprintf(plug.why, sizeof plug.why, "cannot find the running program (/proc/self/exe) to find %s next to it",
                 PLUGIN);
        return;
    }
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (slash)
        *slash = '\0';
    static const char *const where[] = {"", "../lib/franja/", "../"};
    char path[PATH_MAX + 64];
    void *h = NULL;
    for (size_t i = 0; i < sizeof where / sizeof *where && !h; i++) {
        snprintf(path, sizeof path, "%s/%s%s", exe, where[i], PLUGIN);
        if (access(path, F_OK) != 0)
            continue;
        h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!h) {
            const char *e = dlerror();
            snprintf(plug.why, sizeof plug.why, "cannot load %s", e ? e : path);
            return;
        }
    }
    if (!h) {
        snprintf(plug.why, sizeof plug.why, "%s is not installed (looked in %s, %s/../lib/franja and %s/..)", PLUGIN,
                 exe, exe, exe);
        return;
    }
    /* POSIX lets a data pointer from dlsym become a function pointer. */
    *(void **)&plug.encode_with = dlsym(h, "iio_encode_with");
    *(void **)&plug.read = dlsym(h, "iio_read");
    *(void **)&plug.read_mem = dlsym(h, "iio_read_mem");
    *(void **)&plug.can_write = dlsym(h, "iio_can_write");
    if (!plug.encode_with || !plug.read || !plug.read_mem || !plug.can_write) {
        snprintf(plug.why, sizeof plug.why, "%s is not franja's image plug-in (a function is missing)", path);
        return;
    }
    plug.why[0] = '\0';
}

/* NULL once the plug-in is loaded, else why it cannot be. */
static const char *plug_ready(void)
{
    pthread_once(&plug_once, plug_load);
    return plug.why[0] ? plug.why : NULL;
}

const char *iio_unavailable(void) { return plug_ready(); }

int iio_encode_with(const char *name, const void *pixels, iio_type type, uint32_t width, uint32_t height,
                    const iio_options *o, unsigned char **data, size_t *len, fr_error *err)
{
    *data = NULL;
    *len = 0;
    const char *why = plug_ready();
    if (why)
        return fr_fail(err, "%s: cannot encode the image: %s", name, why);
    return plug.encode_with(name, pixels, type, width, height, o, data, len, err);
}

int iio_read(const char *name, const void *data, size_t len, const iio_dest *dest, void **pixels, iio_type *type,
             uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err)
{
    *pixels = NULL;
    const char *why = plug_ready();
    if (why)
        return fr_fail(err, "%s: cannot read the image: %s", name, why);
    return plug.read(name, data, len, dest, pixels, type, width, height, channels, err);
}

int iio_read_mem(const void *data, size_t len, const char *mime, const iio_dest *dest, void **pixels,
                 iio_type *type, uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err)
{
    *pixels = NULL;
    const char *why = plug_ready();
    if (why)
        return fr_fail(err, "cannot read an embedded image: %s", why);
    return plug.read_mem(data, len, mime, dest, pixels, type, width, height, channels, err);
}

int iio_can_write(const char *path) { return plug_ready() ? 0 : plug.can_write(path); }
