/* test_sched.c -- the scheduler's policy, with fake hosts on a virtual
 * clock (tests/support/fakehost.h): every row lands once in its place,
 * stragglers get a second copy (the oldest first, on another host), a host
 * that keeps failing is dropped after max_host_failures, a host that
 * refuses channels keeps the slots it runs, a failed slab is retried on
 * another host, a lost host's slabs go elsewhere without counting as
 * failures, lying partials are refused, --resume renders only what is
 * missing, and a slab that fails everywhere ends the run with the rows
 * named; the frames of an animation run as one stream of slabs, frame 2
 * starting while frame 1's last slab runs. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "sched.h"
#include "fakehost.h"

enum { W = 8, MAX_EVENTS = 4096, MAX_FRAMES = 4 };

typedef struct {
    sched_event_kind kind;
    int host;
    uint32_t y0, y1;
    double t;
    char text[300];
} event;

/* Everything one run needs; `world` first, so that the hooks' ctx is also
 * the fake_world that fake_now and fake_wait expect. */
typedef struct {
    fake_world world;
    event ev[MAX_EVENTS];
    int nev;
    int stop_after_done;       /* set *stop after this many accepted slabs (0 = never) */
    volatile sig_atomic_t stop;
    char jobdir[64];
    tr_host *tr[FAKE_MAX_HOSTS];
    sched_host sh[FAKE_MAX_HOSTS];
    sched_params p;
    sched_stats st;
    fr_error err;
    int rc;
    /* frames after the first (test_frames_*) */
    int nframes;               /* frames in all, the first included */
    char fjob[MAX_FRAMES][64]; /* their job directories (fjob[0] is jobdir) */
    int staged[MAX_FRAMES][FAKE_MAX_HOSTS];
    int done[MAX_FRAMES];      /* the order in which frame_done came, 1 based; 0 = not done */
    double done_t[MAX_FRAMES];
    int ndone;
    char label[MAX_FRAMES][16];
} run;

static void on_event(void *ctx, const sched_event *e)
{
    run *r = ctx;
    if (r->nev < MAX_EVENTS) {
        event *v = &r->ev[r->nev++];
        *v = (event){e->kind, e->host, e->y0, e->y1, e->t, ""};
        snprintf(v->text, sizeof v->text, "%s", e->text);
    }
    if (e->kind == SCHED_SLAB_DONE && r->stop_after_done && --r->stop_after_done == 0)
        r->stop = 1;
}

static run *setup(int height, int slab_rows)
{
    run *r = calloc(1, sizeof *r);
    if (!r) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    r->world.hash = 0x1234abcd5678ef90ull;
    r->world.width = W;
    r->world.height = (uint32_t)height;
    r->world.spp = 4;
    snprintf(r->jobdir, sizeof r->jobdir, "/tmp/franja-sched.XXXXXX");
    if (!mkdtemp(r->jobdir)) {
        perror("mkdtemp");
        exit(1);
    }
    r->p = (sched_params){.spec = {r->world.hash, W, (uint32_t)height, 4},
                          .jobdir = r->jobdir,
                          .slab_rows = slab_rows,
                          .max_attempts = 5,
                          .max_host_failures = 3,
                          .stop = &r->stop,
                          .hooks = {.event = on_event, .now = fake_now, .wait = fake_wait, .ctx = r}};
    return r;
}

/* Adds a fake host with `slots` worker slots; returns its index. */
static int host(run *r, const char *name, int slots, fake_script s)
{
    int i = r->world.nhosts++;
    s.name = name;
    r->world.host[i] = s;
    r->sh[i].name = name;
    r->sh[i].slots = slots;
    snprintf(r->sh[i].scene, sizeof r->sh[i].scene, "scene.fbin");
    return i;
}

/* Connects the hosts and runs the scheduler. */
static void go(run *r)
{
    tr_options o = {.backend = &fake_backend, .backend_ctx = &r->world, .timeout_s = 10};
    for (int i = 0; i < r->world.nhosts; i++) {
        hosts_entry e;
        memset(&e, 0, sizeof e);
        snprintf(e.name, sizeof e.name, "%s", r->world.host[i].name);
        fr_error err;
        if (tr_connect(&e, &o, &r->tr[i], &err)) {
            fprintf(stderr, "connect: %s\n", err.msg);
            exit(1);
        }
        r->sh[i].tr = r->tr[i];
    }
    fr_error err;
    if (job_open(r->jobdir, &r->p.spec, r->p.have != NULL, &err)) {
        fprintf(stderr, "job_open: %s\n", err.msg);
        exit(1);
    }
    r->rc = sched_run(&r->p, r->sh, r->world.nhosts, &r->st, &r->err);
}

