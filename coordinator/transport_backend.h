/** @file transport_backend.h
 * What a transport backend provides and what it may use (not for the
 * scheduler: it includes transport.h only).  transport.c forwards each
 * tr_* call to the backend of the host.
 */
#ifndef FRANJA_TRANSPORT_BACKEND_H
#define FRANJA_TRANSPORT_BACKEND_H

#include "transport.h"

/** The operations of one backend; `impl` is the backend's own host state. */
typedef struct {
    const char *name;
    int (*connect)(const hosts_entry *e, const tr_options *o, void **impl, fr_error *err);
    int (*probe)(void *impl, tr_info *info, fr_error *err);
    int (*stage)(void *impl, const char *local_path, uint64_t hash, char *remote, size_t cap,
                 int *uploaded, fr_error *err);
    int (*cache)(void *impl, int *files, uint64_t *bytes, fr_error *err);
    int (*spawn)(void *impl, tr_proc *p, const char *const *args, fr_error *err);
    int (*pollfds)(void *impl, tr_proc *procs, struct pollfd *pfd, int max);
    int (*service)(void *impl, tr_proc *procs, fr_error *err); /* procs: live list, via next */
    void (*kill)(tr_proc *p);
    void (*release)(tr_proc *p);   /* frees p->impl; the process is no longer running */
    void (*close)(void *impl);
    int (*sysinfo)(void *impl, char *arch, char *os, fr_error *err);
    int (*install)(void *impl, const char *local_path, const char *name, char *remote, size_t cap,
                   fr_error *err);
} tr_backend;

extern const tr_backend tr_local_backend;
extern const tr_backend tr_ssh_backend;

/** A worker process as both the generic layer and its backend see it. */
struct tr_proc {
    tr_host *host;
    int state;                 /* TR_* */
    int status;                /* exit status, TR_EXITED */
    unsigned char *out;        /* stdout so far */
    size_t out_len, out_cap;
    char err[512];             /* last line(s) of stderr, NUL-terminated */
    size_t err_len;
    char why[256];             /* TR_FAILED: reason given by the transport */
    void *impl;                /* backend's per-process state */
    tr_proc *next;             /* the host's list of unfreed processes */
};

/** Appends n bytes to p's stdout buffer; -1 when out of memory. */
int tr_proc_add_out(tr_proc *p, const void *data, size_t n);

/** Keeps the tail of what p writes on stderr. */
void tr_proc_add_err(tr_proc *p, const void *data, size_t n);

/** Copies the VERSION_CODENAME of an os-release text (NUL-terminated) into
 * os[64], without quotes; "" if it has none. */
void tr_os_codename(const char *os_release, char *os);

/** Marks p failed with a reason (printf-style). */
void tr_proc_fail(tr_proc *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
