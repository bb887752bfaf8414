/** @file budget.h
 * The compile budget: how much one compile may read and build, whatever
 * its input files declare.
 *
 * A scene file is often downloaded; a few hundred bytes of it can declare
 * billions of vertices or name the same large file many times.  Each
 * compile therefore has limits on
 *  - `read`: the bytes it reads from files in all (the scene, glTF buffers,
 *    meshes, images; each read counted, also when a file is named twice);
 *  - `vertices` and `triangles`: across all meshes of the scene, counted as
 *    the files declare them, before anything is read or allocated (a glTF
 *    accessor without a bufferView counts like any other);
 *  - `fbin`: the size of the binary scene it writes;
 *  - `cpu` (seconds) and `memory` (bytes of address space): the limits of
 *    the compiling process (RLIMIT_CPU, RLIMIT_AS; compile_child.h).
 * The defaults (BUDGET_DEFAULT_*) are far above any real asset and stop a
 * crafted file at once; `--limit NAME=VALUE` raises (or lowers) one.  A
 * refusal names the limit and the option:
 * `scene.gltf: /meshes/0/primitives/0: 201326592 vertices would pass the
 * compile's limit of 134217728 vertices (--limit vertices=N raises it)`.
 *
 * A NULL budget means no limits (unit tests and fuzzing, which bound their
 * inputs themselves).  Compile time only.
 */
#ifndef FRANJA_BUDGET_H
#define FRANJA_BUDGET_H

#include <stdint.h>

#include "error.h"

/** The limits, as indices of fr_budget's arrays. */
enum { BUDGET_READ, BUDGET_VERTICES, BUDGET_TRIANGLES, BUDGET_FBIN, BUDGET_CPU, BUDGET_MEMORY, BUDGET_N };

/** Defaults: 4 GiB read, 2^27 vertices, 2^27 triangles (a compile of that
 * many takes minutes and over 10 GiB), a 16 GiB .fbin, an hour of CPU
 * time, 32 GiB of address space. */
#define BUDGET_DEFAULT_READ ((uint64_t)4 << 30)
#define BUDGET_DEFAULT_VERTICES ((uint64_t)1 << 27)
#define BUDGET_DEFAULT_TRIANGLES ((uint64_t)1 << 27)
#define BUDGET_DEFAULT_FBIN ((uint64_t)16 << 30)
#define BUDGET_DEFAULT_CPU ((uint64_t)3600)
#define BUDGET_DEFAULT_MEMORY ((uint64_t)32 << 30)

/** A compile's limits and what it has used of each (cpu and memory are
 * not counted here: the kernel enforces them). */
typedef struct {
    uint64_t limit[BUDGET_N];
    uint64_t used[BUDGET_N];
} fr_budget;

/** The default limits, nothing used. */
void budget_init(fr_budget *b);

/** Sets one limit from "NAME=VALUE": VALUE is a whole number at least 1,
 * with an optional K, M, G or T (powers of 1024) for read, vertices,
 * triangles, fbin and memory, or s, m or h for cpu (seconds by default).
 * Fails with a message naming the names and the forms allowed. */
int budget_set(fr_budget *b, const char *spec, fr_error *err);

/** Counts n more of limit k for what is at `where` (a file, or "FILE:
 * JSON pointer"); fails without counting when the total would pass the
 * limit: "WHERE: N UNIT would pass the compile's limit of L UNIT (--limit
 * NAME=... raises it)".  A NULL budget takes anything. */
int budget_take(fr_budget *b, int k, uint64_t n, const char *where, fr_error *err);

/** budget_take of the size of file `path` (stat; nothing counted when it
 * is not a regular file: its reader then refuses it), for files a library
 * reads by name (images, Assimp meshes). */
int budget_take_file(fr_budget *b, const char *path, const char *where, fr_error *err);

#endif
