/* transport.c -- the generic side of tr_*: picks the backend of a host,
 * keeps what every backend shares (process buffers and lists), and builds
 * tr_run from spawn and service. */
#include "transport/transport_backend.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "protocol.h"

struct tr_host {
    const tr_backend *be;
    void *impl;
    hosts_entry entry;
    tr_options opt;
    tr_place place;
    tr_proc *procs;            /* every process not yet freed */
};

/* The backend that serves entry e: o->backend if set, else the local one
 * for `local` hosts and SSH for the others.  New backends are chosen here. */
static const tr_backend *tr_backend_for(const hosts_entry *e, const tr_options *o)
{
    if (o->backend)
        return o->backend;
    return hosts_is_local(e) ? &tr_local_backend : &tr_ssh_backend;
}

int tr_connect(const hosts_entry *e, const tr_options *o, tr_host **out, fr_error *err)
{
    *out = NULL;
    tr_host *h = calloc(1, sizeof *h);
    if (!h)
        return fr_fail(err, "%s: out of memory", e->name);
    h->entry = *e;
    h->opt = *o;
    h->be = tr_backend_for(e, o);
    if (h->be->connect(h, &h->impl, &h->place, err)) {
        free(h);
        return -1;
    }
    if (!h->place.label[0])
        snprintf(h->place.label, sizeof h->place.label, "%s", e->name);
    *out = h;
    return 0;
}

int tr_spawn(tr_host *h, const char *const *argv, size_t max_out, tr_proc **out, fr_error *err)
{
    *out = NULL;
    tr_proc *p = calloc(1, sizeof *p);
    if (!p)
        return fr_fail(err, "%s: out of memory", h->place.label);
    p->host = h;
    p->out_max = max_out;
    if (h->be->spawn(h->impl, p, argv, err)) {
        free(p);
        return -1;
    }
    p->next = h->procs;
    h->procs = p;
    *out = p;
    return 0;
}

int tr_run(tr_host *h, const char *const *argv, size_t max_out, int timeout_s, tr_proc **out, fr_error *err)
{
    tr_proc *p;
    if (tr_spawn(h, argv, max_out, &p, err))
        return -1;
    double end = clock_now() + timeout_s;
    while (p->state == TR_RUNNING) {
        struct pollfd pfd[16];
        int n = tr_pollfds(h, pfd, 16);
        poll(pfd, (nfds_t)n, 20);
        if (tr_service(h, err)) {
            tr_proc_free(p);
            return -1;
        }
        if (p->state == TR_RUNNING && clock_now() > end) {
            tr_proc_free(p);
            return fr_fail(err, "%s: %s did not finish within %d s", h->place.label, argv[0], timeout_s);
        }
    }
    *out = p;
    return 0;
}

int tr_upload(tr_host *h, const char *local_path, const char *remote, int mode, fr_error *err)
{
    if (!h->place.workdir[0])
        return fr_fail(err, "%s: the host uses this machine's files; nothing to upload", h->place.label);
    return h->be->upload(h->impl, local_path, remote, mode, err);
}

int tr_remove(tr_host *h, const char *remote, fr_error *err)
{
    if (!h->place.workdir[0] || !h->be->remove)
        return fr_fail(err, "%s: nothing was uploaded there to remove", h->place.label);
    return h->be->remove(h->impl, remote, err);
}

int tr_pollfds(tr_host *h, struct pollfd *pfd, int max) { return h->be->pollfds(h->impl, h->procs, pfd, max); }

int tr_service(tr_host *h, fr_error *err)
{
    int rc = h->be->service(h->impl, h->procs, err);
    /* A process failed for its output (too much of it) is stopped here, so
     * that no backend has to remember to. */
    for (tr_proc *p = h->procs; p; p = p->next)
        if (p->kill_pending && p->impl) {
            p->kill_pending = 0;
            h->be->kill(h->impl, p);
        }
    return rc;
}

void tr_close(tr_host *h)
{
    if (!h)
        return;
    while (h->procs)
        tr_proc_free(h->procs);
    h->be->close(h->impl);
    free(h);
}

const hosts_entry *tr_host_entry(const tr_host *h) { return &h->entry; }

const tr_options *tr_host_options(const tr_host *h) { return &h->opt; }

void *tr_host_backend_ctx(const tr_host *h) { return h->opt.backend_ctx; }

