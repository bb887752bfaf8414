/* transport_ssh.c -- the SSH backend: processes on a remote host over
 * libssh, one session per host, one exec channel per process, SFTP for
 * uploads.
 *
 * Liveness: a worker is silent while it renders, so silence on its channel
 * proves nothing.  Instead the session counts every byte received
 * (ssh_set_counters) and, when the host has been quiet for a while, sends a
 * keepalive@openssh.com global request, which a live server must answer.
 * A host that stays silent past the time-out (a stopped server, a cut
 * link) is declared lost, so its slabs go elsewhere. */
#include "transport/transport_backend.h"

#include <errno.h>
#include <fcntl.h>
#include <libssh/libssh.h>
#include <libssh/server.h> /* ssh_send_keepalive: declared here, usable by clients */
#include <libssh/sftp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "clock.h"

#define SFTP_CHUNK (128 * 1024) /* larger writes make sftp-server drop the link */

typedef struct {
    tr_host *th;
    const tr_options *opt;
    const char *label;         /* "name (user@host:port)" for messages (the tr_place's) */
    char host[256];            /* the address actually used (config's HostName applied) */
    ssh_session s;
    sftp_session sftp;
    struct ssh_counter_struct c_sock, c_raw;
    uint64_t seen_bytes;       /* c_sock.in_bytes at the last change */
    double seen_t;             /* when it last changed */
    double keepalive_t;        /* last keepalive sent */
    double service_t;          /* last tr_service call */
    int lost;
} ssh_host;

typedef struct {
    ssh_channel ch;
} ssh_proc;

/* The exit status of a channel's finished command; -1 if it has none
 * (killed by a signal, or the connection ended first).  libssh 0.11
 * (Debian 13) deprecates ssh_channel_get_exit_status for
 * ssh_channel_get_exit_state. */
static int exit_status(ssh_channel ch)
{
#if LIBSSH_VERSION_INT >= SSH_VERSION_INT(0, 11, 0)
    uint32_t code = 0;
    char *sig = NULL;
    int core = 0;
    int rc = ssh_channel_get_exit_state(ch, &code, &sig, &core);
    int killed = sig != NULL;
    ssh_string_free_char(sig);
    return rc == SSH_OK && !killed ? (int)code : -1;
#else
    return ssh_channel_get_exit_status(ch);
#endif
}

/* "~/x" and "x" both mean "x under the home directory" for SFTP and for the
 * remote shell (where a quoted ~ would not expand). */
static const char *home_relative(const char *p)
{
    if (p[0] == '~' && p[1] == '/')
        return p + 2;
    if (p[0] == '~' && p[1] == 0)
        return ".";
    return p;
}

static int expand_tilde(const char *p, char *out, size_t cap)
{
    const char *home = getenv("HOME");
    if (p[0] == '~' && p[1] == '/' && home)
        return snprintf(out, cap, "%s%s", home, p + 1) >= (int)cap ? -1 : 0;
    return snprintf(out, cap, "%s", p) >= (int)cap ? -1 : 0;
}

static char *fingerprint(ssh_session s)
{
    ssh_key key = NULL;
    unsigned char *hash = NULL;
    size_t hlen = 0;
    char *fp = NULL;
    if (ssh_get_server_publickey(s, &key) == SSH_OK &&
        ssh_get_publickey_hash(key, SSH_PUBLICKEY_HASH_SHA256, &hash, &hlen) == SSH_OK)
        fp = ssh_get_fingerprint_hash(SSH_PUBLICKEY_HASH_SHA256, hash, hlen);
    ssh_clean_pubkey_hash(&hash);
    ssh_key_free(key);
    return fp;
}

