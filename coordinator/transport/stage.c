/* stage.c -- probing a host and putting files there, above the transport
 * backends (see stage.h). */
#include "transport/stage.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fbin.h"
#include "fpatch.h"
#include "transport/pack.h"
#include "unpack.h"

/* The exit status of the cache check when there is no cached copy (the
 * worker's own statuses are 0, 1 and 2). */
enum { ABSENT = 97 };

/* `sh -c CHECK_SCRIPT WORKER --scene PATH --check`: the worker checks the
 * copy if there is one; if there is none, says what it can do besides
 * rendering (`--features`: whether a scene may be sent compressed; a
 * worker too old to know prints nothing), in the same round trip. */
static const char CHECK_SCRIPT[] =
    "[ -e \"$2\" ] || { \"$0\" --features 2>/dev/null; exit 97; }; exec \"$0\" \"$@\"";

/* `sh -c LEASE_CHECK_SCRIPT LEASE WORKER --scene PATH --check`: takes (or
 * renews) the render's lease on the scene first, then checks the copy. */
static const char LEASE_CHECK_SCRIPT[] =
    "(set -C; : >\"$0\") 2>/dev/null || touch -c -- \"$0\"; "
    "[ -e \"$3\" ] || { \"$1\" --features 2>/dev/null; exit 97; }; exec \"$@\"";

/* A lease younger than this many minutes keeps its scene (stage.h). */
#define LEASE_MIN "10"

/* `leased F` succeeds when a render holds a live lease on scene F (a file
 * F.lease-* changed within LEASE_MIN minutes); stale leases go. */
#define LEASED                                                                                                    \
    "leased() { r=1; for l in \"$1\".lease-*; do [ -f \"$l\" ] || continue; "                                      \
    "if [ -n \"$(find \"$l\" -mmin -" LEASE_MIN " 2>/dev/null)\" ]; then r=0; else rm -f -- \"$l\"; fi; done; "    \
    "return $r; }; "

static const char CACHE_SCRIPT[] =
    "cd \"$0\" 2>/dev/null || exit 0; for f in *.fbin; do [ -f \"$f\" ] && wc -c <\"$f\"; done; exit 0";

/* The names of the scenes (*.fbin) that the user's processes on the host
 * have mapped, as " A B ... " in $u (Linux's /proc; elsewhere none). */
#define IN_USE "u=\" $(cat /proc/[0-9]*/maps 2>/dev/null | grep -o '[^/ ]*\\.fbin$' | tr '\\n' ' ') \"; "

/* `sh -c EVICT_SCRIPT DIR KEEP LIMIT`: newest first, every scene past the
 * limit goes, unless it is KEEP, in use or leased; prints "NAME SIZE" for
 * each. */
static const char EVICT_SCRIPT[] =
    "cd \"$0\" 2>/dev/null || exit 0; touch -c -- \"$1\"; " IN_USE LEASED
    "t=0; for f in $(ls -t); do case $f in *.fbin) ;; *) continue ;; esac; [ -f \"$f\" ] || continue; "
    "s=$(wc -c <\"$f\") || continue; t=$((t + s)); "
    "if [ \"$t\" -gt \"$2\" ] && [ \"$f\" != \"$1\" ]; then case $u in *\" $f \"*) continue ;; esac; leased \"$f\" && continue; "
    "rm -f -- \"$f\" && t=$((t - s)) && echo \"$f $s\"; fi; done; exit 0";

/* `sh -c CLEAN_SCRIPT DIR`: prints "REMOVED BYTES IN_USE TEMP". */
static const char CLEAN_SCRIPT[] =
    "cd \"$0\" 2>/dev/null || { echo 0 0 0 0; exit 0; }; " IN_USE LEASED
    "n=0; b=0; k=0; p=0; for f in *.fbin; do [ -f \"$f\" ] || continue; "
    "case $u in *\" $f \"*) k=$((k + 1)); continue ;; esac; if leased \"$f\"; then k=$((k + 1)); continue; fi; "
    "s=$(wc -c <\"$f\") && rm -f -- \"$f\" && n=$((n + 1)) && b=$((b + s)); done; "
    "for f in $(find . -maxdepth 1 -type f \\( -name '*.part-*' -o -name '.check-*' -o -name '*.fbin.lease-*' "
    "-o -name '*.fbin.zst-*' \\) "
    "-mmin +" LEASE_MIN "); do "
    "rm -f -- \"$f\" && p=$((p + 1)); done; echo \"$n $b $k $p\"";

