/** @file jsoncheck.h
 * Strict JSON syntax, checked over the raw text before a reader parses it.
 *
 * The text must be one JSON value (RFC 8259: no comments, no trailing
 * commas, no leading zeros, no raw control characters in strings) with
 * nothing but white space after it; no object may name a member twice
 * (names compared after unescaping, so "a" and "\u0061" are the same),
 * since a reader that takes the first and ignores the second would
 * silently drop what the author wrote last; no string may hold \\u0000; and
 * values nest at most JC_MAX_DEPTH deep.  Errors name the file, the line
 * and the column (both from 1, columns counted in characters) and what was
 * expected, e.g. `scene.json:12:5: duplicate member "white" in materials
 * (first at 8:5)`.  Works on any bytes (NULs included) and allocates only
 * for the member names of the objects it is inside.
 */
#ifndef FRANJA_JSONCHECK_H
#define FRANJA_JSONCHECK_H

#include <stddef.h>

#include "error.h"

/** The deepest nesting of arrays and objects accepted. */
#define JC_MAX_DEPTH 256

/** Check `len` bytes of JSON text named `file` in messages: 0, or -1 with
 * *err set. */
int jc_check(const char *text, size_t len, const char *file, fr_error *err);

#endif
