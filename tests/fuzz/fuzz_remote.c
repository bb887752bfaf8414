/* fuzz_remote.c -- libFuzzer target for what the coordinator reads from a
 * host's commands (network messages: a host may be broken or hostile).
 * The input's first byte picks the reader, the rest is the host's output:
 *
 *   0  the probe's answer (proto_parse_probe)
 *   1  `franja-worker --check` (proto_parse_check)
 *   2  a `--version` line (proto_parse_version)
 *   3  the cache trimming's "NAME BYTES" lines (stage_parse_evicted)
 *   4  the cache listing (stage_parse_cache)
 *   5  an os-release text (stage_os_codename)
 *   6  the cache cleaning's "REMOVED BYTES IN_USE TEMP" (stage_parse_cleaned)
 *   7  a process's stdout and stderr as the transports collect them
 *      (tr_proc_add_out, tr_proc_add_err), in chunks whose sizes the
 *      output's bytes give, and what a message shows of them
 *      (tr_proc_reason)
 *
 * Text that a message may show (the probe's fields, the codename, the
 * tail of stderr) must hold no control character. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "protocol.h"
#include "transport/stage.h"
#include "transport/transport_backend.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void printable(const char *s, size_t cap)
{
    size_t n = strnlen(s, cap);
    if (n == cap)
        abort();
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            abort();
}

/* The output in chunks, as reads from a pipe or a channel give it. */
static void streams(const uint8_t *d, size_t n)
{
    tr_proc p;
    memset(&p, 0, sizeof p);
    p.state = TR_RUNNING;
    p.out_max = 4096;
    for (size_t i = 0; i < n;) {
        size_t k = 1 + d[i] % 64, left = n - i - 1;
        if (k > left)
            k = left;
        if (d[i] & 0x80)
            tr_proc_add_err(&p, d + i + 1, k);
        else if (tr_proc_add_out(&p, d + i + 1, k) && !(p.state == TR_FAILED && p.out_len <= p.out_max))
            abort();
        i += 1 + k;
    }
    if (p.out_len > p.out_max || p.err_len >= sizeof p.err)
        abort();
    printable(tr_proc_reason(&p), sizeof p.err);
    free(p.out);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0)
        return 0;
    const char *out = (const char *)data + 1;
    size_t len = size - 1;
    char *text = malloc(len + 1);
    if (!text)
        return 0;
    memcpy(text, out, len);
    text[len] = 0;
    fr_error err;
    switch (data[0] % 8) {
    case 0: {
        proto_host h;
        if (proto_parse_probe(out, len, &h, &err) == 0) {
            if (h.cores < 1 || h.cores > PROTO_MAX_CORES)
                abort();
            printable(h.arch, sizeof h.arch);
            printable(h.os, sizeof h.os);
            printable(h.version, sizeof h.version);
            proto_version v;
            (void)proto_parse_version(h.version, &v, &err);
        }
        break;
    }
    case 1: {
        uint64_t hash;
        (void)proto_parse_check(out, len, &hash, &err);
        break;
    }
    case 2: {
        proto_version v;
        if (proto_parse_version(text, &v, &err) == 0 && v.scene_format < 0)
            abort();
        break;
    }
    case 3: {
        int removed;
        uint64_t bytes;
        if (stage_parse_evicted(len ? out : NULL, len, &removed, &bytes, &err) == 0 && removed < 0)
            abort();
        break;
    }
    case 4: {
        int files;
        uint64_t bytes;
        if (stage_parse_cache(len ? out : NULL, len, &files, &bytes, &err) == 0 && files < 0)
            abort();
        break;
    }
    case 5: {
        char os[64];
        stage_os_codename(text, os);
        printable(os, sizeof os);
        break;
    }
    case 6: {
        stage_cleaned c;
        if (stage_parse_cleaned(len ? out : NULL, len, &c, &err) == 0 &&
            (c.removed < 0 || c.in_use < 0 || c.temp < 0))
            abort();
        break;
    }
    default:
        streams(data + 1, len);
        break;
    }
    free(text);
    return 0;
}
