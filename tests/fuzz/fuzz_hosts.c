/* fuzz_hosts.c -- libFuzzer target for the host table reader
 * (coordinator/transport/hosts.h): any text as a table (hosts_parse, then what a
 * render asks of each entry), and the input's first line as a cache=
 * size (hosts_parse_size, hosts_format_size).  A table read from a file
 * never holds a NUL byte (hosts_load refuses one), so the text ends at the
 * first. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "transport/hosts.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    hosts_table t;
    fr_error err;
    if (hosts_parse(text, "fuzz.hosts", &t, &err) == 0) {
        for (int i = 0; i < t.n; i++) {
            const hosts_entry *h = &t.v[i];
            /* Every field a caller prints or passes on is a terminated
             * string of its array. */
            if (strlen(h->name) >= sizeof h->name || strlen(h->address) >= sizeof h->address ||
                strlen(h->workdir) >= sizeof h->workdir || h->cores < 0 || h->cores > HOSTS_MAX_CORES ||
                h->port < 0 || h->port > 65535 || h->line < 1)
                abort();
            (void)hosts_is_local(h);
            (void)hosts_workdir(h);
            char size_text[32];
            hosts_format_size(h->cache ? h->cache : HOSTS_CACHE_DEFAULT, size_text);
        }
        hosts_free(&t);
    }
    char *nl = strchr(text, '\n');
    if (nl)
        *nl = 0;
    uint64_t bytes;
    if (hosts_parse_size(text, &bytes) == 0) {
        if (bytes == 0 || bytes > (1ull << 60))
            abort();
        char size_text[32];
        hosts_format_size(bytes, size_text);
    }
    free(text);
    return 0;
}
