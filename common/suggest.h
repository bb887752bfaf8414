/** @file suggest.h
 * "Did you mean": the known option nearest to one a person typed, for the
 * messages of franja's subcommands (coordinator/opt.c) and of
 * franja-worker (protocol.c) alike.  Pure string work: no allocation, no
 * output.
 */
#ifndef FRANJA_SUGGEST_H
#define FRANJA_SUGGEST_H

#include <stddef.h>

/** The known option nearest to typed (as written: "--samples", "--spp=0",
 * "-x"), among names[0..count) (option names without dashes: "spp", and
 * one letter for a short option: "o").  First a usual synonym from other
 * renderers' command lines ("--samples" -> "--spp", "--output" -> "-o"),
 * when names holds what it stands for; otherwise the long name fewest
 * edits away within a limit that grows with the name's length (1 edit up
 * to 3 bytes, 2 up to 6, 3 beyond).  Writes "--NAME" or "-C" to buf[cap]
 * and returns 0; -1 when nothing is near or it does not fit. */
int sug_option(const char *typed, const char *const *names, size_t count, char *buf, size_t cap);

#endif