const char *tr_host_label(const tr_host *h) { return h->place.label[0] ? h->place.label : h->entry.name; }

const char *tr_host_worker(const tr_host *h) { return h->place.worker; }

const char *tr_host_workdir(const tr_host *h) { return h->place.workdir; }
const char *tr_host_backend(const tr_host *h) { return h->be->name; }

int tr_host_busy_upload(const tr_host *h) { return h->place.busy_upload; }

int tr_host_link_upload(const tr_host *h) { return h->place.link_upload; }

void tr_note(tr_host *h, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    note_say(&h->opt.notes, "%s: %s", tr_host_label(h), msg);
}

int tr_proc_state(const tr_proc *p) { return p->state; }

int tr_proc_status(const tr_proc *p) { return p->status; }

const unsigned char *tr_proc_output(const tr_proc *p, size_t *len)
{
    *len = p->out_len;
    return p->out;
}

const char *tr_proc_reason(const tr_proc *p)
{
    if (p->why[0])
        return p->why;
    return p->err;
}

void tr_proc_kill(tr_proc *p)
{
    if (p->state != TR_RUNNING)
        return;
    p->host->be->kill(p->host->impl, p);
    if (p->state == TR_RUNNING)
        tr_proc_fail(p, "killed");
}

void tr_proc_free(tr_proc *p)
{
    if (!p)
        return;
    tr_proc_kill(p);
    tr_host *h = p->host;
    h->be->release(h->impl, p);
    for (tr_proc **pp = &h->procs; *pp; pp = &(*pp)->next)
        if (*pp == p) {
            *pp = p->next;
            break;
        }
    free(p->out);
    free(p);
}

int tr_proc_add_out(tr_proc *p, const void *data, size_t n)
{
    if (p->state != TR_RUNNING)
        return -1;
    if (n == 0)
        return 0;
    if (n > p->out_max - p->out_len) {
        tr_proc_fail(p, "sent more than the %zu bytes expected", p->out_max);
        p->kill_pending = 1;
        return -1;
    }
    if (p->out_len + n > p->out_cap) {
        size_t cap = p->out_cap ? p->out_cap : 65536;
        while (cap < p->out_len + n)
            cap *= 2;
        unsigned char *b = realloc(p->out, cap);
        if (!b) {
            tr_proc_fail(p, "out of memory for the output");
            p->kill_pending = 1;
            return -1;
        }
        p->out = b;
        p->out_cap = cap;
    }
    memcpy(p->out + p->out_len, data, n);
    p->out_len += n;
    return 0;
}

/* Keeps the last bytes only: the final lines say why a worker failed. */
void tr_proc_add_err(tr_proc *p, const void *data, size_t n)
{
    const char *d = data;
    size_t cap = sizeof p->err - 1;
    if (n >= cap) {
        d += n - cap;
        n = cap;
    }
    if (p->err_len + n > cap) {
        size_t drop = p->err_len + n - cap;
        memmove(p->err, p->err + drop, p->err_len - drop);
        p->err_len -= drop;
    }
    memcpy(p->err + p->err_len, d, n);
    p->err_len += n;
    p->err[p->err_len] = 0;
    while (p->err_len && (p->err[p->err_len - 1] == '\n' || p->err[p->err_len - 1] == '\r'))
        p->err[--p->err_len] = 0;
    /* One line in messages: inner newlines become spaces, other control
     * characters (a remote host's escape sequences) '?'. */
    for (size_t i = 0; i < p->err_len; i++)
        if (p->err[i] == '\n' || p->err[i] == '\t')
            p->err[i] = ' ';
    proto_printable(p->err);
}

void tr_proc_fail(tr_proc *p, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->why, sizeof p->why, fmt, ap);
    va_end(ap);
    p->state = TR_FAILED;
}

int tr_shell_quote(const char *word, char *out, size_t cap, fr_error *err)
{
    size_t n = 0;
#define PUT(c)                                                                      \
    do {                                                                            \
        if (n + 1 >= cap)                                                           \
            return fr_fail(err, "command argument too long for the remote shell"); \
        out[n++] = (c);                                                             \
    } while (0)
    PUT('\'');
    for (const char *s = word; *s; s++) {
        if (*s == '\'') {
            PUT('\'');
            PUT('\\');
            PUT('\'');
            PUT('\'');
        } else {
            PUT(*s);
        }
    }
    PUT('\'');
#undef PUT
    out[n] = 0;
    return 0;
}