/* Checks the server's key against known_hosts; refusals say what to do. */
static int verify_host_key(ssh_host *h, fr_error *err)
{
    unsigned int port = 22;
    ssh_options_get_port(h->s, &port);
    char spec[300];
    if (port == 22)
        snprintf(spec, sizeof spec, "%s", h->host);
    else
        snprintf(spec, sizeof spec, "[%s]:%u", h->host, port);
    char *khs = NULL;
    ssh_options_get(h->s, SSH_OPTIONS_KNOWNHOSTS, &khs); /* as ~/.ssh/config may have set it */
    char kh[600];
    snprintf(kh, sizeof kh, "%s", khs ? khs : h->opt->known_hosts ? h->opt->known_hosts : "~/.ssh/known_hosts");
    ssh_string_free_char(khs);
    char *fp = fingerprint(h->s);
    const char *fps = fp ? fp : "(unknown fingerprint)";
    int rc = 0;
    switch (ssh_session_is_known_server(h->s)) {
    case SSH_KNOWN_HOSTS_OK:
        break;
    case SSH_KNOWN_HOSTS_CHANGED:
    case SSH_KNOWN_HOSTS_OTHER:
        rc = fr_fail(err,
                     "%s: REFUSED: the host key changed (now %s); this may be an attack. If the host "
                     "was reinstalled, check the new fingerprint on its console, then run: "
                     "ssh-keygen -R '%s' -f %s (--accept-new-hosts never replaces a changed key)",
                     h->label, fps, spec, kh);
        break;
    case SSH_KNOWN_HOSTS_NOT_FOUND:
    case SSH_KNOWN_HOSTS_UNKNOWN:
        if (h->opt->accept_new) {
            if (ssh_session_update_known_hosts(h->s) != SSH_OK)
                rc = fr_fail(err, "%s: cannot add its key to %s: %s", h->label, kh, ssh_get_error(h->s));
            else
                tr_note(h->th, "added key %s to %s", fps, kh);
        } else {
            rc = fr_fail(err,
                         "%s: REFUSED: unknown host (key %s is not in %s). Check the fingerprint, then "
                         "add it with: ssh-keyscan -p %u %s >> %s (or run once with --accept-new-hosts)",
                         h->label, fps, kh, port, h->host, kh);
        }
        break;
    default:
        rc = fr_fail(err, "%s: cannot check the host key against %s: %s", h->label, kh,
                     ssh_get_error(h->s));
    }
    ssh_string_free_char(fp);
    return rc;
}