static const char SYSINFO_SCRIPT[] = "uname -m && (cat /etc/os-release 2>/dev/null || true)";

/* Runs a short command; *p is the finished process (TR_EXITED or
 * TR_FAILED), to be freed. */
static int run(tr_host *h, const char *const *argv, tr_proc **p, fr_error *err)
{
    int t = tr_host_options(h)->timeout_s;
    return tr_run(h, argv, 65536, 3 * (t > 0 ? t : 10), p, err);
}

/* A failed process's reason as an error. */
static int failed(tr_host *h, tr_proc *p, const char *what, fr_error *err)
{
    if (tr_proc_state(p) == TR_FAILED)
        return fr_fail(err, "%s: %s: %s", tr_host_label(h), what, tr_proc_reason(p));
    return fr_fail(err, "%s: %s failed (status %d): %s", tr_host_label(h), what, tr_proc_status(p),
                   tr_proc_reason(p));
}

int stage_probe(tr_host *h, proto_host *info, fr_error *err)
{
    const char *argv[] = {"sh", "-c", PROTO_PROBE_SCRIPT, tr_host_worker(h), NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    int rc = 0;
    size_t len;
    const char *out = (const char *)tr_proc_output(p, &len);
    fr_error e;
    if (tr_proc_state(p) == TR_FAILED)
        rc = failed(h, p, "probe", err);
    else if (tr_proc_status(p) != 0)
        rc = fr_fail(err, "%s: worker '%s' cannot be run (status %d): %s -- %s", tr_host_label(h), tr_host_worker(h),
                     tr_proc_status(p), tr_proc_reason(p),
                     tr_host_workdir(h)[0] ? "install it with franja deploy or give worker= in the host table"
                                           : "build it with make, or give worker=");
    else if (proto_parse_probe(out, len, info, &e))
        rc = fr_fail(err, "%s: %s", tr_host_label(h), e.msg);
    tr_proc_free(p);
    return rc;
}

/* 1 when the cached copy at path checks out, 0 when there is none, 2 when
 * it is damaged (or unreadable for this worker), -1 on error.  When there
 * is none, *unpack says in which form the worker can unpack a compressed
 * scene (PACK_PARTS, PACK_ZSTD; else it is 0) and *patches whether it
 * applies scene patches (fpatch.h). */
static int cached(tr_host *h, const char *path, const char *lease, uint64_t hash, int *unpack, int *patches,
                  fr_error *err)
{
    *unpack = 0;
    *patches = 0;
    const char *check[4];
    proto_check_argv(path, check);
    const char *plain[] = {"sh", "-c", CHECK_SCRIPT, tr_host_worker(h), check[0], check[1], check[2], NULL};
    const char *leased[] = {"sh", "-c", LEASE_CHECK_SCRIPT, lease, tr_host_worker(h), check[0], check[1], check[2],
                            NULL};
    const char *const *argv = lease[0] ? leased : plain;
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    int rc;
    size_t len;
    const char *out = (const char *)tr_proc_output(p, &len);
    uint64_t got;
    fr_error e;
    if (tr_proc_state(p) == TR_FAILED)
        rc = failed(h, p, "scene check", err);
    else if (tr_proc_status(p) == ABSENT) {
        rc = 0;
        *unpack = proto_has_feature(out, len, UNPACK_FEATURE)         ? PACK_PARTS
                  : proto_has_feature(out, len, PROTO_FEATURE_UNPACK) ? PACK_ZSTD
                                                                      : 0;
        *patches = proto_has_feature(out, len, FPATCH_FEATURE);
    }
    else
        rc = tr_proc_status(p) == 0 && proto_parse_check(out, len, &got, &e) == 0 && got == hash ? 1 : 2;
    tr_proc_free(p);
    return rc;
}

/* The name of this render's lease on the scene at `remote`: this machine,
 * this process and the time, so that no other render shares it. */
static int lease_name(const char *remote, char *lease, size_t cap)
{
    char host[64] = "";
    gethostname(host, sizeof host - 1);
    for (char *c = host; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '-'))
            *c = '_';
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return snprintf(lease, cap, "%s.lease-%s-%ld-%lld%03ld", remote, host, (long)getpid(), (long long)ts.tv_sec,
                    ts.tv_nsec / 1000000) >= (int)cap;
}

