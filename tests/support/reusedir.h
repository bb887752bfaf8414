/** @file reusedir.h
 * A scratch folder of a scene for the tests of an animation's reuse
 * (test_reuse.c, test_reuse_placed.c): files written into it, and a
 * frame's scene compared with the full compile of its scene.json.
 */
#ifndef FRANJA_REUSEDIR_H
#define FRANJA_REUSEDIR_H

#include <stddef.h>

#include "compile/compile.h"
#include "reuse.h"

/** Writes `text` to dir/name; on failure prints a FAIL line and exits
 * the test. */
void reusedir_put(const char *dir, const char *name, const char *text);

/** 1 when the file at `path` has the bytes of the full compile
 * (compile_child) of dir/scene.json at frame f with options co, else 0.
 * The compile goes to dir/ref.fbin, removed after. */
int reusedir_same_as_full(const char *dir, const char *path, const compile_opts *co, double f);

/** Writes `text` to dir/name as reusedir_put, with its times set to 2001
 * (a rewrite that a size and time can tell from the file before). */
void reusedir_rewrite(const char *dir, const char *name, const char *text);

/** The options of an animation's frames: timed, 24 frames per second,
 * everything else 0. */
void reusedir_opts(compile_opts *co);

/** Frame f (co->frame set to it) of dir/scene.json through reuse_compile
 * into dir/fF.fbin (its path into out, n bytes), the patch to
 * dir/scene.patch; returns reuse_compile's. */
int reusedir_frame(const char *dir, reuse_state *st, compile_opts *co, int f, char *out, size_t n,
                   reuse_result *r, fr_error *err);

/** Removes dir's files `names` (n of them) and then dir; returns 0, or
 * -1 when dir held something else. */
int reusedir_clean(const char *dir, const char *const *names, size_t n);

#endif
