/** @file quick.h
 * FRANJA_MAX_SPP: an upper bound on the samples per pixel, read from the
 * environment, for quick looks and for the test that runs the
 * documentation's examples as written (tests/it_docs.sh).  Unset, nothing
 * changes.  The partial images and the job directory record the samples
 * actually taken, so a capped render is never mistaken for a full one.
 */
#ifndef FRANJA_QUICK_H
#define FRANJA_QUICK_H

#include <stdint.h>

#include "error.h"

/** The environment variable quick_spp reads. */
#define QUICK_ENV "FRANJA_MAX_SPP"

/** Lowers *spp to FRANJA_MAX_SPP when that is set and smaller.  Returns 1
 * when *spp was lowered, 0 when not (unset, or not smaller), -1 with err
 * filled (and *spp untouched) when the variable is set but is not an
 * integer in [1, 1048576]. */
int quick_spp(uint32_t *spp, fr_error *err);

#endif
