/** @file compile_child.h
 * A scene compiled into a .fbin file by a child process, so that an
 * interruption stops it at once.
 *
 * Compiling a large scene takes seconds to minutes (reading meshes,
 * building the BVH, writing the file), with no point where it could look
 * at a stop request.  compile_child forks; the child compiles (compile.h)
 * and writes the binary scene into a private directory (mkdtemp, beside
 * the output, or in the current directory when the output is a device or
 * a FIFO); the parent waits, looking at the caller's stop flag ten
 * times a second.  When the flag is set (SIGINT, SIGTERM) the child is
 * killed at once.  The output appears, by a rename, only when complete
 * (a device or a FIFO, such as /dev/null or /dev/stdout, is written in
 * place then, never replaced);
 * the private directory is removed in every case but one: a caller killed
 * by SIGKILL.  The child then gets SIGKILL too (PR_SET_PDEATHSIG), so it
 * neither keeps what it inherited (a job lock) nor goes on compiling; its
 * private directory is left.  The caller must have no other threads
 * running (fork).  compile_child_sweep removes such leftovers where the
 * caller knows no other compile into the same output can be running.
 *
 * With o->files, the child also writes the files the compile read
 * through its confine.h scope (the scene, meshes, MTL files, textures,
 * glTF buffers; not those an Assimp import opens in its own process) to
 * that file, a line each: "DEV INO SIZE MTIME_S MTIME_NS REALPATH" in
 * decimal, or a line "!" for a path that holds a newline (reuse.h reads
 * it).
 *
 * The child runs within the compile's limits (budget.h): RLIMIT_CPU at the
 * cpu limit, RLIMIT_AS at what it maps when it starts plus the memory
 * limit, no core file.  Passing one fails with a message that names the
 * limit and the option that raises it.
 */
#ifndef FRANJA_COMPILE_CHILD_H
#define FRANJA_COMPILE_CHILD_H

#include <signal.h>

#include "compile/compile.h"
#include "error.h"

/** What the compile made, for a summary line. */
typedef struct {
    char hash[17];          /**< the scene hash in hex */
    unsigned long long bytes; /**< size of the .fbin */
    unsigned prims, triangles, materials, lights, nodes, leaves;
    unsigned instances, meshes; /**< placements of meshes, and the meshes they place */
    double seconds;         /**< compile time, without writing the file */
    uint64_t mesh_key;      /**< compile_opts.mesh_key's */
    uint64_t placed_key;    /**< compile_opts.placed_key's */
} compile_child_stats;

/** Compiles `scene` with options o (warnings are reported by the child
 * through o->warn) into the .fbin file `out`, replaced atomically.  stop
 * (may be NULL) is polled; once it is non-zero the compile is abandoned.
 * st (may be NULL) receives the summary.  Returns 0; -1 with err: the
 * compiler's error, "PATH: compile interrupted", "PATH: the compile used
 * its N s of CPU time (--limit cpu=SECONDS raises it)", or "PATH: the
 * compiling process died (signal N: NAME)"; the output is then untouched and nothing
 * of the attempt is left on disk. */
int compile_child(const char *scene, const compile_opts *o, const char *out, volatile sig_atomic_t *stop,
                  compile_child_stats *st, fr_error *err);

/** Removes the private directories that compiles into `out` left beside
 * it when their caller was killed (".NAME.compile-XXXXXX" next to NAME),
 * with what they hold.  Only for a caller that excludes any other compile
 * into `out` (a render holding its job directory's lock): a running
 * compile's directory would go too.  Returns the number removed. */
int compile_child_sweep(const char *out);

#endif
