/** @file error.h
 * How errors travel in Franja.
 *
 * A function that can fail returns an int: 0 on success, -1 on failure,
 * after writing one human-readable line into a caller-owned fr_error.  The
 * message names where the problem is (file:line, JSON path or byte offset)
 * and what was expected.  Nothing below main() prints or exits.
 *
 * Messages may carry names and words from input files, so every message
 * is made safe for a terminal: control characters (C0, DEL and the C1
 * range in its UTF-8 form) are written as \\xHH, never raw.
 */
#ifndef FRANJA_ERROR_H
#define FRANJA_ERROR_H

#include <stddef.h>

typedef struct { char msg[512]; } fr_error;

/** Formats the message into e (if e is not NULL), escapes it
 * (fr_escape_controls) and returns -1, so a caller can write
 * `return fr_fail(e, "...", ...);`. */
int fr_fail(fr_error *e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/** Rewrites the NUL-terminated string s (in a buffer of cap bytes) with
 * each control character as the four characters \\xHH: bytes 0x01-0x1f,
 * 0x7f, and the UTF-8 forms of U+0080-U+009F.  An escape that no longer
 * fits ends the string (the text is cut, never left raw).  Every other
 * byte, backslashes included, stays as it is, so escaping twice changes
 * nothing. */
void fr_escape_controls(char *s, size_t cap);

#endif
