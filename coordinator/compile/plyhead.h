/** @file plyhead.h
 * A PLY file's header against the file's size, before the mesh importer
 * reads it.
 *
 * A PLY header declares how many elements (vertices, faces ...) follow and
 * what each holds; the importer allocates for what the header declares.  A
 * header that declares more elements than the bytes after it could hold
 * (10^8 faces in a 100-byte file) is refused here, so memory stays bounded
 * by the file's size.  Each element takes at least, in ASCII, two bytes per
 * property (a digit and a separator) and, in binary, the size of each
 * scalar property and of each list's count.
 */
#ifndef FRANJA_PLYHEAD_H
#define FRANJA_PLYHEAD_H

#include <stddef.h>

#include "error.h"

/** The most header bytes plyhead_check reads. */
#define PLY_HEADER_MAX 65536

/** Checks the PLY header at the start of text[0..len) (the file's first
 * bytes, at most PLY_HEADER_MAX needed) against file_size, the whole
 * file's size.  Returns 0 when text is not a PLY header ("ply" line
 * first), when the header is one plyhead_check does not understand (left to
 * the importer), or when the declared elements fit; fails with "PATH: the
 * PLY header declares N ELEMENT elements (at least B bytes), more than the
 * M bytes after the header hold" otherwise. */
int plyhead_check(const char *path, const char *text, size_t len, size_t file_size, fr_error *err);

#endif