static int ssh_connect_host(tr_host *th, void **impl, tr_place *place, fr_error *err)
{
    const hosts_entry *e = tr_host_entry(th);
    const tr_options *o = tr_host_options(th);
    ssh_host *h = calloc(1, sizeof *h);
    if (!h)
        return fr_fail(err, "%s: out of memory", e->name);
    h->th = th;
    h->opt = o;
    h->label = place->label;
    snprintf(place->label, sizeof place->label, "%s", e->name);
    snprintf(place->workdir, sizeof place->workdir, "%s", home_relative(hosts_workdir(e)));
    place->busy_upload = 1; /* SFTP, on the session's own channel */
    place->link_upload = 1;
    if (e->worker[0])
        snprintf(place->worker, sizeof place->worker, "%s", home_relative(e->worker));
    else
        snprintf(place->worker, sizeof place->worker, "%s/franja-worker", place->workdir);
    h->s = ssh_new();
    if (!h->s) {
        free(h);
        return fr_fail(err, "%s: cannot create an SSH session", e->name);
    }
    ssh_session s = h->s;
    bool cfg = o->read_ssh_config != 0;
    long timeout = o->timeout_s > 0 ? o->timeout_s : 10;
    int nodelay = 1;
    char ident[1024];
    /* The host table wins over ~/.ssh/config, as the command line does for ssh(1). */
    int bad = ssh_options_set(s, SSH_OPTIONS_HOST, e->address) ||
              ssh_options_set(s, SSH_OPTIONS_PROCESS_CONFIG, &cfg) ||
              (cfg && ssh_options_parse_config(s, o->ssh_config)) ||
              (e->port && ssh_options_set(s, SSH_OPTIONS_PORT, &(unsigned int){(unsigned)e->port})) ||
              (e->user[0] && ssh_options_set(s, SSH_OPTIONS_USER, e->user)) ||
              (o->known_hosts && ssh_options_set(s, SSH_OPTIONS_KNOWNHOSTS, o->known_hosts)) ||
              ssh_options_set(s, SSH_OPTIONS_TIMEOUT, &timeout) ||
              ssh_options_set(s, SSH_OPTIONS_NODELAY, &nodelay);
    int bad_identity = 0;
    if (!bad && e->identity[0]) {
        if (expand_tilde(e->identity, ident, sizeof ident) || access(ident, R_OK))
            bad_identity = 1;
        else
            bad = ssh_options_set(s, SSH_OPTIONS_IDENTITY, ident);
    }
    char *user = NULL, *host = NULL;
    unsigned int port = 22;
    ssh_options_get(s, SSH_OPTIONS_USER, &user);
    ssh_options_get(s, SSH_OPTIONS_HOST, &host); /* after ~/.ssh/config's HostName */
    ssh_options_get_port(s, &port);
    snprintf(h->host, sizeof h->host, "%s", host ? host : e->address);
    snprintf(place->label, sizeof place->label, "%s (%s@%s:%u)", e->name, user ? user : "?", h->host, port);
    ssh_string_free_char(user);
    ssh_string_free_char(host);
    if (bad_identity) {
        fr_fail(err, "%s: identity file '%s' cannot be read", h->label, e->identity);
        goto fail;
    }
    if (bad) {
        fr_fail(err, "%s: bad SSH options: %s", h->label, ssh_get_error(s));
        goto fail;
    }
    if (ssh_connect(s) != SSH_OK) {
        fr_fail(err, "%s: cannot connect: %s", h->label, ssh_get_error(s));
        goto fail;
    }
    if (verify_host_key(h, err))
        goto fail;
    int auth = ssh_userauth_publickey_auto(s, NULL, NULL);
    if (auth != SSH_AUTH_SUCCESS) {
        fr_fail(err,
                "%s: authentication refused: no key was accepted (tried %s%s); put your public key "
                "in the host's ~/.ssh/authorized_keys, load it into ssh-agent, or give identity=",
                h->label, getenv("SSH_AUTH_SOCK") ? "ssh-agent and " : "",
                e->identity[0] ? e->identity : "the default keys");
        goto fail;
    }
    ssh_set_counters(s, &h->c_sock, &h->c_raw);
    h->seen_t = h->keepalive_t = h->service_t = clock_now();
    *impl = h;
    return 0;
fail:
    ssh_disconnect(s);
    ssh_free(s);
    free(h);
    return -1;
}

/* Builds "exec 'a' 'b' ..." so the program replaces the login shell (a
 * signal then reaches it) and no argument is interpreted by the shell. */
static int build_command(const char *const *argv, char *cmd, size_t cap, fr_error *err)
{
    size_t n = (size_t)snprintf(cmd, cap, "exec");
    char q[2200];
    for (int i = 0; argv[i]; i++) {
        if (tr_shell_quote(argv[i], q, sizeof q, err))
            return -1;
        if (n + strlen(q) + 2 >= cap)
            return fr_fail(err, "remote command too long");
        n += (size_t)snprintf(cmd + n, cap - n, " %s", q);
    }
    return 0;
}

static int sftp_ready(ssh_host *h, fr_error *err)
{
    if (h->sftp)
        return 0;
    h->sftp = sftp_new(h->s);
    if (!h->sftp || sftp_init(h->sftp) != SSH_OK) {
        fr_fail(err, "%s: SFTP unavailable: %s", h->label, ssh_get_error(h->s));
        if (h->sftp)
            sftp_free(h->sftp);
        h->sftp = NULL;
        return -1;
    }
    return 0;
}

/* The SFTP channel counts against the server's MaxSessions like a worker's
 * channel, so it is closed as soon as the file is in place. */
static void sftp_done(ssh_host *h)
{
    if (h->sftp)
        sftp_free(h->sftp);
    h->sftp = NULL;
}

/* An SFTP status code in words. */
static const char *sftp_words(int code)
{
    switch (code) {
    case SSH_FX_NO_SUCH_FILE: return "no such file or directory";
    case SSH_FX_PERMISSION_DENIED: return "permission denied";
    case SSH_FX_NO_SUCH_PATH: return "no such path";
    case SSH_FX_FILE_ALREADY_EXISTS: return "file exists";
    case SSH_FX_WRITE_PROTECT: return "read-only file system";
    case SSH_FX_NO_MEDIA: return "no medium";
    case SSH_FX_OP_UNSUPPORTED: return "operation not supported";
    default: return "failure";
    }
}

