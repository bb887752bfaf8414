/** @file file.h
 * Whole files into memory, files written atomically, and the directory a
 * file is in.
 *
 * For the readers that parse a file as one buffer (scene JSON, OBJ/MTL, host
 * tables, job directories) and for every file Franja writes whole (binary
 * scenes, finished slabs, final images), and a check for files that
 * libraries open by name.  Inputs must be regular files: a FIFO, a device
 * (/dev/zero) or a directory, directly or through a symbolic link, is
 * refused at once instead of blocking the open or filling memory, and so
 * is a file larger than the reader's limit.  Errors name the path
 * (error.h).
 */
#ifndef FRANJA_FILE_H
#define FRANJA_FILE_H

#include <stddef.h>
#include <stdio.h>

#include "error.h"

/** The largest file file_read and file_read_stream read: 1 GiB. */
#define FILE_READ_MAX ((size_t)1 << 30)

/** Open path for reading if it is a regular file of at most max bytes: the
 * open does not block (O_NONBLOCK, so a FIFO without a writer cannot hang
 * it), then the file's type and size are checked on the open descriptor.
 * *fd receives the descriptor (the caller closes it) and *size the file's
 * size.  Fails with "PATH: <system error>", "PATH: not a regular file (a
 * FIFO)" (a character device, a directory ...) or "PATH: N bytes, more than
 * the M this reader takes"; *fd is then -1. */
int file_open_regular(const char *path, size_t max, int *fd, size_t *size, fr_error *err);

/** Writes buf[0..n) to descriptor fd whole, again after EINTR and short
 * writes.  Returns 0, or -1 with errno set by the failed write (0 when a
 * write wrote nothing). */
int file_write_all(int fd, const void *buf, size_t n);

/** Read the whole regular file at path (file_open_regular with
 * FILE_READ_MAX) into a new malloc'd buffer with a NUL after its *len bytes
 * (the file may hold NULs of its own).  The caller frees *text.  Fails with
 * file_open_regular's errors, "PATH: read error: <system error>" or "PATH:
 * out of memory"; *text is then NULL. */
int file_read(const char *path, char **text, size_t *len, fr_error *err);

/** file_read for a file of at most max bytes, which may be more than
 * FILE_READ_MAX (a partial image whose size its job bounds). */
int file_read_max(const char *path, size_t max, char **text, size_t *len, fr_error *err);

/** The same for a stream the caller opened (to word its own open error):
 * reads f to its end, at most FILE_READ_MAX bytes, and closes it, whatever
 * happens; path names it in errors. */
int file_read_stream(FILE *f, const char *path, char **text, size_t *len, fr_error *err);

/** An output file being written: a private temporary file in the target's
 * directory, which file_out_commit renames over the target, so that the
 * target is always either the old file or the complete new one.  A target
 * that is a character device or a FIFO (/dev/null, /dev/stdout, a named
 * pipe) is written in place instead, never replaced. */
typedef struct {
    int fd;                    /**< open for writing; -1 once committed or aborted */
    int direct;                /**< 1: fd is the target itself (a device or FIFO), tmp its name */
    char tmp[4400];            /**< the temporary file's name (the target's when direct) */
} file_out;

/** Creates the temporary file for path: DIR/.BASE.tmp-PID-N.EXT (it keeps
 * path's extension, for writers that choose a format by it and write by
 * name), with O_CREAT|O_EXCL|O_NOFOLLOW (never an existing file or a
 * link), mode 0666 less the umask.  Fails with "PATH: cannot create a
 * temporary file beside it: <system error>".  When path is a character
 * device or a FIFO, or a link under /dev/ or /proc/ (/dev/stdout) to one
 * or to a plain file (then truncated), it is opened for writing as it is
 * (direct); a link elsewhere is replaced, never followed.  A block device,
 * a socket or a directory is refused: "PATH: cannot write over a block
 * device". */
int file_out_open(const char *path, file_out *o, fr_error *err);

/** 1 when file_out_open(path) would write path in place (a character
 * device or FIFO, or a link under /dev/ or /proc/ to one or to a plain
 * file), else 0 (a plain target, a missing one, or one it refuses). */
int file_out_in_place(const char *path);

/** Writes all n bytes to the temporary file (short writes and EINTR
 * retried).  On failure the caller still calls file_out_abort. */
int file_out_write(file_out *o, const void *data, size_t n, fr_error *err);

/** Appends every byte of the file src to the output (read errors: "SRC:
 * <system error>"; write errors as file_out_write's).  On failure the
 * caller still calls file_out_abort. */
int file_out_copy(file_out *o, const char *src, fr_error *err);

/** Puts the file in place: fsync, close and rename over path, each
 * checked.  On failure the temporary file is removed and path untouched.
 * A direct target is only closed. */
int file_out_commit(file_out *o, const char *path, fr_error *err);

/** Closes and removes the temporary file (a direct target is only
 * closed); nothing once committed. */
void file_out_abort(file_out *o);

/** Writes data[0..len) to path atomically (open, write, commit). */
int file_write_atomic(const char *path, const void *data, size_t len, fr_error *err);

/** Write the directory part of path (all before its last '/') into dir[cap],
 * or "." when path has no '/', for resolving names relative to a file. */
void file_dir(const char *path, char *dir, size_t cap);

#endif