/* Every row of the job directory holds the fake pixels of that row. */
static int stitched_ok(run *r)
{
    size_t n = (size_t)W * r->world.height * 3;
    float *rgb = malloc(n * sizeof *rgb);
    fr_error err;
    int ok = rgb && job_stitch(r->jobdir, &r->p.spec, rgb, NULL, &err) == 0;
    for (uint32_t y = 0; ok && y < r->world.height; y++)
        for (uint32_t x = 0; ok && x < W; x++)
            ok = rgb[((size_t)y * W + x) * 3 + 2] == fake_pixel(x, y, 2);
    free(rgb);
    return ok;
}

static void teardown(run *r)
{
    for (int i = 0; i < r->world.nhosts; i++) {
        CHECK(r->world.running[i] == 0, "host %s still runs %d processes after sched_run", r->world.host[i].name,
              r->world.running[i]);
        tr_close(r->tr[i]);
    }
    job_remove(r->jobdir);
    free(r);
}

static int count(const run *r, sched_event_kind kind, int host)
{
    int n = 0;
    for (int i = 0; i < r->nev; i++)
        n += r->ev[i].kind == kind && (host < 0 || r->ev[i].host == host);
    return n;
}

static const event *first(const run *r, sched_event_kind kind)
{
    for (int i = 0; i < r->nev; i++)
        if (r->ev[i].kind == kind)
            return &r->ev[i];
    return NULL;
}

/* The host that delivered rows [y0, y1), or -1. */
static int done_by(const run *r, uint32_t y0, uint32_t y1)
{
    for (int i = 0; i < r->nev; i++)
        if (r->ev[i].kind == SCHED_SLAB_DONE && r->ev[i].y0 == y0 && r->ev[i].y1 == y1)
            return r->ev[i].host;
    return -1;
}

