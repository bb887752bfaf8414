/** @file confine.h
 * The folders a scene may read: the files a scene names (meshes, MTL
 * libraries, textures, environment maps, glTF buffers and images) are
 * opened here, and only when they lie in the scene file's own folder (or
 * below it) or in a folder the user allowed (`--allow-path DIR`).
 *
 * Scenes are downloaded: a name such as `../../etc/passwd`, an absolute
 * path or a symbolic link out of the folder would otherwise copy any file
 * the user can read into the binary scene, which is shipped to every render
 * host.  The rule is applied to the file's real path (every `..` and link
 * resolved) before anything is opened, and checked again on the opened
 * descriptor (its /proc/self/fd name), so a folder swapped for a link in
 * between is caught.  Only regular files pass: a FIFO, a device (/dev/zero)
 * or a directory is refused without blocking.  Errors start with the path
 * as the scene wrote it (joined to its folder); the caller puts the
 * reference (file and JSON path or line) in front.
 */
#ifndef FRANJA_CONFINE_H
#define FRANJA_CONFINE_H

#include <stddef.h>
#include <sys/stat.h>

#include "error.h"

/** The most folders `--allow-path` may add. */
#define CONFINE_MAX_ALLOW 16

/** Where a scene may read from: its own folder and the allowed ones, all
 * as real paths.  Filled by confine_init; holds no resources. */
typedef struct {
    char root[4096];           /**< the scene file's folder, real path ("" when it could not be resolved) */
    char root_err[256];        /**< why root is "", for the first file a scene names */
    char allow[CONFINE_MAX_ALLOW][1024]; /**< the allowed folders, real paths */
    unsigned n_allow;
} confine;

/** Sets c to the folder of the file `scene` (its directory part, "." for a
 * bare name) and the n folders `allow` (NULL when n is 0), each resolved
 * to its real path.  Fails with "DIR: --allow-path: <system error>" for an
 * allowed folder that is missing or not a directory, or more than
 * CONFINE_MAX_ALLOW of them.  A scene folder that cannot be resolved is no
 * error here: every file it names is then refused. */
int confine_init(confine *c, const char *scene, const char *const *allow, unsigned n, fr_error *err);

/** 1 when the real path `real` is the folder `dir` or lies below it (a
 * whole-component prefix: /a/bc is not below /a/b), else 0. */
int confine_below(const char *real, const char *dir);

/** Opens `path` (a name from the scene, already joined to the folder it is
 * relative to) for reading if it is a regular file of at most `max` bytes
 * inside c's folders.  *fd receives a blocking descriptor (the caller
 * closes it) and *size the file's size.  Fails, with *fd -1 and nothing
 * opened or read, with "PATH: <system error>", "PATH: outside the scene's
 * folder ROOT: a scene reads only files in its own folder (franja
 * --allow-path DIR allows another)", "PATH: not a regular file (a FIFO)"
 * (a character device, a directory ...), or "PATH: N bytes, more than the
 * M this reader takes". */
int confine_open(const confine *c, const char *path, size_t max, int *fd, size_t *size, fr_error *err);

/** From now on, in this process, every file confine_open opens is also
 * given to fn (its real path and its fstat), with `user`; fn NULL stops
 * it.  How a compile lists the files it read (compile.h: files). */
void confine_watch(void (*fn)(void *user, const char *real, const struct stat *st), void *user);

/** confine_open, then reads the whole file into a new malloc'd buffer with
 * a NUL after its *len bytes (the caller frees *data).  Also fails with
 * "PATH: read error: <system error>" or "PATH: out of memory". */
int confine_read(const confine *c, const char *path, size_t max, char **data, size_t *len, fr_error *err);

#endif
