/** @file hosts.h
 * The host table: which machines render, how to reach them, how many
 * worker processes each runs.  The format is described in franja-hosts(5):
 *
 *     # name   address[:port]   user   cores   [key=value ...]
 *     alpha    10.0.0.5         anna   8       workdir=/scratch/franja
 *     beta     beta.lab:2222    -      auto    identity=~/.ssh/lab_ed25519
 *     here     local            -      auto
 *
 * `local` as the address runs workers on this machine without SSH; `-` as
 * the user means "the SSH default" (~/.ssh/config, else the login name);
 * `auto` cores means "as many as the host reports".
 */
#ifndef FRANJA_HOSTS_H
#define FRANJA_HOSTS_H

#include <stdint.h>

#include "error.h"

/** Most worker processes one host may run (cores, and franja render -j). */
#define HOSTS_MAX_CORES 4096

/** Most hosts one table may name. */
#define HOSTS_MAX_HOSTS 65536

/** The scene cache limit of a host whose line gives no cache= (10 GiB). */
#define HOSTS_CACHE_DEFAULT (10ull << 30)

/** Parses a size: decimal digits and an optional K, M, G or T (powers of
 * 1024, any case, an optional trailing B or iB: "500M", "10GiB"), at least
 * 1 and at most 2^60 bytes.  Returns -1 otherwise. */
int hosts_parse_size(const char *s, uint64_t *bytes);

/** Writes bytes as a short text into out[32]: "512 B", "6.8 KiB",
 * "12.0 MiB", "1.5 GiB" (powers of 1024, like cache=). */
void hosts_format_size(uint64_t bytes, char *out);

/** One line of the host table.  Empty strings mean "not given". */
typedef struct {
    char name[64];       /**< unique label used in messages and logs */
    char address[256];   /**< DNS name, IPv4, IPv6 (no brackets), or "local" */
    int port;            /**< TCP port, 0 = SSH default */
    char user[64];       /**< login name, "" = SSH default */
    int cores;           /**< worker processes (1..HOSTS_MAX_CORES), 0 = ask the host */
    char identity[512];  /**< private key file, "" = agent / default keys */
    char worker[512];    /**< worker path on the host, "" = WORKDIR/franja-worker */
    char workdir[512];   /**< work directory on the host, "" = .cache/franja (home-relative) */
    char arch[32];       /**< declared architecture (uname -m), "" = unknown */
    char os[64];         /**< declared operating system, "" = unknown */
    uint64_t cache;      /**< scene cache limit in bytes (cache=SIZE), 0 = HOSTS_CACHE_DEFAULT */
    int line;            /**< line number in the file, for messages */
} hosts_entry;

/** A parsed host table.  Owns `v` (hosts_free releases it). */
typedef struct {
    hosts_entry *v;
    int n;
    char path[512];      /**< the file it came from, for messages */
} hosts_table;

/** Parses `text` (NUL-terminated) as a host table named `path` in messages.
 * Fails with "path:line: what was expected" on the first bad line (a
 * name given on an earlier line is one, as is a host past
 * HOSTS_MAX_HOSTS) and on a table without hosts.  On failure *t is
 * empty. */
int hosts_parse(const char *text, const char *path, hosts_table *t, fr_error *err);

/** Reads and parses the file at `path` (see hosts_parse). */
int hosts_load(const char *path, hosts_table *t, fr_error *err);

/** Returns 1 if the entry runs workers on this machine without SSH. */
int hosts_is_local(const hosts_entry *h);

/** The work directory with its default applied. */
const char *hosts_workdir(const hosts_entry *h);

/** Frees the table's entries and zeroes *t. */
void hosts_free(hosts_table *t);

#endif