/* mkdir -p over SFTP.  A mkdir fails harmlessly when the directory exists;
 * when the directory is missing at the end, the error is the first mkdir
 * that failed on a path that is not there (the reason, say "permission
 * denied"), not what a later stat says. */
static int sftp_mkdirs(ssh_host *h, const char *dir, fr_error *err)
{
    char path[700], failed[700] = "";
    int code = 0;
    snprintf(path, sizeof path, "%s", dir);
    for (char *s = path + 1;; s++) {
        if (*s == '/' || *s == 0) {
            char c = *s;
            *s = 0;
            if (sftp_mkdir(h->sftp, path, 0755) != SSH_OK && !failed[0]) {
                int why = sftp_get_error(h->sftp);
                sftp_attributes a = sftp_stat(h->sftp, path);
                if (!a) {
                    code = why;
                    snprintf(failed, sizeof failed, "%s", path);
                }
                sftp_attributes_free(a);
            }
            *s = c;
            if (!c)
                break;
        }
    }
    sftp_attributes a = sftp_stat(h->sftp, dir);
    int ok = a && a->type == SSH_FILEXFER_TYPE_DIRECTORY;
    sftp_attributes_free(a);
    if (ok)
        return 0;
    if (failed[0])
        return fr_fail(err, "%s: cannot create directory '%s': mkdir %s: %s", h->label, dir, failed,
                       sftp_words(code));
    return fr_fail(err, "%s: cannot create directory '%s': %s", h->label, dir, ssh_get_error(h->s));
}