/* Two equal hosts: every row arrives once, in its place. */
static void test_plain(void)
{
    run *r = setup(16, 2);
    host(r, "a", 2, (fake_script){0});
    host(r, "b", 2, (fake_script){0});
    go(r);
    CHECK(r->rc == 0, "plain run failed: %s", r->err.msg);
    CHECK(r->st.slabs == 8, "%d slabs, expected 8", r->st.slabs);
    CHECK(count(r, SCHED_SLAB_DONE, -1) == 8, "%d slabs accepted, expected 8", count(r, SCHED_SLAB_DONE, -1));
    CHECK(r->st.retries == 0, "%d retries", r->st.retries);
    CHECK(r->sh[0].rows + r->sh[1].rows == 16, "rows %d + %d", r->sh[0].rows, r->sh[1].rows);
    CHECK(r->sh[0].slabs > 0 && r->sh[1].slabs > 0, "one host did nothing (%d, %d)", r->sh[0].slabs, r->sh[1].slabs);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* Without --slab-rows, slabs shrink toward the end: each is the rows left
 * over twice the slots (ceiling), at least a sixteenth of the rows per
 * slot; 64 rows over 2 slots: 16 12 9 7 5 4 3 2 2 2 2. */
static void test_guided(void)
{
    run *r = setup(64, 0);
    host(r, "a", 1, (fake_script){0});
    host(r, "b", 1, (fake_script){0});
    go(r);
    CHECK(r->rc == 0, "guided run failed: %s", r->err.msg);
    static const uint32_t want[] = {16, 12, 9, 7, 5, 4, 3, 2, 2, 2, 2};
    CHECK(r->st.slabs == 11, "%d slabs, expected 11", r->st.slabs);
    uint32_t y = 0;
    for (int k = 0; k < 11; k++) {
        int found = 0;
        for (int i = 0; i < r->nev; i++)
            if (r->ev[i].kind == SCHED_SLAB_DONE && r->ev[i].y0 == y) {
                CHECK(r->ev[i].y1 - y == want[k], "slab %d at row %u: %u rows, expected %u", k, y, r->ev[i].y1 - y,
                      want[k]);
                y = r->ev[i].y1;
                found = 1;
                break;
            }
        CHECK(found, "no slab starts at row %u", y);
        if (!found)
            break;
    }
    CHECK(y == 64, "the slabs end at row %u", y);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* One slow slab on a, one started later on a: once the queue is empty, b
 * copies the one that has run longest, and its copy wins. */
static void test_straggler(void)
{
    run *r = setup(6, 1);
    int a = host(r, "a", 2, (fake_script){.duration = 100, .durations = {100, 2, 100}});
    int b = host(r, "b", 1, (fake_script){.duration = 1});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    const event *c = first(r, SCHED_COPY);
    CHECK(c != NULL, "no second copy started");
    if (c) {
        CHECK(c->host == b, "first copy on host %d, expected b", c->host);
        CHECK(c->y0 == 0 && c->y1 == 1, "first copy of rows %u:%u, expected the oldest, 0:1", c->y0, c->y1);
    }
    CHECK(done_by(r, 0, 1) == b, "rows 0:1 delivered by host %d, expected b", done_by(r, 0, 1));
    CHECK(r->world.spawn[0].host == a && r->world.spawn[0].killed, "a's slow copy of rows 0:1 was not killed");
    CHECK(r->st.wall_s < 20, "took %.1f virtual seconds: the slow copies were waited for", r->st.wall_s);
    CHECK(r->sh[a].slabs == 1, "a delivered %d slabs, expected only its quick one", r->sh[a].slabs);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* A host whose every worker fails is dropped after three failures in a
 * row; the other host renders everything. */
static void test_drop_failing_host(void)
{
    run *r = setup(16, 2);
    int a = host(r, "a", 1, (fake_script){.fail_always = 1});
    int b = host(r, "b", 1, (fake_script){0});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->sh[a].dropped, "the failing host was not dropped");
    CHECK(count(r, SCHED_SLAB_FAILED, a) == 3, "%d failures on a before the drop, expected 3",
          count(r, SCHED_SLAB_FAILED, a));
    const event *d = first(r, SCHED_HOST_DROPPED);
    CHECK(d && d->host == a && strstr(d->text, "3 failures in a row"), "drop event: %s", d ? d->text : "(none)");
    CHECK(r->sh[b].rows == 16, "b rendered %d rows, expected all 16", r->sh[b].rows);
    CHECK(r->st.retries == 3, "%d retries, expected 3", r->st.retries);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* A host that opens only two channels keeps two slots, with a message,
 * and never runs more. */
static void test_shrink_slots(void)
{
    run *r = setup(24, 1);
    int a = host(r, "a", 5, (fake_script){.max_procs = 2});
    host(r, "b", 1, (fake_script){0});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->sh[a].slots == 2, "a has %d slots, expected 2", r->sh[a].slots);
    CHECK(!r->sh[a].dropped, "a was dropped");
    CHECK(count(r, SCHED_HOST_SHRUNK, a) == 1, "%d shrink events", count(r, SCHED_HOST_SHRUNK, a));
    CHECK(r->world.peak[a] == 2, "a ran %d processes at once", r->world.peak[a]);
    CHECK(r->world.refused[a] == 1, "a refused %d spawns, expected one", r->world.refused[a]);
    CHECK(r->sh[a].slabs > 0, "a delivered nothing");
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* A host that refuses every channel is tried again later, then dropped. */
static void test_refusing_host(void)
{
    run *r = setup(8, 2);
    int a = host(r, "a", 2, (fake_script){.refuse_all = 1});
    int b = host(r, "b", 1, (fake_script){0});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->sh[a].dropped, "the refusing host was not dropped");
    CHECK(count(r, SCHED_HOST_RETRY, a) == 2, "%d retries announced, expected 2", count(r, SCHED_HOST_RETRY, a));
    CHECK(r->world.refused[a] == 3, "a was asked %d times, expected 3", r->world.refused[a]);
    CHECK(r->sh[b].rows == 8, "b rendered %d rows", r->sh[b].rows);
    teardown(r);
}

/* A slab that failed on a goes to b, even though a is free first. */
static void test_retry_elsewhere(void)
{
    run *r = setup(8, 1);
    int a = host(r, "a", 1, (fake_script){.fail_first = 1, .duration = 1});
    int b = host(r, "b", 1, (fake_script){.duration = 1});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    const fake_spawn *s0 = &r->world.spawn[0];
    CHECK(s0->host == a && s0->outcome == 2, "the first process was not a's failing one");
    int again = -1;
    for (int i = 1; i < r->world.nspawn; i++)
        if (r->world.spawn[i].y0 == s0->y0) {
            again = r->world.spawn[i].host;
            break;
        }
    CHECK(again == b, "rows %u:%u were retried on host %d, expected b", s0->y0, s0->y1, again);
    CHECK(done_by(r, s0->y0, s0->y1) == b, "rows %u:%u delivered by host %d", s0->y0, s0->y1,
          done_by(r, s0->y0, s0->y1));
    CHECK(!r->sh[a].dropped, "a was dropped for one failure");
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* With one host, a failed slab is retried there. */
static void test_retry_same_host_when_alone(void)
{
    run *r = setup(4, 2);
    host(r, "a", 1, (fake_script){.fail_first = 1});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->st.retries == 1, "%d retries", r->st.retries);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* Partials that do not check out are refused, and a host that only lies
 * is dropped; every kind of lie is caught. */
static void test_lying_host(void)
{
    const fake_lie lies[] = {FAKE_WRONG_ROWS, FAKE_WRONG_SCENE, FAKE_TRUNCATED};
    const char *names[] = {"wrong rows", "wrong scene", "truncated"};
    for (int k = 0; k < 3; k++) {
        run *r = setup(12, 2);
        int a = host(r, "a", 1, (fake_script){.lie = lies[k]});
        int b = host(r, "b", 1, (fake_script){0});
        go(r);
        CHECK(r->rc == 0, "%s: run failed: %s", names[k], r->err.msg);
        CHECK(r->sh[a].slabs == 0, "%s: %d lying slabs accepted", names[k], r->sh[a].slabs);
        const event *f = first(r, SCHED_SLAB_FAILED);
        CHECK(f && f->host == a && strstr(f->text, "bad partial image"), "%s: failure event: %s", names[k],
              f ? f->text : "(none)");
        CHECK(r->sh[a].dropped, "%s: the lying host was not dropped", names[k]);
        CHECK(r->sh[b].rows == 12, "%s: b rendered %d rows", names[k], r->sh[b].rows);
        CHECK(stitched_ok(r), "%s: stitched rows are not the fake pixels", names[k]);
        teardown(r);
    }
}

/* A host lost mid-render is dropped at once; its slabs go elsewhere and do
 * not count as failed attempts. */
static void test_dying_host(void)
{
    run *r = setup(12, 2);
    int a = host(r, "a", 2, (fake_script){.duration = 2, .die_at = 2.5});
    host(r, "b", 1, (fake_script){.duration = 2});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->sh[a].dropped, "the lost host was not dropped");
    const event *d = first(r, SCHED_HOST_DROPPED);
    CHECK(d && d->host == a && strstr(d->text, "connection lost"), "drop event: %s", d ? d->text : "(none)");
    CHECK(d && d->t >= 2.5 && d->t < 3.0, "dropped at %.2f s, expected just after 2.5 s", d ? d->t : -1.0);
    CHECK(r->st.retries == 0, "%d retries counted for a lost connection", r->st.retries);
    int lost = 0;
    for (int i = 0; i < r->world.nspawn; i++)
        lost += r->world.spawn[i].host == a && r->world.spawn[i].outcome == 3 && !r->world.spawn[i].killed;
    CHECK(lost == 2, "%d of a's processes were lost with it, expected 2", lost);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* --resume: rows already in the job directory are not rendered again. */
static void test_resume(void)
{
    run *r = setup(16, 2);
    unsigned char have[16] = {0};
    for (int y = 0; y < 10; y++)
        have[y] = 1;
    r->p.have = have;
    host(r, "a", 2, (fake_script){0});
    /* The job directory of the interrupted run, with rows 0:10 in it. */
    fr_error err;
    unsigned char *buf;
    size_t len;
    CHECK(job_open(r->jobdir, &r->p.spec, 0, &err) == 0, "job_open: %s", err.msg);
    CHECK(fake_partial(&r->world, 0, 10, &buf, &len) == 0 && job_save(r->jobdir, 0, 10, buf, len, &err) == 0,
          "saving rows 0:10: %s", err.msg);
    free(buf);
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->st.slabs == 3, "%d slabs for 6 missing rows in slabs of 2, expected 3", r->st.slabs);
    int low = 0;
    for (int i = 0; i < r->world.nspawn; i++)
        low += r->world.spawn[i].y0 < 10;
    CHECK(low == 0, "%d processes rendered rows that were already there", low);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* A slab that fails everywhere ends the run, naming the rows. */
static void test_gives_up(void)
{
    run *r = setup(4, 4);
    r->p.max_attempts = 2;
    r->p.max_host_failures = 100;
    host(r, "a", 1, (fake_script){.fail_always = 1});
    host(r, "b", 1, (fake_script){.fail_always = 1});
    go(r);
    CHECK(r->rc != 0, "a run whose slabs always fail succeeded");
    CHECK(strstr(r->err.msg, "failed 2 times") != NULL, "message: %s", r->err.msg);
    CHECK(strstr(r->err.msg, "rows 0:4 not rendered") != NULL, "message: %s", r->err.msg);
    CHECK(strstr(r->err.msg, "nothing was kept") != NULL, "message: %s", r->err.msg);
    teardown(r);
}

/* Interrupted: the run stops, keeps what is done and kills the rest. */
static void test_interrupt(void)
{
    run *r = setup(16, 2);
    r->stop_after_done = 2;
    host(r, "a", 2, (fake_script){.duration = 1, .durations = {1, 5}});
    go(r);
    CHECK(r->rc != 0, "an interrupted run succeeded");
    CHECK(strstr(r->err.msg, "interrupted") != NULL, "message: %s", r->err.msg);
    CHECK(strstr(r->err.msg, "4 finished rows are kept") && strstr(r->err.msg, "--resume"), "message: %s",
          r->err.msg);
    CHECK(count(r, SCHED_SLAB_DONE, -1) == 2, "%d slabs done, expected 2", count(r, SCHED_SLAB_DONE, -1));
    unsigned char have[16];
    fr_error err;
    CHECK(job_scan(r->jobdir, &r->p.spec, have, NULL, NULL, &err) == 4, "the job directory does not keep the 4 rows done");
    int killed = 0;
    for (int i = 0; i < r->world.nspawn; i++)
        killed += r->world.spawn[i].killed;
    CHECK(killed >= 1, "no running process was killed");
    teardown(r);
}

/* A host that runs no process never gets dropped for being slow, and the
 * run's progress is reported to the end. */
static int last_done = -1, last_total = -1;
static void on_progress(void *ctx, double t, int done, int total)
{
    (void)ctx, (void)t;
    last_done = done;
    last_total = total;
}

static void test_progress(void)
{
    run *r = setup(8, 2);
    r->p.hooks.progress = on_progress;
    host(r, "a", 1, (fake_script){0});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(last_done == 8 && last_total == 8, "last progress %d/%d, expected 8/8", last_done, last_total);
    teardown(r);
}

/* Hosts that are not ready at the start: slabs start at once on the ready
 * one; b joins at 3 s (the admit hook), c never does (dropped at 5 s) and
 * d stays pending to the end; nobody waits for them. */
static double b_ready_at = 3, c_gone_at = 5;
static int admits;
static void admit_late(void *ctx, sched_host *hs, int n)
{
    run *r = ctx;
    admits++;
    (void)n;
    if (hs[1].pending && r->world.now >= b_ready_at) {
        hs[1].pending = 0;
        hs[1].slots = 2;
    }
    if (hs[2].pending && r->world.now >= c_gone_at) {
        hs[2].pending = 0;
        hs[2].dropped = 1;
        snprintf(hs[2].drop_reason, sizeof hs[2].drop_reason, "probe timed out");
    }
}

static void admit_b_late(void *ctx, sched_host *hs, int n)
{
    run *r = ctx;
    (void)n;
    if (hs[1].pending && r->world.now >= b_ready_at) {
        hs[1].pending = 0;
        hs[1].slots = 1;
    }
}

/* Broken hosts ready first, a good one joining later: the slabs that fail
 * on the broken hosts more than max_attempts times wait for the good host
 * instead of ending the run; a slab that failed on every host still ends it. */
static void test_good_host_late(void)
{
    run *r = setup(8, 4);
    r->p.hooks.admit = admit_b_late;
    r->p.max_attempts = 2;
    r->p.max_host_failures = 100;
    host(r, "bad", 2, (fake_script){.fail_always = 1, .duration = 0.25});
    int b = host(r, "good", 1, (fake_script){.duration = 1});
    r->sh[b].pending = 1;
    go(r);
    CHECK(r->rc == 0, "run failed before the good host joined: %s", r->err.msg);
    CHECK(r->sh[b].rows == 8, "the good host rendered %d rows of 8", r->sh[b].rows);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

static void test_pending_hosts(void)
{
    run *r = setup(40, 1);
    r->p.hooks.admit = admit_late;
    int a = host(r, "a", 1, (fake_script){.duration = 1});
    int b = host(r, "b", 1, (fake_script){.duration = 1});
    int c = host(r, "c", 1, (fake_script){.duration = 1});
    int d = host(r, "d", 1, (fake_script){.duration = 1});
    r->sh[b].pending = r->sh[c].pending = r->sh[d].pending = 1;
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(admits > 0, "the admit hook was never called");
    CHECK(r->world.nspawn > 0 && r->world.spawn[0].host == a && r->world.spawn[0].start < 0.01,
          "the first slab did not start at once on the ready host");
    double first_b = -1;
    int on_c = 0, on_d = 0;
    for (int i = 0; i < r->world.nspawn; i++) {
        const fake_spawn *sp = &r->world.spawn[i];
        if (sp->host == b && first_b < 0)
            first_b = sp->start;
        on_c += sp->host == c;
        on_d += sp->host == d;
    }
    CHECK(first_b >= b_ready_at && first_b < b_ready_at + 0.5, "b's first slab at %.2f s, expected just after %.1f",
          first_b, b_ready_at);
    CHECK(r->sh[b].rows > 0 && r->sh[a].rows > 0, "rows a %d, b %d: both should render", r->sh[a].rows,
          r->sh[b].rows);
    CHECK(on_c == 0 && on_d == 0, "%d processes on c, %d on d, which were never ready", on_c, on_d);
    CHECK(r->sh[c].dropped && !r->sh[d].dropped && r->sh[d].pending, "c dropped %d, d pending %d",
          r->sh[c].dropped, r->sh[d].pending);
    CHECK(r->st.wall_s < 30, "took %.1f virtual s: 40 one-second slabs on a then a and b", r->st.wall_s);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* A stream that never ends (a host whose processes hang): once the other
 * slabs have shown how long a row takes (1 s here), an attempt that runs
 * 8 times that plus 5 s is given up as a failure of its host, long before
 * the queue is empty; after three the host is dropped. */
static void test_deadline(void)
{
    run *r = setup(60, 1);
    int a = host(r, "a", 1, (fake_script){.hang = 1});
    int b = host(r, "b", 1, (fake_script){.duration = 1});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    const event *f = first(r, SCHED_SLAB_FAILED);
    CHECK(f && f->host == a && strstr(f->text, "no result after"), "first failure: %s", f ? f->text : "(none)");
    CHECK(f && f->t >= 13 && f->t < 14, "first stuck attempt given up at %.1f s, expected at 8 * 1 s + 5 s",
          f ? f->t : -1.0);
    CHECK(r->sh[a].dropped && count(r, SCHED_SLAB_FAILED, a) == 3, "a dropped %d after %d failures",
          r->sh[a].dropped, count(r, SCHED_SLAB_FAILED, a));
    const event *d = first(r, SCHED_HOST_DROPPED);
    CHECK(d && d->t < 45, "a dropped at %.1f s, before b's 60 slabs are done", d ? d->t : -1.0);
    CHECK(r->sh[b].rows == 60, "b rendered %d rows", r->sh[b].rows);
    CHECK(stitched_ok(r), "stitched rows are not the fake pixels");
    teardown(r);
}

/* A host slower than the others (4 s a row against 1 s) is judged by its
 * own pace once it has delivered: none of its slabs is given up. */
static void test_deadline_slow_host(void)
{
    run *r = setup(30, 1);
    int a = host(r, "a", 1, (fake_script){.duration = 4});
    host(r, "b", 2, (fake_script){.duration = 1});
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(count(r, SCHED_SLAB_FAILED, a) == 0, "%d slabs of the slow host given up",
          count(r, SCHED_SLAB_FAILED, a));
    CHECK(r->sh[a].slabs > 0, "the slow host delivered nothing");
    teardown(r);
}

/* Pending hosts without an admit hook are dropped; the others render. */
static void test_pending_without_hook(void)
{
    run *r = setup(8, 2);
    host(r, "a", 1, (fake_script){0});
    int b = host(r, "b", 1, (fake_script){0});
    r->sh[b].pending = 1;
    go(r);
    CHECK(r->rc == 0, "run failed: %s", r->err.msg);
    CHECK(r->sh[b].dropped && r->sh[b].slabs == 0, "b (never ready) ran slabs or was not dropped");
    teardown(r);
}

/* The frames of an animation (the next_frame, stage and frame_done hooks):
 * frame f's job directory is fjob[f], its scene "fF.fbin" on every host. */
static int next_frame(void *ctx, int f, sched_frame *next, fr_error *err)
{
    run *r = ctx;
    if (f >= r->nframes)
        return 1;
    snprintf(r->fjob[f], sizeof r->fjob[f], "/tmp/franja-sched.XXXXXX");
    if (!mkdtemp(r->fjob[f]))
        return fr_fail(err, "mkdtemp failed");
    snprintf(r->label[f], sizeof r->label[f], "frame %d", f + 1);
    *next = (sched_frame){.spec = r->p.spec, .jobdir = r->fjob[f], .label = r->label[f]};
    return job_open(r->fjob[f], &next->spec, 0, err) ? -1 : 0;
}

static int stage(void *ctx, int f, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                 size_t lease_cap, fr_error *err)
{
    (void)h, (void)err, (void)lease_cap;
    run *r = ctx;
    r->staged[f][host_i]++;
    snprintf(scene, scene_cap, "f%d.fbin", f);
    lease[0] = 0;
    return 0;
}

static int frame_done(void *ctx, int f, fr_error *err)
{
    (void)err;
    run *r = ctx;
    r->done[f] = ++r->ndone;
    r->done_t[f] = r->world.now;
    return 0;
}

static run *setup_frames(int nframes, int height, int slab_rows)
{
    run *r = setup(height, slab_rows);
    r->nframes = nframes;
    snprintf(r->fjob[0], sizeof r->fjob[0], "%s", r->jobdir);
    snprintf(r->label[0], sizeof r->label[0], "frame 1");
    r->p.label = r->label[0];
    r->p.hooks.next_frame = next_frame;
    r->p.hooks.stage = stage;
    r->p.hooks.frame_done = frame_done;
    return r;
}

/* Every row of frame f's job directory holds the fake pixels. */
static int frame_ok(run *r, int f)
{
    char keep[64];
    snprintf(keep, sizeof keep, "%s", r->jobdir);
    snprintf(r->jobdir, sizeof r->jobdir, "%s", r->fjob[f]);
    int ok = stitched_ok(r);
    snprintf(r->jobdir, sizeof r->jobdir, "%s", keep);
    return ok;
}

static void teardown_frames(run *r)
{
    for (int f = 1; f < r->nframes; f++)
        if (r->fjob[f][0])
            job_remove(r->fjob[f]);
    teardown(r);
}

/* The frame a spawn rendered, from its scene's name. */
static int spawn_frame(const fake_spawn *sp)
{
    return sp->scene[0] == 'f' ? atoi(sp->scene + 1) : -1;
}

/* Two frames on two slots: when frame 1's slabs are all started and one
 * slot is free (its last slab is slow), that slot starts frame 2 at once
 * instead of waiting for frame 1's tail; each frame is done as soon as
 * its rows are saved (here frame 2 first), and its scene went to the host
 * once. */
static void test_frames_overlap(void)
{
    run *r = setup_frames(2, 16, 4);
    /* 4 slabs a frame; the second process (frame 1's rows 4:8) takes 8 s. */
    host(r, "a", 2, (fake_script){.duration = 1, .durations = {1, 8}});
    go(r);
    CHECK(r->rc == 0, "two-frame run failed: %s", r->err.msg);
    CHECK(r->st.frames == 2 && r->st.frames_done == 2, "%d frames, %d done", r->st.frames, r->st.frames_done);
    CHECK(r->st.slabs == 8, "%d slabs, expected 8", r->st.slabs);
    double last_end_1 = 0, first_start_2 = 1e9;
    int n1 = 0, n2 = 0;
    for (int i = 0; i < r->world.nspawn; i++) {
        const fake_spawn *sp = &r->world.spawn[i];
        int f = spawn_frame(sp);
        if (f == 0 && sp->end > last_end_1)
            last_end_1 = sp->end;
        if (f == 1 && sp->start < first_start_2)
            first_start_2 = sp->start;
        n1 += f == 0;
        n2 += f == 1;
    }
    CHECK(n1 >= 4 && n2 >= 4, "%d and %d processes for the two frames, expected 4 each at least", n1, n2);
    CHECK(first_start_2 < last_end_1 - 1.5, "frame 2's first slab started at %.1f s, frame 1's last ended at "
          "%.1f s: no overlap", first_start_2, last_end_1);
    /* Frame 2 ends first (frame 1 waits for its slow slab): frames are
     * done as they complete. */
    CHECK(r->done[1] == 1 && r->done[0] == 2, "frames done in the order %d, %d", r->done[0], r->done[1]);
    CHECK(r->done_t[0] >= last_end_1 - 0.01 && r->done_t[0] < last_end_1 + 0.5,
          "frame 1 done at %.1f s, its last slab ended at %.1f s", r->done_t[0], last_end_1);
    CHECK(r->world.peak[0] == 2, "peak %d processes on 2 slots", r->world.peak[0]);
    /* One slot ran 3 quick slabs of frame 1 then all of frame 2 while the
     * other ran the slow one: about 8 s in all, not 8 s and then frame 2's
     * 2 s on two slots. */
    CHECK(r->st.wall_s < 9, "took %.1f virtual seconds; frame by frame takes 10", r->st.wall_s);
    CHECK(r->staged[0][0] == 1 && r->staged[1][0] == 1, "scenes staged %d and %d times, expected once each",
          r->staged[0][0], r->staged[1][0]);
    CHECK(frame_ok(r, 0) && frame_ok(r, 1), "a frame's stitched rows are not the fake pixels");
    teardown_frames(r);
}

/* A retry of frame 1's slab goes before frame 2's slabs, on the other
 * host; a host lost in the middle of the range is dropped, its slabs go
 * elsewhere, and every frame is done, each scene staged once per host
 * that ran it. */
static void test_frames_host_lost(void)
{
    run *r = setup_frames(3, 16, 2);
    int a = host(r, "a", 2, (fake_script){.duration = 1});
    int b = host(r, "b", 2, (fake_script){.duration = 1, .die_at = 3.5});
    go(r);
    CHECK(r->rc == 0, "three-frame run with a lost host failed: %s", r->err.msg);
    CHECK(r->sh[b].dropped, "the lost host was not dropped");
    CHECK(r->st.frames_done == 3, "%d frames done", r->st.frames_done);
    for (int f = 0; f < 3; f++) {
        CHECK(frame_ok(r, f), "frame %d's stitched rows are not the fake pixels", f + 1);
        CHECK(r->staged[f][a] == 1, "frame %d staged %d times on a", f + 1, r->staged[f][a]);
        CHECK(r->staged[f][b] <= 1, "frame %d staged %d times on b", f + 1, r->staged[f][b]);
    }
    CHECK(r->staged[2][b] == 0, "b got frame 3's scene after it was lost");
    CHECK(r->done[0] == 1 && r->done[1] == 2 && r->done[2] == 3, "frames done in the order %d %d %d", r->done[0],
          r->done[1], r->done[2]);
    teardown_frames(r);
}

/* An interrupt in the second frame: the first is done, the error names
 * the second frame's missing rows, and its finished slabs stay. */
static void test_frames_interrupt(void)
{
    run *r = setup_frames(3, 16, 4);
    r->stop_after_done = 6;
    host(r, "a", 1, (fake_script){.duration = 1});
    go(r);
    CHECK(r->rc != 0, "an interrupted run succeeded");
    CHECK(r->done[0] == 1 && !r->done[1] && !r->done[2], "frames done: %d %d %d", r->done[0], r->done[1],
          r->done[2]);
    CHECK(strstr(r->err.msg, "interrupted") && strstr(r->err.msg, "frame 2 rows 8:16 not rendered"), "message: %s",
          r->err.msg);
    unsigned char have[16];
    fr_error err;
    CHECK(job_scan(r->fjob[1], &r->p.spec, have, NULL, NULL, &err) == 8, "frame 2 does not keep its 8 rows done");
    CHECK(r->fjob[2][0] == 0, "frame 3 was asked for before frame 2's slabs were all started");
    teardown_frames(r);
}

int main(void)
{
    test_frames_overlap();
    test_frames_host_lost();
    test_frames_interrupt();
    test_plain();
    test_guided();
    test_straggler();
    test_drop_failing_host();
    test_shrink_slots();
    test_refusing_host();
    test_retry_elsewhere();
    test_retry_same_host_when_alone();
    test_lying_host();
    test_dying_host();
    test_resume();
    test_gives_up();
    test_interrupt();
    test_progress();
    test_pending_hosts();
    test_good_host_late();
    test_pending_without_hook();
    test_deadline();
    test_deadline_slow_host();
    return check_done();
}
