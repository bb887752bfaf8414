/** @file fakehost.h
 * A transport backend for tests: hosts that live in the test process and
 * follow a script (slow, failing, lying, refusing, dying, hanging), on a
 * virtual clock.  Put &fake_backend and a fake_world in tr_options.backend
 * and .backend_ctx, and fake_now / fake_wait in sched_hooks: the scheduler
 * then runs unchanged, in virtual time, without a process or a socket.
 *
 * A fake worker reads its command line with the worker's own parser
 * (proto_parse_args) and answers with a real partial image (img_write)
 * whose pixels encode their position (fake_pixel), so a stitched image
 * shows whether every row landed in its place.
 */
#ifndef FRANJA_FAKEHOST_H
#define FRANJA_FAKEHOST_H

#include <poll.h>
#include <stddef.h>
#include <stdint.h>

#include "transport/transport_backend.h"

enum { FAKE_MAX_HOSTS = 8, FAKE_MAX_SPAWNS = 4096 };

/** How a fake worker lies (fake_script.lie). */
typedef enum {
    FAKE_TRUTH = 0,            /**< a correct partial image */
    FAKE_WRONG_ROWS,           /**< the partial of the next rows */
    FAKE_WRONG_SCENE,          /**< another scene hash in the header */
    FAKE_TRUNCATED             /**< half of the bytes, exit status 0 */
} fake_lie;

/** What one host does. */
typedef struct {
    const char *name;          /**< the host table name it answers to */
    double duration;           /**< virtual seconds a process takes (0 = 1 s) */
    double durations[16];      /**< the k-th process of the host takes durations[k] if not 0 */
    int fail_first;            /**< the first N processes exit with status 1 */
    int fail_always;           /**< every process exits with status 1 */
    fake_lie lie;              /**< every process's answer */
    int max_procs;             /**< a spawn beyond this many running is refused; 0 = no limit */
    int refuse_all;            /**< every spawn is refused */
    double die_at;             /**< the connection is lost at this virtual time; 0 = never */
    int hang;                  /**< processes never end */
} fake_script;

/** One process as the fake hosts saw it. */
typedef struct {
    int host;
    uint32_t y0, y1;
    double start;
    int killed;                /**< killed before it ended */
    int outcome;               /**< 0 running, 1 exited 0, 2 exited 1, 3 lost */
    double end;                /**< when it ended (exited, killed or lost); valid when outcome or killed */
    char scene[64];            /**< the scene path it was given (cut short) */
} fake_spawn;

/** The fake hosts and what happened to them. */
typedef struct {
    double now;                /**< the virtual clock, seconds */
    uint64_t hash;             /**< the scene hash honest partials carry */
    uint32_t width, height, spp; /**< the image partials belong to */
    int nhosts;
    fake_script host[FAKE_MAX_HOSTS];
    /* records */
    fake_spawn spawn[FAKE_MAX_SPAWNS];
    int nspawn;
    int refused[FAKE_MAX_HOSTS];  /**< spawns refused */
    int running[FAKE_MAX_HOSTS];  /**< processes running now */
    int peak[FAKE_MAX_HOSTS];     /**< most processes running at once */
    int connected[FAKE_MAX_HOSTS];
} fake_world;

extern const tr_backend fake_backend;

/** The value of pixel (x, y), channel c, in a fake partial. */
float fake_pixel(uint32_t x, uint32_t y, int c);

/** A correct partial image of rows [y0, y1) of w's image (PF bytes,
 * malloc'd into *buf; the caller frees).  -1 when out of memory. */
int fake_partial(const fake_world *w, uint32_t y0, uint32_t y1, unsigned char **buf, size_t *len);

/** sched_hooks.now: w's virtual clock (ctx is the fake_world). */
double fake_now(void *ctx);

/** sched_hooks.wait: lets ms of virtual time pass; returns 0 at once. */
int fake_wait(void *ctx, struct pollfd *pfd, int n, int ms);

#endif
