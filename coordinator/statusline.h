/** @file statusline.h
 * The live progress line of `franja render` on a terminal (and the plain
 * progress lines of a log): rows done, elapsed time, ETA, samples per
 * second and each host's slots and rate, cut to the terminal's width so
 * that it never wraps.
 */
#ifndef FRANJA_STATUSLINE_H
#define FRANJA_STATUSLINE_H

#include <stddef.h>

#include "sched.h"

/** The figures of one progress line. */
typedef struct {
    double elapsed_s;          /**< since the render began */
    int done, total;           /**< rows done in this run, of the rows it renders (an animation: of the
                                    frames started so far) */
    double samples_per_row;    /**< width * spp */
    int frames_done, frames;   /**< an animation: frames written or skipped, of those in the list; 0
                                    frames: a single image */
    double rows_ahead;         /**< an animation: rows of the frames not started yet, estimated (for the
                                    ETA) */
} statusline_figures;

/** Writes the line into out[cap] (always terminated): "rows D/T (P%)
 * elapsed M:SS  ETA M:SS  R Msamples/s" (an animation: "frames F/N rows
 * D/T (P%) ...", its ETA over the rows ahead too) and then the hosts ("name:running/
 * slots rate r/s", ":starting", ":down"; hosts never ready and dropped are
 * left out).  With cols > 0 it has at most cols - 1 characters: the parts
 * that do not fit are left out from the end, hosts left out are counted as
 * "+N" when that fits, and the first part is cut if even it does not fit.
 * Returns the line's length. */
size_t statusline_format(char *out, size_t cap, int cols, const statusline_figures *f, const sched_host *hosts, int nhosts);

/** The width of the terminal on fd (TIOCGWINSZ), else $COLUMNS when it is
 * a number from 10 to 1000, else 80. */
int statusline_columns(int fd);

/** Formats seconds as "S s" below a minute, "M:SS" below an hour, else
 * "H:MM:SS", into out[cap]. */
void statusline_duration(double s, char *out, size_t cap);

#endif
