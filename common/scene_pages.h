/** @file scene_pages.h
 * The BVH of a loaded scene in memory of large pages.
 *
 * A ray's walk reads nodes and leaf blocks scattered over the whole tree.
 * In 4 KiB pages a tree of tens of megabytes needs thousands of TLB
 * entries, so most node visits miss the TLB; the same bytes in 2 MiB pages
 * need a few dozen.  A mapped binary scene gets such pages only where the
 * page cache happens to hold large folios (which depends on the kernel and
 * on how the file was written and read), so the walk of the same tree ran
 * slower in some loads than in others
 * (tests/bench/README.md, "Large pages for the BVH").
 *
 * scn_bvh_large_pages copies the nodes and leaf blocks into private
 * anonymous memory, 2 MiB-aligned, that asks the kernel for large pages
 * (madvise MADV_HUGEPAGE, where the system has it), and points the scene's
 * `nodes` and `leaves` at the copy.  The copy has the same bytes, so
 * renders are the same bits with or without it.
 */
#ifndef FRANJA_SCENE_PAGES_H
#define FRANJA_SCENE_PAGES_H

#include <stddef.h>

#include "scene.h"

/** Trees smaller than this stay where they are: they need few pages. */
#define SCN_PAGES_MIN ((size_t)4 << 20)

/** Copies s's nodes and leaves as above when together they take at least
 * SCN_PAGES_MIN bytes and one copy per online processor (a worker per
 * core, each with its own copy) fits in an eighth of physical memory.
 * Returns 1 when copied (scn_free releases the copy), 0 when the scene is
 * left as it was: too small, too large, or no memory for it (never an
 * error: the walk is the same, only slower). */
int scn_bvh_large_pages(fr_scene *s);

/** Releases the copy (nothing when there is none); scn_free calls it. */
void scn_bvh_pages_free(fr_scene *s);

#endif
