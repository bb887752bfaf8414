/* transport_ssh.c -- worker processes on a remote host over libssh: one
 * session per host, one exec channel per process, SFTP for the scene.
 *
 * Liveness: a worker is silent while it renders, so silence on its channel
 * proves nothing.  Instead the session counts every byte received
 * (ssh_set_counters) and, when the host has been quiet for a while, sends a
 * keepalive@openssh.com global request, which a live server must answer.
 * A host that stays silent past the time-out (a stopped server, a cut
 * link) is declared lost, so its slabs go elsewhere. */
#include "transport_backend.h"

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

#define SFTP_CHUNK (128 * 1024) /* larger writes make sftp-server drop the link */

typedef struct {
    hosts_entry entry;
    tr_options opt;
    char label[400];           /* "name (user@host:port)" for messages */
    char host[256];            /* the address actually used (config's HostName applied) */
    char workdir[600];         /* home-relative unless absolute */
    char worker[1100];
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

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
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
    snprintf(kh, sizeof kh, "%s", khs ? khs : h->opt.known_hosts ? h->opt.known_hosts : "~/.ssh/known_hosts");
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
        if (h->opt.accept_new) {
            if (ssh_session_update_known_hosts(h->s) != SSH_OK)
                rc = fr_fail(err, "%s: cannot add its key to %s: %s", h->label, kh, ssh_get_error(h->s));
            else
                fprintf(stderr, "franja: %s: added key %s to %s\n", h->label, fps, kh);
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

static int ssh_connect_host(const hosts_entry *e, const tr_options *o, void **impl, fr_error *err)
{
    ssh_host *h = calloc(1, sizeof *h);
    if (!h)
        return fr_fail(err, "%s: out of memory", e->name);
    h->entry = *e;
    h->opt = *o;
    snprintf(h->workdir, sizeof h->workdir, "%s", home_relative(hosts_workdir(e)));
    if (e->worker[0])
        snprintf(h->worker, sizeof h->worker, "%s", home_relative(e->worker));
    else
        snprintf(h->worker, sizeof h->worker, "%s/franja-worker", h->workdir);
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
    snprintf(h->label, sizeof h->label, "%s (%s@%s:%u)", e->name, user ? user : "?", h->host, port);
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
    h->seen_t = h->keepalive_t = h->service_t = now_s();
    *impl = h;
    return 0;
fail:
    ssh_disconnect(s);
    ssh_free(s);
    free(h);
    return -1;
}

/* Builds "exec 'a' 'b' ..." so the worker replaces the login shell (a
 * signal then reaches it) and no argument is interpreted by the shell. */
static int build_command(const char *prog, const char *const *args, char *cmd, size_t cap,
                         fr_error *err)
{
    size_t n = (size_t)snprintf(cmd, cap, "exec ");
    char q[2200];
    for (int i = -1; i < 0 || args[i]; i++) {
        if (tr_shell_quote(i < 0 ? prog : args[i], q, sizeof q, err))
            return -1;
        if (n + strlen(q) + 2 >= cap)
            return fr_fail(err, "remote command too long");
        n += (size_t)snprintf(cmd + n, cap - n, "%s%s", i < 0 ? "" : " ", q);
    }
    return 0;
}

/* Runs a short remote command to completion, collecting stdout and the tail
 * of stderr into p; *status is its exit status. */
static int run_remote(ssh_host *h, const char *cmd, tr_proc *p, int *status, fr_error *err)
{
    ssh_channel ch = ssh_channel_new(h->s);
    if (!ch || ssh_channel_open_session(ch) != SSH_OK || ssh_channel_request_exec(ch, cmd) != SSH_OK) {
        fr_fail(err, "%s: cannot run a command: %s", h->label, ssh_get_error(h->s));
        if (ch)
            ssh_channel_free(ch);
        return -1;
    }
    double end = now_s() + (h->opt.timeout_s > 0 ? h->opt.timeout_s : 10) * 3;
    char buf[16384];
    int rc = 0;
    for (;;) {
        int n = ssh_channel_read_timeout(ch, buf, sizeof buf, 0, 100);
        if (n > 0 && tr_proc_add_out(p, buf, (size_t)n)) {
            rc = fr_fail(err, "%s: out of memory", h->label);
            break;
        }
        int m;
        while ((m = ssh_channel_read_nonblocking(ch, buf, sizeof buf, 1)) > 0)
            tr_proc_add_err(p, buf, (size_t)m);
        if ((n < 0 && n != SSH_EOF) || (m < 0 && m != SSH_EOF)) {
            rc = fr_fail(err, "%s: connection lost: %s", h->label, ssh_get_error(h->s));
            break;
        }
        if ((n == 0 || n == SSH_EOF) && (ssh_channel_is_eof(ch) || ssh_channel_is_closed(ch)))
            break;
        if (now_s() > end) {
            rc = fr_fail(err, "%s: command did not finish in time: %s", h->label, cmd);
            break;
        }
    }
    if (rc == 0)
        *status = exit_status(ch);
    ssh_channel_close(ch);
    ssh_channel_free(ch);
    return rc;
}

static int ssh_probe(void *impl, tr_info *info, fr_error *err)
{
    ssh_host *h = impl;
    char q[1200], cmd[1600];
    if (tr_shell_quote(h->worker, q, sizeof q, err))
        return -1;
    snprintf(cmd, sizeof cmd,
             "uname -m && uname -s && (nproc 2>/dev/null || getconf _NPROCESSORS_ONLN) && exec %s --version",
             q);
    tr_proc p;
    memset(&p, 0, sizeof p);
    int status = -1, rc = run_remote(h, cmd, &p, &status, err);
    if (rc == 0 && status != 0)
        rc = fr_fail(err, "%s: worker '%s' cannot be run (status %d): %s -- install it with "
                     "franja deploy or give worker= in the host table", h->label, h->worker, status, p.err);
    if (rc == 0 && tr_proc_add_out(&p, "", 1))
        rc = fr_fail(err, "%s: out of memory", h->label);
    if (rc == 0) {
        char *save = NULL, *text = (char *)p.out;
        char *l1 = strtok_r(text, "\n", &save), *l2 = strtok_r(NULL, "\n", &save),
             *l3 = strtok_r(NULL, "\n", &save), *l4 = strtok_r(NULL, "\n", &save);
        if (!l4 || atoi(l3) <= 0) {
            rc = fr_fail(err, "%s: unexpected answer to uname/nproc/--version", h->label);
        } else {
            snprintf(info->arch, sizeof info->arch, "%s", l1);
            snprintf(info->os, sizeof info->os, "%s", l2);
            info->cores = atoi(l3);
            snprintf(info->version, sizeof info->version, "%s", l4);
        }
    }
    free(p.out);
    return rc;
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
 * channel, so it is closed as soon as the scene is in place. */
static void sftp_done(ssh_host *h)
{
    if (h->sftp)
        sftp_free(h->sftp);
    h->sftp = NULL;
}

/* mkdir -p over SFTP. */
static int sftp_mkdirs(ssh_host *h, const char *dir, fr_error *err)
{
    char path[700];
    snprintf(path, sizeof path, "%s", dir);
    for (char *s = path + 1;; s++) {
        if (*s == '/' || *s == 0) {
            char c = *s;
            *s = 0;
            sftp_mkdir(h->sftp, path, 0755); /* fails harmlessly when it exists */
            *s = c;
            if (!c)
                break;
        }
    }
    sftp_attributes a = sftp_stat(h->sftp, dir);
    int ok = a && a->type == SSH_FILEXFER_TYPE_DIRECTORY;
    sftp_attributes_free(a);
    return ok ? 0 : fr_fail(err, "%s: cannot create work directory '%s': %s", h->label, dir,
                            ssh_get_error(h->s));
}

/* 1 if the remote copy is intact: right size and the worker reads it and
 * reports the expected content hash. */
static int remote_copy_ok(ssh_host *h, const char *remote, uint64_t size, const char *hex, fr_error *err)
{
    sftp_attributes a = sftp_stat(h->sftp, remote);
    int size_ok = a && a->size == size;
    sftp_attributes_free(a);
    if (!size_ok)
        return 0;
    char cmd[2600];
    const char *args[] = {"--scene", remote, "--check", NULL};
    if (build_command(h->worker, args, cmd, sizeof cmd, err))
        return -1;
    tr_proc p;
    memset(&p, 0, sizeof p);
    int status = -1;
    int rc = run_remote(h, cmd, &p, &status, err);
    int ok = 0;
    if (rc == 0 && status == 0 && tr_proc_add_out(&p, "", 1) == 0)
        ok = strstr((char *)p.out, hex) != NULL;
    free(p.out);
    return rc ? -1 : ok;
}

static int upload(ssh_host *h, const char *local, const char *tmp, fr_error *err)
{
    int fd = open(local, O_RDONLY);
    if (fd < 0)
        return fr_fail(err, "%s: %s", local, strerror(errno));
    sftp_file f = sftp_open(h->sftp, tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
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

static int ssh_stage(void *impl, const char *local_path, uint64_t hash, char *remote, size_t cap,
                     int *uploaded, fr_error *err)
{
    ssh_host *h = impl;
    struct stat st;
    if (stat(local_path, &st))
        return fr_fail(err, "%s: %s", local_path, strerror(errno));
    char dir[700], hex[17], path[800], tmp[900];
    snprintf(hex, sizeof hex, "%016llx", (unsigned long long)hash);
    snprintf(dir, sizeof dir, "%s/scenes", h->workdir);
    snprintf(path, sizeof path, "%s/%s.fbin", dir, hex);
    if (strlen(path) >= cap)
        return fr_fail(err, "%s: work directory path too long", h->label);
    strcpy(remote, path);
    if (sftp_ready(h, err) || sftp_mkdirs(h, dir, err))
        return -1;
    int ok = remote_copy_ok(h, path, (uint64_t)st.st_size, hex, err);
    if (ok < 0)
        return -1;
    if (ok) {
        sftp_done(h);
        return 0;
    }
    sftp_attributes a = sftp_stat(h->sftp, path);
    if (a)
        fprintf(stderr, "franja: %s: cached scene %s is damaged; uploading it again\n", h->label, path);
    sftp_attributes_free(a);
    /* A private temporary name, renamed into place: a reader never sees a
     * half-written scene, and two coordinators do not write the same file. */
    snprintf(tmp, sizeof tmp, "%s.part-%ld-%ld", path, (long)getpid(), (long)(now_s() * 1e3));
    if (upload(h, local_path, tmp, err)) {
        sftp_unlink(h->sftp, tmp);
        return -1;
    }
    if (sftp_rename(h->sftp, tmp, path) != SSH_OK) {
        sftp_unlink(h->sftp, path);
        if (sftp_rename(h->sftp, tmp, path) != SSH_OK) {
            sftp_unlink(h->sftp, tmp);
            return fr_fail(err, "%s: cannot rename the uploaded scene into place: %s", h->label,
                           ssh_get_error(h->s));
        }
    }
    *uploaded = 1;
    ok = remote_copy_ok(h, path, (uint64_t)st.st_size, hex, err);
    if (ok < 0)
        return -1;
    if (!ok)
        return fr_fail(err, "%s: the uploaded scene %s does not check out (size or hash); "
                       "is the worker '%s' able to read this scene format?", h->label, path, h->worker);
    sftp_done(h);
    return 0;
}

static int ssh_cache(void *impl, int *files, uint64_t *bytes, fr_error *err)
{
    ssh_host *h = impl;
    char dir[700];
    snprintf(dir, sizeof dir, "%s/scenes", h->workdir);
    if (sftp_ready(h, err))
        return -1;
    sftp_dir d = sftp_opendir(h->sftp, dir);
    if (!d)
        return 0; /* no cache yet */
    sftp_attributes a;
    while ((a = sftp_readdir(h->sftp, d))) {
        size_t n = strlen(a->name);
        if (n > 5 && !strcmp(a->name + n - 5, ".fbin")) {
            (*files)++;
            *bytes += a->size;
        }
        sftp_attributes_free(a);
    }
    sftp_closedir(d);
    return 0;
}

static int ssh_sysinfo(void *impl, char *arch, char *os, fr_error *err)
{
    ssh_host *h = impl;
    tr_proc p;
    memset(&p, 0, sizeof p);
    int status = -1;
    int rc = run_remote(h, "uname -m && (cat /etc/os-release 2>/dev/null || true)", &p, &status, err);
    if (rc == 0 && status != 0)
        rc = fr_fail(err, "%s: uname -m failed (status %d): %s", h->label, status, p.err);
    if (rc == 0 && tr_proc_add_out(&p, "", 1))
        rc = fr_fail(err, "%s: out of memory", h->label);
    if (rc == 0) {
        const char *text = (const char *)p.out;
        size_t n = strcspn(text, "\n");
        if (n == 0 || n >= 32) {
            rc = fr_fail(err, "%s: unexpected answer to uname -m", h->label);
        } else {
            snprintf(arch, 32, "%.*s", (int)n, text);
            tr_os_codename(text + n, os);
        }
    }
    free(p.out);
    return rc;
}

static int ssh_install(void *impl, const char *local_path, const char *name, char *remote, size_t cap,
                       fr_error *err)
{
    ssh_host *h = impl;
    struct stat st;
    if (stat(local_path, &st))
        return fr_fail(err, "%s: %s", local_path, strerror(errno));
    char path[800], tmp[900];
    snprintf(path, sizeof path, "%s/%s", h->workdir, name);
    if (strlen(path) >= cap)
        return fr_fail(err, "%s: work directory path too long", h->label);
    if (sftp_ready(h, err))
        return -1;
    /* As for scenes: a private temporary name, renamed into place. */
    snprintf(tmp, sizeof tmp, "%s.part-%ld-%ld", path, (long)getpid(), (long)(now_s() * 1e3));
    int rc = sftp_mkdirs(h, h->workdir, err);
    if (rc == 0)
        rc = upload(h, local_path, tmp, err);
    if (rc == 0) {
        sftp_attributes a = sftp_stat(h->sftp, tmp);
        if (!a || a->size != (uint64_t)st.st_size)
            rc = fr_fail(err, "%s: %s arrived incomplete", h->label, tmp);
        sftp_attributes_free(a);
    }
    if (rc == 0 && sftp_chmod(h->sftp, tmp, 0755) != SSH_OK)
        rc = fr_fail(err, "%s: cannot make %s executable: %s", h->label, tmp, ssh_get_error(h->s));
    if (rc == 0 && sftp_rename(h->sftp, tmp, path) != SSH_OK) {
        /* SFTP version 3 does not rename over an existing file. */
        sftp_unlink(h->sftp, path);
        if (sftp_rename(h->sftp, tmp, path) != SSH_OK)
            rc = fr_fail(err, "%s: cannot rename %s into place: %s", h->label, tmp, ssh_get_error(h->s));
    }
    if (rc)
        sftp_unlink(h->sftp, tmp);
    else
        strcpy(remote, path);
    sftp_done(h);
    return rc;
}

static int ssh_spawn(void *impl, tr_proc *p, const char *const *args, fr_error *err)
{
    ssh_host *h = impl;
    if (h->lost)
        return fr_fail(err, "%s: connection lost", h->label);
    char cmd[8192];
    if (build_command(h->worker, args, cmd, sizeof cmd, err))
        return -1;
    ssh_proc *sp = calloc(1, sizeof *sp);
    if (!sp)
        return fr_fail(err, "%s: out of memory", h->label);
    sp->ch = ssh_channel_new(h->s);
    if (!sp->ch || ssh_channel_open_session(sp->ch) != SSH_OK ||
        ssh_channel_request_exec(sp->ch, cmd) != SSH_OK) {
        fr_fail(err, "%s: cannot start a worker: %s (a host running more than ~9 workers needs "
                "MaxSessions raised in its sshd_config)", h->label, ssh_get_error(h->s));
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
                tr_proc_fail(p, "out of memory for the worker's output");
        while (n >= 0 && (m = ssh_channel_read_nonblocking(sp->ch, buf, sizeof buf, 1)) > 0)
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
    double t = now_s();
    double interval = h->opt.timeout_s > 0 ? h->opt.timeout_s / 4.0 : 2.5;
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
    } else if (h->opt.timeout_s > 0 && t - h->seen_t > h->opt.timeout_s) {
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

static void ssh_kill(tr_proc *p)
{
    ssh_proc *sp = p->impl;
    if (!sp || !sp->ch || !ssh_channel_is_open(sp->ch))
        return;
    ssh_channel_request_send_signal(sp->ch, "KILL");
    ssh_channel_close(sp->ch);
}

static void ssh_release(tr_proc *p)
{
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

const tr_backend tr_ssh_backend = {
    "ssh", ssh_connect_host, ssh_probe, ssh_stage, ssh_cache, ssh_spawn, ssh_pollfds,
    ssh_service, ssh_kill, ssh_release, ssh_close_host, ssh_sysinfo, ssh_install,
};
