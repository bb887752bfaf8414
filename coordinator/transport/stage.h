/** @file stage.h
 * Getting one host ready, written once for every backend: asking it what
 * it is, putting a scene or a worker there, and listing its scene cache.
 * Everything is done with tr_run (short commands: the worker, `sh -c` with
 * fixed scripts whose variable parts travel as arguments) and tr_upload.
 *
 * The scene cache of a host with a work directory is
 * WORKDIR/scenes/HASH.fbin.  A cached copy is trusted when the host's own
 * worker, run with `--check` on it, prints the expected content hash (the
 * worker verifies the hash of the whole file); otherwise it is uploaded
 * again and checked again.  A host without a work directory (a local one)
 * reads the scene where it is.
 *
 * Each function uses one host and may run in a thread of its own; each
 * command may take up to three times the host's time-out.
 */
#ifndef FRANJA_STAGE_H
#define FRANJA_STAGE_H

#include <stddef.h>
#include <stdint.h>

#include "protocol.h"
#include "transport/transport.h"

/** Asks the host for its architecture, OS, processor count and worker
 * version (protocol.h's probe).  Fails, saying how to install a worker,
 * when the worker cannot be run there. */
int stage_probe(tr_host *h, proto_host *info, fr_error *err);

/** A scene patch on this machine (fpatch.h): the file, and the hash of
 * the scene it patches. */
typedef struct {
    const char *path;
    uint64_t base;
} stage_patch;

/** Makes the binary scene at local_path (content hash `hash`) available on
 * the host and writes the path its worker must be given into remote[cap].
 * *sent gets the bytes sent (0: the cached copy was used).  A damaged
 * cached copy is noted (tr_options.notes) and replaced.
 *
 * Over a network link (tr_host_link_upload) to a worker that can unpack
 * (`--features`, asked in the round trip that finds no cached copy), the
 * scene travels compressed (pack.h: a packed scene, or one zstd frame to
 * a worker that only unpacks those) under a name of its own and the
 * worker unpacks it into the cache, checking its hash before it takes the
 * cache's name; a transfer that does not unpack (damaged on the way) is
 * noted and sent again, and after two such it is sent uncompressed.
 *
 * A patch (may be NULL): when the host has no copy of the scene, sends
 * over a network link to a worker that advertises FPATCH_FEATURE the
 * patch file patch->path (fpatch.h: the scene as the sections it changes
 * in the scene of hash patch->base, which the host should hold from
 * before) instead of the scene; the worker rebuilds the scene from its
 * cached base and checks its hash.  A patch that does not apply (the base
 * evicted, a damaged transfer) is noted and the scene sent as above.
 *
 * The lease: on an SSH host with a scene cache, and when lease_cap is not
 * 0, the render takes a lease on the scene before looking for it: an empty
 * file beside it, SCENE.lease-MACHINE-PID-TIME, whose path goes into
 * lease[lease_cap] ("" where there is none).  While a lease has changed
 * within the last ten minutes, stage_evict and stage_clean of any render
 * leave its scene alone, even when no worker has it mapped (between two
 * slabs or passes of a long render); so the render renews it (`touch -c`)
 * every minute or so and removes it at its end (tr_remove).  The lease of
 * a render that died goes stale in ten minutes and is then removed by the
 * next eviction or clean. */
int stage_scene(tr_host *h, const char *local_path, uint64_t hash, const stage_patch *patch, char *remote,
                size_t cap, char *lease, size_t lease_cap, uint64_t *sent, fr_error *err);

/** Checks that files reach the host's scene cache the way a render's scene
 * does (tr_upload: SFTP for an SSH host): a small file is uploaded into
 * WORKDIR/scenes, read back by a command on the host and removed.  Does
 * nothing for a host that shares this machine's files (no work directory).
 * Fails, naming the host, with the upload's or the read-back's reason. */
int stage_try_upload(tr_host *h, fr_error *err);

/** Keeps the host's scene cache within limit bytes after the scene named
 * keep (its path as stage_scene gave it) was staged: marks keep as just
 * used (its modification time), then removes the least recently used
 * scenes until the cache's scenes add up to limit or less.  Never removes
 * keep, nor a scene that a process on the host has mapped (a running
 * worker) or a live render holds a lease on (stage_scene), so the cache may
 * stay above the limit.  *removed and *bytes say
 * what went.  Nothing to do for a host without a work directory. */
int stage_evict(tr_host *h, const char *keep, uint64_t limit, int *removed, uint64_t *bytes, fr_error *err);

/** Reads what the host printed while trimming its cache (out[0..len), not
 * NUL-terminated, NULL when len is 0): a line "NAME BYTES" for each scene
 * removed.  Counts them into *removed and adds their sizes into *bytes
 * (saturating).  Fails, naming the line, on a line of any other shape. */
int stage_parse_evicted(const char *out, size_t len, int *removed, uint64_t *bytes, fr_error *err);

/** What stage_clean did on one host. */
typedef struct {
    int removed;       /**< scenes removed */
    uint64_t bytes;    /**< their size */
    int in_use;        /**< scenes kept because a process has them mapped or a render a live lease */
    int temp;          /**< stale temporary files removed */
} stage_cleaned;

/** Reads what the cache cleaning printed (out[0..len), not NUL-terminated,
 * NULL when len is 0): one line "REMOVED BYTES IN_USE TEMP" of decimal
 * numbers, counts saturating at INT_MAX and bytes at UINT64_MAX.  Fails,
 * saying what was expected, on anything else. */
int stage_parse_cleaned(const char *out, size_t len, stage_cleaned *c, fr_error *err);

/** Empties the host's scene cache: removes every scene but those a
 * process on the host has mapped (a running worker) or a live render holds
 * a lease on, and the temporary files of uploads that were cut off and the
 * leases of renders that ended without removing theirs (unchanged for ten
 * minutes). */
int stage_clean(tr_host *h, stage_cleaned *out, fr_error *err);

/** Counts the scenes in the host's cache (*files, *bytes; 0 and 0 for a
 * host without a work directory). */
int stage_cache(tr_host *h, int *files, uint64_t *bytes, fr_error *err);

/** Reads the host's cache listing (out[0..len), not NUL-terminated, NULL
 * when len is 0): the size in bytes of each scene, a line each, blanks
 * around it allowed.  Counts them into *files and adds them into *bytes
 * (saturating).  Fails, naming the line, on a line of any other shape. */
int stage_parse_cache(const char *out, size_t len, int *files, uint64_t *bytes, fr_error *err);

/** What the host's system is, found without running its worker (so it works
 * before the first `franja deploy`): arch[32] from `uname -m`, os[64] the
 * VERSION_CODENAME of its /etc/os-release ("" when there is none); control
 * characters in either are made '?' (proto_printable). */
int stage_sysinfo(tr_host *h, char *arch, char *os, fr_error *err);

/** Installs the local file at local_path on the host as WORKDIR/name,
 * executable (tr_upload), and writes its path into remote[cap].  Fails for
 * a host without a work directory: it runs this machine's files. */
int stage_install(tr_host *h, const char *local_path, const char *name, char *remote, size_t cap,
                  fr_error *err);

/** Copies the VERSION_CODENAME of an os-release text (NUL-terminated) into
 * os[64], without quotes, control characters made '?' (proto_printable);
 * "" if it has none. */
void stage_os_codename(const char *os_release, char *os);

#endif