static int send_file(ssh_host *h, const char *local, const char *tmp, fr_error *err)
{
    int fd = open(local, O_RDONLY);
    if (fd < 0)
        return fr_fail(err, "%s: %s", local, strerror(errno));
    sftp_file f = sftp_open(h->sftp, tmp, O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (!f) {
        close(fd);
        return fr_fail(err, "%s: cannot create '%s': %s", h->label, tmp, ssh_get_error(h->s));
    }
    static __thread char buf[SFTP_CHUNK];
    int rc = 0;
    for (;;) {
        ssize_t n = read(fd, buf, sizeof buf);
        if (n < 0) {
            rc = fr_fail(err, "%s: %s", local, strerror(errno));
            break;
        }
        if (n == 0)
            break;
        if (sftp_write(f, buf, (size_t)n) != n) {
            rc = fr_fail(err, "%s: upload of %s failed: %s", h->label, local, ssh_get_error(h->s));
            break;
        }
    }
    close(fd);
    if (sftp_close(f) != SSH_NO_ERROR && rc == 0)
        rc = fr_fail(err, "%s: upload of %s failed on close: %s", h->label, local, ssh_get_error(h->s));
    return rc;
}

/* A private temporary name, renamed into place: a reader never sees a
 * half-written file, and two coordinators never write the same one. */
static int ssh_upload(void *impl, const char *local_path, const char *remote, int mode, fr_error *err)
{
    ssh_host *h = impl;
    struct stat st;
    if (stat(local_path, &st))
        return fr_fail(err, "%s: %s", local_path, strerror(errno));
    char dir[1100], tmp[1200];
    snprintf(dir, sizeof dir, "%s", remote);
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = 0;
    if (snprintf(tmp, sizeof tmp, "%s.part-%ld-%ld", remote, (long)getpid(), (long)(clock_now() * 1e3)) >=
        (int)sizeof tmp)
        return fr_fail(err, "%s: path too long: %s", h->label, remote);
    if (sftp_ready(h, err))
        return -1;
    int rc = slash && dir[0] ? sftp_mkdirs(h, dir, err) : 0;
    if (rc == 0)
        rc = send_file(h, local_path, tmp, err);
    if (rc == 0) {
        sftp_attributes a = sftp_stat(h->sftp, tmp);
        if (!a || a->size != (uint64_t)st.st_size)
            rc = fr_fail(err, "%s: %s arrived incomplete", h->label, tmp);
        sftp_attributes_free(a);
    }
    if (rc == 0 && sftp_chmod(h->sftp, tmp, (mode_t)mode) != SSH_OK)
        rc = fr_fail(err, "%s: cannot set the mode of %s: %s", h->label, tmp, ssh_get_error(h->s));
    if (rc == 0 && sftp_rename(h->sftp, tmp, remote) != SSH_OK) {
        /* SFTP version 3 does not rename over an existing file. */
        sftp_unlink(h->sftp, remote);
        if (sftp_rename(h->sftp, tmp, remote) != SSH_OK)
            rc = fr_fail(err, "%s: cannot rename %s into place: %s", h->label, tmp, ssh_get_error(h->s));
    }
    if (rc)
        sftp_unlink(h->sftp, tmp);
    sftp_done(h);
    return rc;
}

static int ssh_spawn(void *impl, tr_proc *p, const char *const *argv, fr_error *err)
{
    ssh_host *h = impl;
    if (h->lost)
        return fr_fail(err, "%s: connection lost", h->label);
    char cmd[8192];
    if (build_command(argv, cmd, sizeof cmd, err))
        return -1;
    ssh_proc *sp = calloc(1, sizeof *sp);
    if (!sp)
        return fr_fail(err, "%s: out of memory", h->label);
    double t0 = clock_now();
    sp->ch = ssh_channel_new(h->s);
    int ok = sp->ch && ssh_channel_open_session(sp->ch) == SSH_OK && ssh_channel_request_exec(sp->ch, cmd) == SSH_OK;
    /* The request waited for this host's answer: a silence meanwhile is
     * the host's, and counts toward losing it (ssh_service). */
    h->service_t = clock_now();
    if (!ok) {
        const char *why = ssh_get_error(h->s);
        if (!why[0] || h->service_t - t0 >= 0.9 * (h->opt->timeout_s > 0 ? h->opt->timeout_s : 10))
            fr_fail(err, "%s: cannot start a process: no answer within %.0f s", h->label, h->service_t - t0);
        else
            fr_fail(err, "%s: cannot start a process: %s (a host running more than ~9 workers needs "
                    "MaxSessions raised in its sshd_config)", h->label, why);
        if (sp->ch)
            ssh_channel_free(sp->ch);
        free(sp);
        return -1;
    }
    p->impl = sp;
    p->state = TR_RUNNING;
    return 0;
}

static int ssh_pollfds(void *impl, tr_proc *procs, struct pollfd *pfd, int max)
{
    ssh_host *h = impl;
    (void)procs;
    if (h->lost || max < 1)
        return 0;
    socket_t fd = ssh_get_fd(h->s);
    if (fd < 0)
        return 0;
    pfd[0] = (struct pollfd){fd, POLLIN, 0};
    return 1;
}

static void lose(ssh_host *h, tr_proc *procs, const char *why)
{
    h->lost = 1;
    for (tr_proc *p = procs; p; p = p->next)
        if (p->state == TR_RUNNING)
            tr_proc_fail(p, "%s", why);
}

static int ssh_service(void *impl, tr_proc *procs, fr_error *err)
{
    ssh_host *h = impl;
    if (h->lost)
        return fr_fail(err, "%s: connection lost", h->label);
    char buf[65536];
    for (tr_proc *p = procs; p; p = p->next) {
        ssh_proc *sp = p->impl;
        if (p->state != TR_RUNNING || !sp)
            continue;
        int n, m = 0;
        while ((n = ssh_channel_read_nonblocking(sp->ch, buf, sizeof buf, 0)) > 0)
            if (tr_proc_add_out(p, buf, (size_t)n))
                break; /* failed for its output; transport.c kills it */
        /* stderr too when stdout is at its end: a failing process writes
         * there last. */
        while (n != SSH_ERROR && (m = ssh_channel_read_nonblocking(sp->ch, buf, sizeof buf, 1)) > 0)
            tr_proc_add_err(p, buf, (size_t)m);
        if ((n < 0 && n != SSH_EOF) || (m < 0 && m != SSH_EOF)) {
            char why[1024];
            snprintf(why, sizeof why, "%s: connection lost: %s", h->label, ssh_get_error(h->s));
            lose(h, procs, why);
            return fr_fail(err, "%s", why);
        }
        if (p->state == TR_RUNNING && (ssh_channel_is_eof(sp->ch) || ssh_channel_is_closed(sp->ch)) &&
            ssh_channel_poll(sp->ch, 0) <= 0 && ssh_channel_poll(sp->ch, 1) <= 0) {
            int st = exit_status(sp->ch);
            if (st < 0)
                tr_proc_fail(p, "worker ended without an exit status (killed by a signal?)");
            else {
                p->status = st;
                p->state = TR_EXITED;
            }
        }
    }
    double t = clock_now();
    double interval = h->opt->timeout_s > 0 ? h->opt->timeout_s / 4.0 : 2.5;
    if (interval < 0.25)
        interval = 0.25;
    if (t - h->service_t > interval)
        h->seen_t = t; /* nobody was listening: the silence does not count */
    h->service_t = t;
    if (!ssh_is_connected(h->s)) {
        char why[1024];
        snprintf(why, sizeof why, "%s: connection closed: %s", h->label, ssh_get_error(h->s));
        lose(h, procs, why);
        return fr_fail(err, "%s", why);
    }
    if (h->c_sock.in_bytes != h->seen_bytes) {
        h->seen_bytes = h->c_sock.in_bytes;
        h->seen_t = t;
    } else if (h->opt->timeout_s > 0 && t - h->seen_t > h->opt->timeout_s) {
        char why[1024];
        snprintf(why, sizeof why, "%s: no answer for %.0f s (host stopped or link cut)", h->label,
                 t - h->seen_t);
        lose(h, procs, why);
        return fr_fail(err, "%s", why);
    }
    if (t - h->seen_t >= interval && t - h->keepalive_t >= interval) {
        /* Non-blocking for this one call: the request leaves now and its
         * answer is read later with the channels' data. */
        ssh_set_blocking(h->s, 0);
        ssh_send_keepalive(h->s);
        ssh_set_blocking(h->s, 1);
        h->keepalive_t = t;
    }
    return 0;
}

static void ssh_kill(void *impl, tr_proc *p)
{
    (void)impl;
    ssh_proc *sp = p->impl;
    if (!sp || !sp->ch || !ssh_channel_is_open(sp->ch))
        return;
    ssh_channel_request_send_signal(sp->ch, "KILL");
    ssh_channel_close(sp->ch);
}

static void ssh_release(void *impl, tr_proc *p)
{
    (void)impl;
    ssh_proc *sp = p->impl;
    if (!sp)
        return;
    if (sp->ch)
        ssh_channel_free(sp->ch);
    free(sp);
    p->impl = NULL;
}

static void ssh_close_host(void *impl)
{
    ssh_host *h = impl;
    if (h->sftp)
        sftp_free(h->sftp);
    if (h->lost)
        ssh_silent_disconnect(h->s);
    else
        ssh_disconnect(h->s);
    ssh_free(h->s);
    free(h);
}

static int ssh_remove(void *impl, const char *remote, fr_error *err)
{
    ssh_host *h = impl;
    if (sftp_ready(h, err))
        return -1;
    int rc = 0;
    if (sftp_unlink(h->sftp, remote) != SSH_OK && sftp_get_error(h->sftp) != SSH_FX_NO_SUCH_FILE)
        rc = fr_fail(err, "%s: cannot remove '%s': %s", h->label, remote, ssh_get_error(h->s));
    sftp_done(h);
    return rc;
}

const tr_backend tr_ssh_backend = {
    .name = "ssh",
    .connect = ssh_connect_host,
    .spawn = ssh_spawn,
    .upload = ssh_upload,
    .remove = ssh_remove,
    .pollfds = ssh_pollfds,
    .service = ssh_service,
    .kill = ssh_kill,
    .release = ssh_release,
    .close = ssh_close_host,
};
