/** @file note.h
 * Where the coordinator's modules send what the person running franja
 * should read.
 *
 * Nothing below main() prints: a module that has something to say (a
 * discarded slab file, a host key added to known_hosts, a damaged cached
 * scene) hands one line to a note_sink that its caller gave it, and the
 * command decides where the line goes (stderr, a log, a test's buffer).
 */
#ifndef FRANJA_NOTE_H
#define FRANJA_NOTE_H

/** A receiver of message lines.  `fn` gets one line without a trailing
 * newline and without a "franja: " prefix; the line is only valid during
 * the call.  A sink with fn NULL drops every line.  Unless a module says
 * otherwise, fn is called from the thread that called the module. */
typedef struct {
    void (*fn)(void *ctx, const char *line);
    void *ctx;
} note_sink;

/** Formats one line (printf-style, at most 1 KB) and hands it to the sink;
 * a NULL sink or one without fn drops it. */
void note_say(const note_sink *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
