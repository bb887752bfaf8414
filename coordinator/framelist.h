/** @file framelist.h
 * Frame ranges of an animation: the --frames list (which frame numbers)
 * and the file-name patterns in which a run of '#' stands for the frame
 * number, zero-padded to the run's length ("f.####.json", frame 7:
 * "f.0007.json"; a number wider than the run is written whole).
 */
#ifndef FRANJA_FRAMELIST_H
#define FRANJA_FRAMELIST_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"

/** The most frames one --frames list may name. */
#define FRAMES_MAX 100000u
/** The largest frame number. */
#define FRAMES_MAX_NUMBER 999999999u

/** Frame numbers in the order the list gives them (v[0..n), malloc'd:
 * free with framelist_free). */
typedef struct {
    uint32_t *v;
    size_t n;
} frame_list;

/** Parses a --frames value: comma-separated items, each N, A-B (A..B
 * inclusive, A <= B) or A-B:S (every S-th frame from A up to B), numbers
 * in 0..FRAMES_MAX_NUMBER, FRAMES_MAX frames at most ("1-240", "1-240:2",
 * "1,5,9", "1-3,10").  On failure writes what is wrong and where (the
 * item's byte offset) into err and returns -1, with out empty. */
int framelist_parse(const char *spec, frame_list *out, fr_error *err);

/** Frees the list and empties it. */
void framelist_free(frame_list *l);

/** Whether s holds a '#' (a frame pattern). */
int framelist_is_pattern(const char *s);

/** Writes pattern with each run of '#' replaced by frame, zero-padded to
 * the run's length, into buf[cap].  Returns -1 when it does not fit. */
int framelist_subst(const char *pattern, uint32_t frame, char *buf, size_t cap);

#endif