/* Uploads the local file `file` (`size` bytes: a compressed scene or a
 * patch, `what`) under a name of its own beside `remote` and has the
 * host's worker unpack it into `remote` (unpack.h, fpatch.h), adding the
 * bytes sent to *sent.  0 when the unpacked scene has the expected hash;
 * 1 when the unpacking failed (noted: a damaged transfer, or a patch
 * whose base is gone); -1 on error (the upload failed). */
static int upload_unpack(tr_host *h, const char *file, uint64_t size, uint64_t hash, const char *remote,
                         const char *what, uint64_t *sent, fr_error *err)
{
    char name[1400];
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    char host[64] = "";
    gethostname(host, sizeof host - 1);
    for (char *c = host; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '-'))
            *c = '_';
    snprintf(name, sizeof name, "%s.zst-%s-%ld-%ld", remote, host, (long)getpid(), (long)ts.tv_nsec);
    if (tr_upload(h, file, name, 0600, err))
        return -1;
    *sent += size;
    const char *un[6];
    proto_unpack_argv(name, remote, un);
    const char *argv[] = {tr_host_worker(h), un[0], un[1], un[2], un[3], NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    size_t len;
    const char *out = (const char *)tr_proc_output(p, &len);
    uint64_t got;
    fr_error e;
    int rc;
    if (tr_proc_state(p) == TR_EXITED && tr_proc_status(p) == 0 && proto_parse_check(out, len, &got, &e) == 0 &&
        got == hash) {
        rc = 0;
    } else {
        char why[300];
        snprintf(why, sizeof why, "%s", tr_proc_state(p) == TR_EXITED && tr_proc_status(p) == 0
                                            ? "a scene of another hash" : tr_proc_reason(p));
        tr_note(h, "the %s did not unpack (%s); sending %s", what, why,
                strstr(what, "patch") ? "the whole scene" : "it again");
        if (tr_proc_state(p) != TR_EXITED) {
            fr_error ignored;
            tr_remove(h, name, &ignored); /* the worker removes it itself when it runs */
        }
        rc = 1;
    }
    tr_proc_free(p);
    return rc;
}

/* Sends the scene compressed (pack.h, in form `form`) and has the host's
 * worker unpack it into `remote` (upload_unpack's statuses). */
static int send_packed(tr_host *h, const char *local_path, uint64_t hash, int form, const char *remote,
                       uint64_t *sent, fr_error *err)
{
    char packed[4200];
    uint64_t size;
    if (pack_acquire(local_path, hash, form, packed, sizeof packed, &size, err))
        return -1;
    int rc = upload_unpack(h, packed, size, hash, remote, "compressed scene", sent, err);
    pack_release(hash, form);
    return rc;
}

/* Attempts at a compressed transfer before the scene is sent as it is. */
enum { PACKED_TRIES = 2 };

