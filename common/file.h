/** @file file.h
 * Whole files into memory, and the directory a file is in.
 *
 * For the readers that parse a file as one buffer (scene JSON, OBJ/MTL, host
 * tables, job directories).  Errors name the path (error.h).
 */
#ifndef FRANJA_FILE_H
#define FRANJA_FILE_H

#include <stddef.h>
#include <stdio.h>

#include "error.h"

/** Read the whole file at path into a new malloc'd buffer with a NUL after
 * its *len bytes (the file may hold NULs of its own).  The caller frees
 * *text.  Fails with "PATH: <system error>" when the file cannot be opened,
 * "PATH: read error: <system error>" or "PATH: out of memory"; *text is then
 * NULL. */
int file_read(const char *path, char **text, size_t *len, fr_error *err);

/** The same for a stream the caller opened (to word its own open error):
 * reads f to its end and closes it, whatever happens; path names it in
 * errors. */
int file_read_stream(FILE *f, const char *path, char **text, size_t *len, fr_error *err);

/** Write the directory part of path (all before its last '/') into dir[cap],
 * or "." when path has no '/', for resolving names relative to a file. */
void file_dir(const char *path, char *dir, size_t cap);

#endif
