/* transport.c -- the generic side of tr_*: picks the backend of a host and
 * keeps what every backend shares (process buffers and lists). */
#include "transport_backend.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct tr_host {
    const tr_backend *be;
    void *impl;
    hosts_entry entry;
    tr_proc *procs;            /* every process not yet freed */
};

int tr_connect(const hosts_entry *e, const tr_options *o, tr_host **out, fr_error *err)
{
    *out = NULL;
    tr_host *h = calloc(1, sizeof *h);
    if (!h)
        return fr_fail(err, "%s: out of memory", e->name);
    h->entry = *e;
    h->be = hosts_is_local(e) ? &tr_local_backend : &tr_ssh_backend;
    if (h->be->connect(&h->entry, o, &h->impl, err)) {
        free(h);
        return -1;
    }
    *out = h;
    return 0;
}

int tr_probe(tr_host *h, tr_info *info, fr_error *err)
{
    memset(info, 0, sizeof *info);
    return h->be->probe(h->impl, info, err);
}

int tr_stage(tr_host *h, const char *local_path, uint64_t hash, char *remote, size_t cap,
             int *uploaded, fr_error *err)
{
    *uploaded = 0;
    return h->be->stage(h->impl, local_path, hash, remote, cap, uploaded, err);
}

int tr_cache(tr_host *h, int *files, uint64_t *bytes, fr_error *err)
{
    *files = 0;
    *bytes = 0;
    return h->be->cache(h->impl, files, bytes, err);
}

int tr_sysinfo(tr_host *h, char *arch, char *os, fr_error *err)
{
    arch[0] = os[0] = 0;
    return h->be->sysinfo(h->impl, arch, os, err);
}

int tr_install(tr_host *h, const char *local_path, const char *name, char *remote, size_t cap,
               fr_error *err)
{
    return h->be->install(h->impl, local_path, name, remote, cap, err);
}

void tr_os_codename(const char *text, char *os)
{
    const char key[] = "VERSION_CODENAME=";
    const size_t klen = sizeof key - 1;
    os[0] = 0;
    for (const char *l = text; *l;) {
        const char *end = strchr(l, '\n');
        size_t len = end ? (size_t)(end - l) : strlen(l);
        if (len > klen && !strncmp(l, key, klen)) {
            const char *v = l + klen;
            size_t n = len - klen;
            /* The value may be quoted: VERSION_CODENAME="bookworm". */
            if (n >= 2 && (v[0] == '"' || v[0] == '\'') && v[n - 1] == v[0]) {
                v++;
                n -= 2;
            }
            snprintf(os, 64, "%.*s", (int)(n < 63 ? n : 63), v);
            return;
        }
        if (!end)
            break;
        l = end + 1;
    }
}

int tr_spawn(tr_host *h, const char *const *args, tr_proc **out, fr_error *err)
{
    *out = NULL;
    tr_proc *p = calloc(1, sizeof *p);
    if (!p)
        return fr_fail(err, "%s: out of memory", h->entry.name);
    p->host = h;
    if (h->be->spawn(h->impl, p, args, err)) {
        free(p);
        return -1;
    }
    p->next = h->procs;
    h->procs = p;
    *out = p;
    return 0;
}

int tr_pollfds(tr_host *h, struct pollfd *pfd, int max) { return h->be->pollfds(h->impl, h->procs, pfd, max); }

int tr_service(tr_host *h, fr_error *err) { return h->be->service(h->impl, h->procs, err); }

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
    p->host->be->kill(p);
    if (p->state == TR_RUNNING)
        tr_proc_fail(p, "killed");
}

void tr_proc_free(tr_proc *p)
{
    if (!p)
        return;
    tr_proc_kill(p);
    tr_host *h = p->host;
    h->be->release(p);
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
    if (p->out_len + n > p->out_cap) {
        size_t cap = p->out_cap ? p->out_cap : 65536;
        while (cap < p->out_len + n)
            cap *= 2;
        unsigned char *b = realloc(p->out, cap);
        if (!b)
            return -1;
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
    /* One line in messages: inner newlines become spaces. */
    for (size_t i = 0; i < p->err_len; i++)
        if (p->err[i] == '\n' && i + 1 < p->err_len)
            p->err[i] = ' ';
    while (p->err_len && (p->err[p->err_len - 1] == '\n' || p->err[p->err_len - 1] == '\r'))
        p->err[--p->err_len] = 0;
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