int stage_scene(tr_host *h, const char *local_path, uint64_t hash, const stage_patch *patch, char *remote,
                size_t cap, char *lease, size_t lease_cap, uint64_t *sent, fr_error *err)
{
    *sent = 0;
    if (lease_cap)
        lease[0] = 0;
    const char *wd = tr_host_workdir(h);
    if (!wd[0]) {
        char abs[PATH_MAX];
        if (!realpath(local_path, abs))
            return fr_fail(err, "%s: %s: %s", tr_host_label(h), local_path, strerror(errno));
        if (strlen(abs) >= cap)
            return fr_fail(err, "%s: scene path too long", tr_host_label(h));
        strcpy(remote, abs);
        return 0;
    }
    char hex[17];
    fbin_hash_hex(hash, hex);
    if (snprintf(remote, cap, "%s/scenes/%s.fbin", wd, hex) >= (int)cap)
        return fr_fail(err, "%s: work directory path too long", tr_host_label(h));
    /* A Slurm job step per renewal would wait for a CPU: leases are for
     * SSH hosts, where a short command costs a channel for a moment. */
    if (lease_cap && !strcmp(tr_host_backend(h), "ssh") && lease_name(remote, lease, lease_cap))
        return fr_fail(err, "%s: work directory path too long", tr_host_label(h));
    const char *mine = lease_cap ? lease : "";
    int unpack, patches;
    int ok = cached(h, remote, mine, hash, &unpack, &patches, err);
    if (ok < 0 || ok == 1)
        return ok < 0 ? -1 : 0;
    if (ok == 2)
        tr_note(h, "cached scene %s is damaged; uploading it again", remote);
    /* A patch against a scene the host was given before, when its worker
     * applies them; one that does not apply is followed by the scene. */
    struct stat ps;
    int patched = -1;
    if (ok == 0 && patch && patch->path && patches && tr_host_link_upload(h) && stat(patch->path, &ps) == 0 &&
        (patched = upload_unpack(h, patch->path, (uint64_t)ps.st_size, hash, remote, "scene patch", sent, err)) < 0)
        return -1;
    /* Over a link, compressed when the worker there can unpack (a worker
     * built without libzstd cannot); a transfer that does not unpack to
     * the scene is sent again, then sent as it is. */
    int packed = patched == 0 ? 0 : -1;
    for (int i = 0; i < PACKED_TRIES && tr_host_link_upload(h) && unpack && packed != 0; i++)
        if ((packed = send_packed(h, local_path, hash, unpack, remote, sent, err)) < 0)
            return -1;
    if (packed != 0) {
        if (packed == 1)
            tr_note(h, "sending the scene uncompressed");
        if (tr_upload(h, local_path, remote, 0644, err))
            return -1;
        struct stat st;
        *sent += stat(local_path, &st) == 0 ? (uint64_t)st.st_size : 0;
    }
    ok = cached(h, remote, mine, hash, &unpack, &patches, err); /* takes the lease if the directory was new */
    if (ok < 0)
        return -1;
    if (ok != 1)
        return fr_fail(err, "%s: the uploaded scene %s does not check out (size or hash); "
                       "is the worker '%s' able to read this scene format?", tr_host_label(h), remote,
                       tr_host_worker(h));
    return 0;
}

/* `sh -c TRY_SCRIPT FILE`: prints the uploaded file and removes it. */
static const char TRY_SCRIPT[] = "c=$(cat -- \"$0\") || exit 1; rm -f -- \"$0\"; printf '%s\\n' \"$c\"";
static const char TRY_TEXT[] = "franja hosts check";

int stage_try_upload(tr_host *h, fr_error *err)
{
    const char *wd = tr_host_workdir(h);
    if (!wd[0])
        return 0;
    char local[] = "/tmp/franja-check-XXXXXX";
    int fd = mkstemp(local);
    if (fd < 0)
        return fr_fail(err, "cannot make a local file to upload: %s", strerror(errno));
    size_t n = strlen(TRY_TEXT);
    int wrote = write(fd, TRY_TEXT, n) == (ssize_t)n;
    if (close(fd) || !wrote) {
        unlink(local);
        return fr_fail(err, "cannot write a local file to upload: %s", strerror(errno));
    }
    char remote[1200];
    snprintf(remote, sizeof remote, "%s/scenes/.check-%s", wd, strrchr(local, '-') + 1);
    int rc = tr_upload(h, local, remote, 0600, err);
    unlink(local);
    if (rc)
        return -1;
    const char *argv[] = {"sh", "-c", TRY_SCRIPT, remote, NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    size_t len;
    const char *out = (const char *)tr_proc_output(p, &len);
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0)
        rc = failed(h, p, "reading back an uploaded file", err);
    else if (len != n + 1 || memcmp(out, TRY_TEXT, n))
        rc = fr_fail(err, "%s: an uploaded file (%s) reads back as %zu other bytes", tr_host_label(h), remote, len);
    tr_proc_free(p);
    return rc;
}

/* The bytes of a line of out[0..len) from *i, without its newline, into
 * *line and *n; *i moves past the newline. */
