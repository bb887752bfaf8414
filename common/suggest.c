/* suggest.c -- the nearest known option (see suggest.h). */
#include "suggest.h"

#include <stdio.h>
#include <string.h>

/* Levenshtein distance of a[0..na) and b[0..nb): insertions, deletions
 * and substitutions of one byte.  Strings longer than 32 bytes are 99 away
 * from everything. */
static int sug_edits(const char *a, size_t na, const char *b, size_t nb)
{
    if (na > 32 || nb > 32)
        return 99;
    int row[33];
    for (size_t j = 0; j <= nb; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= na; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= nb; j++) {
            int up = row[j];
            int best = diag + (a[i - 1] != b[j - 1]);
            if (row[j] + 1 < best)
                best = row[j] + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            diag = up;
            row[j] = best;
        }
    }
    return row[nb];
}

static int known(const char *name, const char *const *names, size_t count)
{
    for (size_t i = 0; i < count; i++)
        if (!strcmp(names[i], name))
            return 1;
    return 0;
}

int sug_option(const char *typed, const char *const *names, size_t count, char *buf, size_t cap)
{
    /* What people coming from other renderers type, and what franja calls it. */
    static const char *const synonyms[][2] = {
        {"samples", "spp"},     {"spp-count", "spp"},  {"resolution", "size"}, {"res", "size"},
        {"threads", "j"},       {"jobs", "j"},         {"output", "o"},        {"out", "o"},
        {"host", "hosts"},      {"hostfile", "hosts"}, {"curve", "tonemap"},   {"tone-map", "tonemap"},
        {"continue", "resume"}, {"ev", "exposure"},
    };
    const char *name = typed;
    while (*name == '-')
        name++;
    size_t n = strcspn(name, "=");
    if (n == 0)
        return -1;
    const char *best = NULL, *nearest = NULL;
    for (size_t i = 0; i < sizeof synonyms / sizeof *synonyms && !best; i++)
        if (strlen(synonyms[i][0]) == n && !strncmp(name, synonyms[i][0], n) && known(synonyms[i][1], names, count))
            best = synonyms[i][1];
    /* Otherwise the nearest long option within a few edits (fewer for
     * short names, where a few edits make anything of anything). */
    int limit = n <= 3 ? 1 : n <= 6 ? 2 : 3;
    for (size_t i = 0; i < count && !best; i++) {
        size_t len = strlen(names[i]);
        int d = len > 1 ? sug_edits(name, n, names[i], len) : 99;
        if (d <= limit) {
            limit = d - 1;
            nearest = names[i];
        }
    }
    if (!best)
        best = nearest;
    if (!best)
        return -1;
    int w = snprintf(buf, cap, strlen(best) == 1 ? "-%s" : "--%s", best);
    return w < 0 || (size_t)w >= cap ? -1 : 0;
}
