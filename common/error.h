/** @file error.h
 * How errors travel in Franja.
 *
 * A function that can fail returns an int: 0 on success, -1 on failure,
 * after writing one human-readable line into a caller-owned fr_error.  The
 * message names where the problem is (file:line, JSON path or byte offset)
 * and what was expected.  Nothing below main() prints or exits.
 */
#ifndef FRANJA_ERROR_H
#define FRANJA_ERROR_H

typedef struct { char msg[512]; } fr_error;

/** Formats the message into e (if e is not NULL) and returns -1, so a caller
 * can write `return fr_fail(e, "...", ...);`. */
int fr_fail(fr_error *e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