static void next_line(const char *out, size_t len, size_t *i, const char **line, size_t *n)
{
    const char *s = out + *i, *nl = memchr(s, '\n', len - *i);
    *line = s;
    *n = nl ? (size_t)(nl - s) : len - *i;
    *i += *n + (nl != NULL);
}

/* Adds the decimal number s[0..n) to *sum, saturating; -1 unless s[0..n)
 * is one or more digits. */
static int add_number(const char *s, size_t n, uint64_t *sum)
{
    uint64_t v = 0;
    if (n == 0)
        return -1;
    for (size_t k = 0; k < n; k++) {
        if (s[k] < '0' || s[k] > '9')
            return -1;
        v = v > UINT64_MAX / 10 ? UINT64_MAX : v * 10 + (uint64_t)(s[k] - '0');
    }
    *sum = *sum > UINT64_MAX - v ? UINT64_MAX : *sum + v;
    return 0;
}

int stage_parse_evicted(const char *out, size_t len, int *removed, uint64_t *bytes, fr_error *err)
{
    *removed = 0;
    *bytes = 0;
    for (size_t i = 0, line = 1; i < len; line++) {
        const char *s;
        size_t n;
        next_line(out, len, &i, &s, &n);
        const char *sp = n ? memchr(s, ' ', n) : NULL;
        if (!sp || sp == s || add_number(sp + 1, n - (size_t)(sp + 1 - s), bytes))
            return fr_fail(err, "line %zu: expected 'NAME BYTES', got '%.*s'", line, (int)(n < 80 ? n : 80), s);
        if (*removed < INT_MAX)
            (*removed)++;
    }
    return 0;
}

/* A count at *s, saturating at INT_MAX, and the separator after it
 * (sep, or the end when sep is 0); *s moves past both. */
static int count_at(const char **s, const char *end, char sep, int *v)
{
    uint64_t n = 0;
    const char *p = *s;
    while (p < end && *p >= '0' && *p <= '9')
        p++;
    if (p == *s || add_number(*s, (size_t)(p - *s), &n))
        return -1;
    if (sep ? p == end || *p != sep : p != end)
        return -1;
    *v = n > INT_MAX ? INT_MAX : (int)n;
    *s = sep ? p + 1 : p;
    return 0;
}

int stage_parse_cleaned(const char *out, size_t len, stage_cleaned *c, fr_error *err)
{
    memset(c, 0, sizeof *c);
    static const char what[] = "expected one line 'REMOVED BYTES IN_USE TEMP' (decimal numbers)";
    if (len && out[len - 1] == '\n')
        len--;
    if (len == 0)
        return fr_fail(err, "%s", what);
    const char *s = out, *end = out + len, *b;
    stage_cleaned got = {0, 0, 0, 0};
    int ok = count_at(&s, end, ' ', &got.removed) == 0;
    for (b = s; ok && s < end && *s >= '0' && *s <= '9';)
        s++;
    ok = ok && s > b && s < end && *s == ' ' && add_number(b, (size_t)(s - b), &got.bytes) == 0;
    s += ok;
    ok = ok && count_at(&s, end, ' ', &got.in_use) == 0 && count_at(&s, end, 0, &got.temp) == 0;
    if (!ok)
        return fr_fail(err, "%s", what);
    *c = got;
    return 0;
}

int stage_parse_cache(const char *out, size_t len, int *files, uint64_t *bytes, fr_error *err)
{
    *files = 0;
    *bytes = 0;
    for (size_t i = 0, line = 1; i < len; line++) {
        const char *s;
        size_t n;
        next_line(out, len, &i, &s, &n);
        /* wc -c pads its count with blanks on some systems. */
        while (n && (*s == ' ' || *s == '\t'))
            s++, n--;
        while (n && (s[n - 1] == ' ' || s[n - 1] == '\t'))
            n--;
        if (add_number(s, n, bytes))
            return fr_fail(err, "line %zu: expected a size in bytes", line);
        if (*files < INT_MAX)
            (*files)++;
    }
    return 0;
}

