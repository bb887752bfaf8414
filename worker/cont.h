/** @file cont.h
 * `franja-worker --continue FILE`: the sample sums of an earlier render of
 * the same slab with fewer samples (a PF partial written with --sums), so
 * that only the samples it lacks are rendered and the result has the bits
 * of a render of every sample at once.
 */
#ifndef FRANJA_CONT_H
#define FRANJA_CONT_H

#include <stdint.h>

#include "error.h"
#include "scene.h"

/** Reads path, a partial that must check out (image.h) and be rows
 * [y0, y1) of scene sc at sc's size, with sums and at most sc's samples
 * per pixel; copies its sums into sums (width*(y1-y0)*3 doubles, the
 * caller's) and its samples per pixel into *first.  Fails naming path and
 * what differs. */
int cont_load(const char *path, const fr_scene *sc, uint32_t y0, uint32_t y1, double *sums, uint32_t *first,
              fr_error *err);

#endif
