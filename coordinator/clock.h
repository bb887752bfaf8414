/** @file clock.h
 * The coordinator's one clock: seconds on the monotonic clock, for
 * time-outs, rates and durations (never for dates: its origin is
 * arbitrary).
 */
#ifndef FRANJA_CLOCK_H
#define FRANJA_CLOCK_H

/** Seconds since an arbitrary fixed point (CLOCK_MONOTONIC): differences
 * are elapsed time, unaffected by changes of the wall clock. */
double clock_now(void);

#endif