int stage_evict(tr_host *h, const char *keep, uint64_t limit, int *removed, uint64_t *bytes, fr_error *err)
{
    *removed = 0;
    *bytes = 0;
    const char *wd = tr_host_workdir(h);
    if (!wd[0])
        return 0;
    char dir[1024], lim[32];
    snprintf(dir, sizeof dir, "%s/scenes", wd);
    const char *name = strrchr(keep, '/');
    name = name ? name + 1 : keep;
    snprintf(lim, sizeof lim, "%llu", (unsigned long long)limit);
    const char *argv[] = {"sh", "-c", EVICT_SCRIPT, dir, name, lim, NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    int rc = 0;
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0) {
        rc = failed(h, p, "keeping the scene cache within its limit", err);
    } else {
        size_t len;
        const char *out = (const char *)tr_proc_output(p, &len);
        fr_error e;
        if (stage_parse_evicted(out, len, removed, bytes, &e))
            rc = fr_fail(err, "%s: keeping the scene cache within its limit: %s", tr_host_label(h), e.msg);
    }
    tr_proc_free(p);
    return rc;
}

int stage_clean(tr_host *h, stage_cleaned *out, fr_error *err)
{
    memset(out, 0, sizeof *out);
    const char *wd = tr_host_workdir(h);
    if (!wd[0])
        return 0;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/scenes", wd);
    const char *argv[] = {"sh", "-c", CLEAN_SCRIPT, dir, NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    int rc = 0;
    size_t len;
    const char *text = (const char *)tr_proc_output(p, &len);
    fr_error e;
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0)
        rc = failed(h, p, "cleaning the scene cache", err);
    else if (stage_parse_cleaned(text, len, out, &e))
        rc = fr_fail(err, "%s: unexpected answer cleaning the scene cache: %s", tr_host_label(h), e.msg);
    tr_proc_free(p);
    return rc;
}

int stage_cache(tr_host *h, int *files, uint64_t *bytes, fr_error *err)
{
    *files = 0;
    *bytes = 0;
    const char *wd = tr_host_workdir(h);
    if (!wd[0])
        return 0;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/scenes", wd);
    const char *argv[] = {"sh", "-c", CACHE_SCRIPT, dir, NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    int rc = 0;
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0) {
        rc = failed(h, p, "listing the scene cache", err);
    } else {
        size_t len;
        const char *out = (const char *)tr_proc_output(p, &len);
        fr_error e;
        if (stage_parse_cache(out, len, files, bytes, &e))
            rc = fr_fail(err, "%s: unexpected answer listing the scene cache: %s", tr_host_label(h), e.msg);
    }
    tr_proc_free(p);
    return rc;
}

void stage_os_codename(const char *text, char *os)
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
            proto_printable(os);
            return;
        }
        if (!end)
            break;
        l = end + 1;
    }
}

int stage_sysinfo(tr_host *h, char *arch, char *os, fr_error *err)
{
    arch[0] = os[0] = 0;
    const char *argv[] = {"sh", "-c", SYSINFO_SCRIPT, NULL};
    tr_proc *p;
    if (run(h, argv, &p, err))
        return -1;
    int rc = 0;
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0) {
        rc = failed(h, p, "uname -m", err);
    } else {
        size_t len;
        const char *out = (const char *)tr_proc_output(p, &len);
        char *text = strndup(out ? out : "", len);
        size_t n = text ? strcspn(text, "\n") : 0;
        if (!text)
            rc = fr_fail(err, "%s: out of memory", tr_host_label(h));
        else if (n == 0 || n >= 32 || strlen(text) != len)
            rc = fr_fail(err, "%s: unexpected answer to uname -m", tr_host_label(h));
        else {
            snprintf(arch, 32, "%.*s", (int)n, text);
            proto_printable(arch);
            stage_os_codename(text + n, os);
        }
        free(text);
    }
    tr_proc_free(p);
    return rc;
}

int stage_install(tr_host *h, const char *local_path, const char *name, char *remote, size_t cap, fr_error *err)
{
    const char *wd = tr_host_workdir(h);
    if (!wd[0])
        return fr_fail(err, "%s: a local host runs this machine's worker (%s); nothing to install", tr_host_label(h),
                       tr_host_worker(h));
    if (snprintf(remote, cap, "%s/%s", wd, name) >= (int)cap)
        return fr_fail(err, "%s: work directory path too long", tr_host_label(h));
    return tr_upload(h, local_path, remote, 0755, err);
}
